//! The dense Newton step of the minimizer from the exact eigen-decomposition of the reduced
//! Hessian along the search path (`Ĥ + C = Σ λ_i v_i v_iᵀ`, module `path_hessian`), with the
//! negative curvature used rather than only tolerated:
//!
//! `d = s + n`,  `s = −Σ_i v_i (v_iᵀ∇f) / max(|λ_i|, ε λ_max)`,
//! `n = c Σ_{λ_i < −τ} σ_i (λ_i / λ_min) v_i`,  `σ_i = −sign(v_iᵀ∇f)` (`+1` where it is 0),
//!
//! `ε = 10⁻¹²` (the floor on the magnitudes), `τ` the spectrum's tolerance and `c` such that
//! `‖n‖∞ = max_step`, the length of the step that leaves a saddle. `s` is the Newton step of the
//! Hessian with its eigenvalues replaced by their magnitudes (Nocedal & Wright §3.4); alone, it
//! moves along a direction of curvature `λ < 0` by `−(vᵀ∇f)/|λ|`, which near a maximum or a
//! saddle (`vᵀ∇f ≈ λ x`) is the step `x → 2x`: from a pendulum's upright start the distance
//! doubled per iteration, 16 iterations from a gradient of 6·10⁻⁶ J to the fall. `n` is the
//! direction of negative curvature of Moré & Sorensen's descent pair `(s, n)`: `∇fᵀn ≤ 0` and
//! `nᵀĤn < 0`, so `d` is a descent direction along which the quadratic model falls at least
//! by `½ nᵀĤn`, however small the gradient; it is scaled like the step that leaves a saddle
//! (which it is when `∇f = 0`). The line search takes `d` as one straight step from `α = 1`
//! (the pair's curvilinear path `x + α² s + α n` at `α = 1`) and the step cap (module
//! `step_cap`) bounds its length. Where `Ĥ` has no eigenvalue below `−τ`, `d = s`: the Newton
//! step and its quadratic convergence near a minimum are unchanged.
//!
//! The eigenvalues must be those along the path: `Ĥ`'s own carry a term proportional to the
//! gradient (the curvature of the Cartesian chart), which away from equilibrium is negative
//! along directions that are not (UR5 falling from horizontal: `λ_min(Ĥ)` −14…−30 J where
//! `Ĥ + C` has none below −10⁻⁶); leaving those "saddles" sent Talos, Tiago and iCub-reduced
//! to `max_iterations`.
//!
//! ## References
//! - J. J. Moré, D. C. Sorensen, On the use of directions of negative curvature in a modified
//!   Newton method, *Mathematical Programming* 16 (1979) 1–20.
//! - J. Nocedal, S. J. Wright, *Numerical Optimization*, 2nd ed., Springer (2006), §3.4.
//! - P. E. Gill, W. Murray, M. H. Wright, *Practical Optimization*, Academic Press (1981), §4.4.2.

use crate::solver::stability::spectrum::Spectrum;
use nalgebra::DVector;

/// The dense Newton step's floor on the eigenvalue magnitudes, a fraction of the largest. At
/// 10⁻⁸ it cut the steps along near-neutral directions (iCub's hip yaws, 1.2·10⁻¹⁰ of the
/// largest) 80-fold and the solve crawled at the rate `1 − λ/floor`.
const EIGENVALUE_FLOOR: f64 = 1e-12;

