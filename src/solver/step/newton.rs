//! The dense Newton step of the minimizer from the exact eigen-decomposition of the Hessian
//! along the search path, `Ĥ + C = Σ λ_i v_i v_iᵀ` (module `path_hessian`):
//!
//! `d = −Σ_i v_i (v_iᵀ∇f) / max(|λ_i|, ε λ_max)`,  `ε = 10⁻¹²`,
//!
//! the Newton step with the eigenvalues replaced by their magnitudes (Nocedal & Wright §3.4),
//! a descent direction whatever the inertia.
//!
//! Along a direction of curvature `λ < 0` it moves by `−(vᵀ∇f)/|λ|`, which near a maximum or
//! a saddle (`vᵀ∇f ≈ λ x`) is the step `x → 2x`: from a start with every leg straight up
//! (pybullet_data's minitaurs, ‖∇f‖ = 10⁻⁸) the distance doubled per iteration, and the legs
//! fell one after another, 27 iterations each (57–151 iterations).
//!
//! The escape (module `escape`, where the path keeps every row): near a stationary point,
//! `‖d‖∞ < 0.1 c` (`c = max_step`), each direction of curvature `λ_i < −τ` (`τ` the
//! spectrum's tolerance) along which `d` moves by less than `c_i = c / ‖v_i‖∞` gets the length
//! `t_i = −sign(v_iᵀ∇f) c_i` (`+c_i` where the slope is 0) instead of its magnitude step:
//!
//! `d = −Σ_{i ∉ E} v_i (v_iᵀ∇f) / max(|λ_i|, ε λ_max) + Σ_{i ∈ E} t_i v_i`,
//!
//! all at once, each direction scaled like the step that leaves a saddle (Moré & Sorensen's
//! direction of negative curvature, taken per eigen-direction instead of as one combined
//! vector). Module `escape` keeps a direction in `E` only where the energy along the path
//! falls as the curvature says. Away from stationary points (`‖d‖∞ ≥ 0.1 c`) the step is the
//! magnitude step: a combined step `s + n` taken there as well (tried in session 22) sent
//! falls to other equilibria (Panda +0.18 J; docs/method.md).
//!
//! Decoupled blocks (the fingers of a hand with a fixed palm: the Hessian's eigenvectors each
//! on one block, module `stability::blocks`) are judged one by one as well: a block whose own
//! magnitude step is shorter than `0.1 c` and whose slopes `v_iᵀ∇f` are all below
//! `10⁻¹⁰ ‖∇f‖∞` sits on a stationary point by itself and is escaped even while another
//! block's step is long (the Allegro hands' fingers straight up while the thumb falls:
//! 40 → 23 iterations).
//!
//! In the round that follows a release of several stops decided by the step (module
//! `inequality::release_trial`), the stops released fall from their boundaries, where they
//! were held on the concave side: there every direction of negative curvature whose magnitude
//! step is shorter than its saddle step is escaped, near a stationary point or not
//! ([`newton_step_within`] with `near` infinite; the energy test of module `escape` kept). The
//! classical simple humanoid's wrist roll fell from its released stop in magnitude steps of
//! 0.1 … 0.4 rad through curvatures −2.3 … −0.2 (31 → 30 iterations, no rest of the corpus
//! moved); taken in every round (session 26), the same escape moved Panda, G1 and Alex's rests.
//!
//! ## References
//! - J. Nocedal, S. J. Wright, *Numerical Optimization*, 2nd ed., Springer (2006), §3.4.
//! - J. J. Moré, D. C. Sorensen, On the use of directions of negative curvature in a modified
//!   Newton method, *Mathematical Programming* 16 (1979) 1–20.

use crate::solver::stability::blocks::blocks;
use crate::solver::stability::spectrum::Spectrum;
use nalgebra::{DMatrix, DVector};

/// The dense Newton step's floor on the eigenvalue magnitudes, a fraction of the largest. At
/// 10⁻⁸ it cut the steps along near-neutral directions (iCub's hip yaws, 1.2·10⁻¹⁰ of the
/// largest) 80-fold and the solve crawled at the rate `1 − λ/floor`.
pub(crate) const EIGENVALUE_FLOOR: f64 = 1e-12;

/// The escape is taken where the magnitude step is shorter than this fraction of the saddle
/// step `c`: near a stationary point. At 1 (escaping in the middle of falls too, without the
/// energy test of module `escape`), G1 and the classical simple humanoid of
/// example-robot-data ended `max_iterations`; with no such bound iCub took 59 → 120
/// iterations.
pub(crate) const NEAR_STATIONARY: f64 = 0.1;

/// A decoupled block of the Hessian (one finger of a hand with a fixed palm) is escaped on its
/// own, while the rest of the step is long, where its slopes are at most this fraction of
/// `‖∇f‖∞`: it sits on a stationary point by itself (the Allegro hands' fingers straight up
/// while the thumb falls, slopes exactly 0). Without the slope test (the block's step short
/// is enough) iCub took 32 → 38 iterations and Tiago Pro rested 0.43 J below both
/// releases' rest.
const BLOCK_AT_REST: f64 = 1e-10;

/// The Newton step at the reduced gradient `g` (module docs). With `escape = Some(c)` and a
/// magnitude step shorter than `0.1 c` (near a stationary point; or, per decoupled block, the
/// block's share of it with the block's slopes at rounding, `BLOCK_AT_REST`), every direction of
/// negative curvature `v_i` along which `s` moves by less than `c / ‖v_i‖∞` is stepped along
/// by that length instead, downhill (`−sign(v_iᵀ∇f)`, `+1` where the slope is 0). Returns the
/// step and the escaped directions `(i, t_i, s_i)`: the escape's signed length and the
/// magnitude step's.
pub(crate) fn newton_step(
    e: &Spectrum,
    g: &DVector<f64>,
    escape: Option<f64>,
) -> (DVector<f64>, Vec<(usize, f64, f64)>) {
    newton_step_within(e, g, escape, NEAR_STATIONARY)
}

/// [`newton_step`] with the escape taken where the magnitude step is shorter than `near c`
/// (`NEAR_STATIONARY`; infinite in the round after a release decided by the step, module
/// `inequality::release_trial`: every direction of negative curvature whose magnitude step is
/// shorter than its saddle step).
pub(crate) fn newton_step_within(
    e: &Spectrum,
    g: &DVector<f64>,
    escape: Option<f64>,
    near: f64,
) -> (DVector<f64>, Vec<(usize, f64, f64)>) {
    let floor = EIGENVALUE_FLOOR * e.values.amax().max(1e-12);
    let n = g.len();
    let column = |i: usize| &e.vectors.as_slice()[i * n..(i + 1) * n];
    let slopes: Vec<f64> = (0..n).map(|i| e.vectors.column(i).dot(g)).collect();
    let mut t: Vec<f64> = (0..n)
        .map(|i| -slopes[i] / e.values[i].abs().max(floor))
        .collect();
    // `Σ v_i t_i`, each term `v_i t_i` added in place (the sums of `d += v_i * t_i`).
    let step = |t: &[f64]| {
        let mut d = DVector::zeros(n);
        for (i, ti) in t.iter().enumerate() {
            add_scaled(d.as_mut_slice(), column(i), *ti);
        }
        d
    };
    let mut escaped = Vec::new();
    // Near a stationary point: the whole step (as before), or a decoupled block (a finger, a
    // leg: eigenvectors on one block, module `stability::blocks`) whose own step is short and
    // whose slopes are rounding while the others move (`BLOCK_AT_REST`).
    let group = groups(e);
    let whole = escape.is_some_and(|c| step(&t).amax() < near * c);
    let gmax = g.amax();
    // Per group (indexed by its root): its share of the step and whether its slopes vanish.
    let mut share = DMatrix::zeros(n, n);
    let mut still = vec![true; n];
    for i in 0..n {
        let g = group[i];
        add_scaled(
            &mut share.as_mut_slice()[g * n..(g + 1) * n],
            column(i),
            t[i],
        );
        still[group[i]] &= slopes[i].abs() <= BLOCK_AT_REST * gmax;
    }
    let near: Vec<bool> = (0..n)
        .map(|i| {
            let block = escape.is_some_and(|c| share.column(group[i]).amax() < NEAR_STATIONARY * c);
            whole || (still[group[i]] && block)
        })
        .collect();
    if let Some(c) = escape {
        let tol = e.tolerance();
        for i in (0..n).filter(|&i| near[i] && e.values[i] < -tol) {
            let length = c / e.vectors.column(i).amax().max(1e-300);
            if t[i].abs() < length {
                let newton = t[i];
                t[i] = if slopes[i] > 0.0 { -length } else { length };
                escaped.push((i, t[i], newton));
            }
        }
    }
    (step(&t), escaped)
}