/// The Newton step `d = s + n` at the reduced gradient `g` (module docs), and whether it has a
/// negative-curvature part `n`.
pub(crate) fn newton_step(e: &Spectrum, g: &DVector<f64>, max_step: f64) -> (DVector<f64>, bool) {
    let dof = g.len();
    let floor = EIGENVALUE_FLOOR * e.values.amax().max(1e-12);
    let mut d = DVector::zeros(dof);
    for i in 0..dof {
        let v = e.vectors.column(i);
        d -= v * (v.dot(g) / e.values[i].abs().max(floor));
    }
    let Some((_, lmin)) = e.lowest() else {
        return (d, false);
    };
    let tol = e.tolerance();
    if lmin >= -tol {
        return (d, false);
    }
    let mut n = DVector::zeros(dof);
    for i in (0..dof).filter(|&i| e.values[i] < -tol) {
        let v = e.vectors.column(i);
        let sign = if v.dot(g) > 0.0 { -1.0 } else { 1.0 };
        n += v * (sign * e.values[i] / lmin);
    }
    let size = n.amax();
    if size > 0.0 {
        d += n * (max_step / size);
    }
    (d, true)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::DMatrix;

    /// The exact spectrum of a symmetric matrix, ascending, as the minimizer gets it.
    fn spectrum(h: DMatrix<f64>) -> Spectrum {
        let eig = h.symmetric_eigen();
        let mut order: Vec<usize> = (0..eig.eigenvalues.len()).collect();
        order.sort_by(|&a, &b| eig.eigenvalues[a].total_cmp(&eig.eigenvalues[b]));
        let values = DVector::from_iterator(order.len(), order.iter().map(|&i| eig.eigenvalues[i]));
        let vectors = DMatrix::from_columns(
            &order
                .iter()
                .map(|&i| eig.eigenvectors.column(i).into_owned())
                .collect::<Vec<_>>(),
        );
        Spectrum {
            largest: values.amax(),
            values,
            vectors,
            exact: true,
            negative_by_inertia: None,
        }
    }

    #[test]
    fn positive_definite_hessian_gives_the_newton_step() {
        let h = DMatrix::from_row_slice(2, 2, &[4.0, 1.0, 1.0, 3.0]);
        let g = DVector::from_vec(vec![1.0, -2.0]);
        let (d, negative) = newton_step(&spectrum(h.clone()), &g, 0.3);
        assert!(!negative);
        // H d = −g.
        assert!((&h * &d + &g).amax() < 1e-14, "{d}");
    }

    #[test]
    fn negative_curvature_moves_a_full_step_against_the_gradient() {
        // f = −½ x² + y² near the maximum in x: g = (−x, 2y) at (x, y) = (1e-6, 0.5).
        let h = DMatrix::from_row_slice(2, 2, &[-1.0, 0.0, 0.0, 2.0]);
        let g = DVector::from_vec(vec![-1e-6, 1.0]);
        let (d, negative) = newton_step(&spectrum(h.clone()), &g, 0.3);
        assert!(negative);
        // The positive direction gets its Newton step −g_y / 2; the negative one moves away
        // from the maximum (downhill, the sign of −g_x) by max_step plus the magnitude step,
        // not by the |λ| step 1e-6 (x → 2x).
        assert!((d[1] + 0.5).abs() < 1e-14, "{d}");
        assert!((d[0] - (0.3 + 1e-6)).abs() < 1e-14, "{d}");
        // A descent direction whose quadratic model falls by at least ½ nᵀHn.
        let model = g.dot(&d) + 0.5 * d.dot(&(&h * &d));
        assert!(
            g.dot(&d) < 0.0 && model < -0.5 * 0.3 * 0.3 * 1.0 + 1e-12,
            "{model}"
        );
    }

    #[test]
    fn at_a_saddle_the_step_leaves_along_the_most_negative_curvature() {
        // Zero gradient, two negative curvatures: the step is weighted λ_i / λ_min and scaled
        // so that its largest component is max_step.
        let h = DMatrix::from_diagonal(&DVector::from_vec(vec![-4.0, -1.0, 3.0]));
        let g = DVector::zeros(3);
        let (d, negative) = newton_step(&spectrum(h), &g, 0.3);
        assert!(negative);
        assert!((d.amax() - 0.3).abs() < 1e-14, "{d}");
        assert!((d[1].abs() - 0.075).abs() < 1e-14 && d[2] == 0.0, "{d}");
    }

    #[test]
    fn curvature_within_the_tolerance_is_not_negative() {
        // −1e-12 of the largest eigenvalue is rounding: no negative-curvature part.
        let h = DMatrix::from_diagonal(&DVector::from_vec(vec![-1e-12, 1.0]));
        let g = DVector::from_vec(vec![1e-3, 1.0]);
        let (d, negative) = newton_step(&spectrum(h), &g, 0.3);
        assert!(!negative);
        assert!((d[1] + 1.0).abs() < 1e-14, "{d}");
    }
}