/// `d += v t` entry by entry: the sums of `d += v * t` (each product `v_k t`, then added),
/// without the vector of products.
fn add_scaled(d: &mut [f64], v: &[f64], t: f64) {
    for (dk, vk) in d.iter_mut().zip(v) {
        *dk += vk * t;
    }
}

/// The settling step where the convergence test finds the lowest eigenvalue within the
/// Hessian's error at a gradient below the tolerance (`Spectrum::unresolved`): the Newton step
/// along the resolved curvatures only, `d = −Σ_{λ_i > b} v_i (v_iᵀ∇f) / λ_i`, `b` that error
/// (`Spectrum::error`), and none along the others, whose magnitude steps `v_iᵀ∇f / |λ_i|`
/// are noise over noise. A leg hanging from a yaw tilted 1.3·10⁻⁷ rad (yaw curvature
/// 2·10⁻¹³ N m/rad) sat at `‖∇f‖∞` = 6·10⁻⁹ with `λ_min` = −1.2·10⁻⁸: the magnitude step moved
/// 0.05 along the yaw, brought the gradient back to 6·10⁻⁹, and no later step changed the
/// energy beyond rounding (`max_iterations`); the settling step lowers it to 2.6·10⁻¹³, where
/// the yaw's eigenvalue is resolved (neutral). Taken again only where the last settling step
/// halved the gradient (else the iteration goes on as before).
#[derive(Debug)]
pub(crate) struct Settle {
    /// The error `b` below which curvatures are left alone, where this iteration settles.
    band: Option<f64>,
    /// The gradient where the last step, if a settling one, started (else infinite).
    from: f64,
}

impl Default for Settle {
    fn default() -> Self {
        Settle {
            band: None,
            from: f64::INFINITY,
        }
    }
}

impl Settle {
    /// The convergence test found the lowest eigenvalue within the Hessian's error at the
    /// gradient `gnorm`: settle, unless the last settling step failed to halve the gradient.
    pub(crate) fn ask(&mut self, gnorm: f64) {
        self.band = (gnorm <= 0.5 * self.from).then_some(Spectrum::error(gnorm));
    }

    /// The band of this iteration's settling step, if it settles (then recorded as taken from
    /// `gnorm`), for the step at the gradient `gnorm`; clears the request.
    pub(crate) fn take(&mut self, gnorm: f64) -> Option<f64> {
        let band = self.band.take();
        self.from = band.map_or(f64::INFINITY, |_| gnorm);
        band
    }
}

/// The settling step at `g` ([`Settle`]): Newton along the eigen-directions of `e` whose
/// curvature is above `band`.
pub(crate) fn settling_step(e: &Spectrum, g: &DVector<f64>, band: f64) -> DVector<f64> {
    let mut d = DVector::zeros(g.len());
    for (i, &l) in e.values.iter().enumerate().filter(|&(_, &l)| l > band) {
        let v = e.vectors.column(i);
        d -= v * (v.dot(g) / l);
    }
    d
}

/// The decoupled block (module `stability::blocks`) of each eigenpair of `e`: that of its
/// largest entry (an eigenvector of `stability::blocks::block_symmetric_eigen` is zero outside
/// its block), the blocks those of `V Λ Vᵀ`.
fn groups(e: &Spectrum) -> Vec<usize> {
    let n = e.values.len();
    let h = &e.vectors * DMatrix::from_diagonal(&e.values) * e.vectors.transpose();
    let mut block = vec![0; n];
    for (b, members) in blocks(&h).iter().enumerate() {
        for &r in members {
            block[r] = b;
        }
    }
    (0..n).map(|i| block[e.vectors.column(i).iamax()]).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The exact spectrum of a symmetric matrix, ascending, as the minimizer gets it.
    fn spectrum(h: &DMatrix<f64>) -> Spectrum {
        let (values, vectors) = crate::solver::stability::blocks::block_symmetric_eigen(h);
        Spectrum {
            largest: values.amax(),
            values,
            vectors,
            exact: true,
            negative_by_inertia: None,
            basis: None,
        }
    }

    #[test]
    fn positive_definite_hessian_gives_the_newton_step() {
        let h = DMatrix::from_row_slice(2, 2, &[4.0, 1.0, 1.0, 3.0]);
        let g = DVector::from_vec(vec![1.0, -2.0]);
        let (d, _) = newton_step(&spectrum(&h), &g, None);
        // H d = −g.
        assert!((&h * &d + &g).amax() < 1e-14, "{d}");
    }

    #[test]
    fn negative_curvature_is_stepped_along_by_its_magnitude() {
        // f = −½ x² + y²: the step along x is −g_x/|λ| (downhill, away from the maximum).
        let h = DMatrix::from_row_slice(2, 2, &[-1.0, 0.0, 0.0, 2.0]);
        let g = DVector::from_vec(vec![-1e-3, 1.0]);
        let (d, _) = newton_step(&spectrum(&h), &g, None);
        assert!(
            (d[0] - 1e-3).abs() < 1e-15 && (d[1] + 0.5).abs() < 1e-15,
            "{d}"
        );
        assert!(g.dot(&d) < 0.0);
    }

    #[test]
    fn near_neutral_directions_are_floored_at_1e_12_of_the_largest() {
        let h = DMatrix::from_diagonal(&DVector::from_vec(vec![1e-20, 1.0]));
        let g = DVector::from_vec(vec![1e-9, 0.0]);
        let (d, _) = newton_step(&spectrum(&h), &g, None);
        assert!((d[0] + 1e-9 / 1e-12).abs() < 1e-9, "{d}");
    }

    #[test]
    fn near_a_maximum_every_negative_direction_is_left_by_a_saddle_step() {
        // f = −½ x² − 2 y² + z² near its top in x and y (‖s‖∞ = 2·10⁻⁸ < 0.1 c).
        let h = DMatrix::from_diagonal(&DVector::from_vec(vec![-1.0, -4.0, 1.0]));
        let g = DVector::from_vec(vec![-2e-8, 0.0, 1e-9]);
        let (d, escaped) = newton_step(&spectrum(&h), &g, Some(0.3));
        // Downhill along x (−sign g_x), +1 along y where the slope is 0, Newton along z.
        assert!(
            (d[0] - 0.3).abs() < 1e-15 && (d[1].abs() - 0.3).abs() < 1e-15,
            "{d}"
        );
        assert!((d[2] + 1e-9).abs() < 1e-20, "{d}");
        assert_eq!(escaped.len(), 2);
        for (i, t, newton) in escaped {
            assert!((d[i] - t).abs() < 1e-15);
            assert!(newton.abs() < 1e-7, "the magnitude step was {newton}");
        }
    }

    #[test]
    fn after_a_release_decided_by_the_step_the_escape_is_taken_on_a_long_step() {
        // f = −½ x² + y² far from stationary (‖s‖∞ = 0.5 ≥ 0.1 c): the magnitude step along x
        // (0.05) is shorter than its saddle step (0.3); only with `near` infinite (the round
        // after a release decided by the step) is x escaped, downhill.
        let h = DMatrix::from_diagonal(&DVector::from_vec(vec![-1.0, 2.0]));
        let g = DVector::from_vec(vec![-0.05, 1.0]);
        let (d, escaped) = newton_step(&spectrum(&h), &g, Some(0.3));
        assert!(escaped.is_empty(), "{escaped:?}");
        assert!((d[0] - 0.05).abs() < 1e-15, "{d}");
        let (d, escaped) = newton_step_within(&spectrum(&h), &g, Some(0.3), f64::INFINITY);
        assert_eq!(escaped.len(), 1, "{escaped:?}");
        assert!(
            (d[0] - 0.3).abs() < 1e-15 && (d[1] + 0.5).abs() < 1e-15,
            "{d}"
        );
        // A direction whose magnitude step is already longer keeps it.
        let g = DVector::from_vec(vec![-0.5, 1.0]);
        let (d, escaped) = newton_step_within(&spectrum(&h), &g, Some(0.3), f64::INFINITY);
        assert!(escaped.is_empty() && (d[0] - 0.5).abs() < 1e-15, "{d}");
    }

    #[test]
    fn a_decoupled_block_on_its_maximum_is_escaped_while_another_falls() {
        // Block {0}: a finger on its top (λ = −1, slope 0); block {1}: a thumb far from rest
        // (λ = 2, slope 1: a step of 0.5 ≥ 0.1 c); block {2}: a finger just off its top
        // (slope 10⁻⁶, not rounding): only block {0} is escaped.
        let h = DMatrix::from_diagonal(&DVector::from_vec(vec![-1.0, 2.0, -1.0]));
        let g = DVector::from_vec(vec![0.0, 1.0, 1e-6]);
        let (d, escaped) = newton_step(&spectrum(&h), &g, Some(0.3));
        assert_eq!(escaped.len(), 1, "{escaped:?}");
        assert!((d[0] - 0.3).abs() < 1e-15, "{d}");
        assert!(
            (d[1] + 0.5).abs() < 1e-15 && (d[2] + 1e-6).abs() < 1e-18,
            "{d}"
        );
        // Coupled (one block), the long step keeps every direction on its magnitude step.
        let mut h = h;
        h[(0, 1)] = 0.1;
        h[(1, 0)] = 0.1;
        let (_, escaped) = newton_step(&spectrum(&h), &g, Some(0.3));
        assert!(escaped.is_empty(), "{escaped:?}");
    }

    #[test]
    fn the_settling_step_leaves_curvatures_within_the_error_alone() {
        // f = −10⁻⁸ x²/2 + y² + 2 z²/2 (x unresolved at ‖g‖ = 6·10⁻⁹, band 6·10⁻⁸): Newton
        // along y and z, nothing along x.
        let h = DMatrix::from_diagonal(&DVector::from_vec(vec![-1e-8, 2.0, 4.0]));
        let g = DVector::from_vec(vec![6e-9, -2e-9, 4e-9]);
        let d = settling_step(&spectrum(&h), &g, Spectrum::error(g.amax()));
        assert_eq!(d[0], 0.0);
        assert!(
            (d[1] - 1e-9).abs() < 1e-24 && (d[2] + 1e-9).abs() < 1e-24,
            "{d}"
        );
        // A positive curvature within the band is left alone too.
        let h = DMatrix::from_diagonal(&DVector::from_vec(vec![3e-8, 2.0]));
        let d = settling_step(&spectrum(&h), &g.rows(0, 2).into_owned(), 6e-8);
        assert_eq!(d[0], 0.0);
    }

    #[test]
    fn settling_is_asked_again_only_after_the_gradient_halved() {
        let mut settle = Settle::default();
        settle.ask(6e-9);
        assert_eq!(settle.take(6e-9), Some(6e-8));
        // No request: no settling step, and the record is cleared.
        assert_eq!(settle.take(6e-9), None);
        settle.ask(6e-9);
        assert_eq!(settle.take(6e-9), Some(6e-8));
        // The gradient did not halve: the next step is an ordinary one, then settling again.
        settle.ask(4e-9);
        assert_eq!(settle.take(4e-9), None);
        settle.ask(4e-9);
        assert_eq!(settle.take(4e-9), Some(4e-8));
        settle.ask(1e-9);
        assert!(settle.take(1e-9).is_some());
    }

    #[test]
    fn away_from_stationary_points_the_step_is_the_magnitude_step() {
        // ‖s‖∞ = 0.5 ≥ 0.1 c: no escape, the step along x stays −g_x/|λ| however short.
        let h = DMatrix::from_diagonal(&DVector::from_vec(vec![-1.0, 2.0]));
        let g = DVector::from_vec(vec![-1e-6, 1.0]);
        let (d, escaped) = newton_step(&spectrum(&h), &g, Some(0.3));
        assert!(escaped.is_empty());
        assert!(
            (d[0] - 1e-6).abs() < 1e-18 && (d[1] + 0.5).abs() < 1e-15,
            "{d}"
        );
        // Curvature within the spectrum's tolerance is not negative.
        let h = DMatrix::from_diagonal(&DVector::from_vec(vec![-1e-12, 1.0]));
        let g = DVector::from_vec(vec![1e-9, 1e-9]);
        let (_, escaped) = newton_step(&spectrum(&h), &g, Some(0.3));
        assert!(escaped.is_empty());
    }
}
