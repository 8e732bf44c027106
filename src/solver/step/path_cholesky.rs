//! The Newton step along the path on a small tree, by Cholesky away from stationary points.
//!
//! On the small trees of [`Backend::choose`] (fewer than 40 bodies, open, no stop, contact,
//! lock or mimic: `system::backend::small_tree`) the minimizer steps by the Hessian along the
//! search path `Ĥ + C` (module `path_hessian`) and, as everywhere up to 64 degrees of freedom,
//! decomposes it: the magnitude step `d = −Σ v_i (v_iᵀ∇f) / max(|λ_i|, ε λ_max)` and the escape
//! along its negative curvature (module `escape`). Away from a stationary point
//! (`‖∇f‖∞` above the gradient tolerance) and where the valley watch does not look (module
//! `valley`), the spectrum of `Ĥ` itself is read by nothing: `Ĥ` is formed and not decomposed,
//! `M = Ĥ + C` is summed from it, and where every eigenvalue of `M` lies above the magnitude
//! step's floor the step is
//!
//! `M d = −∇f`,   by the Cholesky factor `M = L Lᵀ`,
//!
//! the magnitude step itself (no eigenvalue floored, no negative one to escape along). The
//! floor is `ε G`, `ε = EIGENVALUE_FLOOR`, `G = maxᵢ Σⱼ |M_ij| ≥ |λ|max` (Gershgorin): the
//! Cholesky factorization of `M − ε G I` succeeds only where `λ_min > ε G ≥ ε |λ|max`. Elsewhere
//! `M` is decomposed and the escape taken as before (module `escape`). At a stationary point
//! the convergence test decomposes `Ĥ` (the verdict's eigenvalues are exact, module
//! `stability::spectrum`).
//!
//! The step is the decomposition's to rounding, not to the bit: `M` is summed from `Ĥ` instead
//! of `V Λ Vᵀ`, and solved by substitution instead of through eigenvectors (the reason it is
//! kept to small trees: on G1 and Romeo LAAS small, which have stops, the rounding of `Ĥ`
//! against `V Λ Vᵀ` moved the rests; docs/benchmarks-history.md, session 27). On chains of
//! 3 – 40 links every iteration count, rest and eigenvalue is the decomposition's (energies to
//! 2·10⁻¹⁵ relative, joint values to 4·10⁻¹⁶ rad); a chain of 20 takes 0.83 of the
//! instructions (docs/benchmarks-history.md, session 34).
//!
//! ## References
//! - J. Nocedal and S. J. Wright, *Numerical Optimization*, 2nd ed., Springer (2006), §3.4
//!   (Newton's method with Hessian modification) and A.1 (Cholesky, Gershgorin).

use crate::solver::inequality::active_set::Guard;
use crate::solver::options::Options;
use crate::solver::partition::Partition;
use crate::solver::stability::blocks::block_symmetric_eigen;
use crate::solver::stability::spectrum::Spectrum;
use crate::solver::step::escape::escape_along;
use crate::solver::step::newton::EIGENVALUE_FLOOR;
use crate::solver::step::path_hessian::{path_curvature, path_keeps_rows};
use crate::solver::system::{is_small_tree, symmetric_part, Backend, Eval, System};
use nalgebra::{DMatrix, DVector};

/// The reduced Hessian `Ĥ` formed and not decomposed, with the null-space basis `Z` it was
/// formed with where it was kept (`System::reduced_hessian_and_basis`).
pub(crate) struct Formed {
    pub(crate) hessian: DMatrix<f64>,
    pub(crate) basis: Option<DMatrix<f64>>,
}

/// Whether the step at a point with reduced gradient `gnorm` (tolerance `gtol`) is taken from
/// `Ĥ` formed and not decomposed (module docs): a small tree on its tree factors whose path
/// keeps every row, a Newton step up to 64 degrees of freedom (`dense_newton`), away from a
/// stationary point, the valley watch not looking (`watched`).
pub(crate) fn applies(
    sys: &System,
    dense_newton: bool,
    gnorm: f64,
    gtol: f64,
    watched: bool,
) -> bool {
    dense_newton
        && gnorm > gtol
        && !watched
        && sys.backend == Backend::Tree
        && is_small_tree(sys.problem.model)
        && path_keeps_rows(sys)
}

/// `Ĥ` at `q`, formed (module docs).
pub(crate) fn formed(sys: &mut System, q: &DVector<f64>, part: &Partition, eval: &Eval) -> Formed {
    let (hessian, basis) = sys.reduced_hessian_and_basis(q, part, eval);
    Formed { hessian, basis }
}

/// The Newton step `d` along the path at `q` from `Ĥ` formed (module docs): by Cholesky where
/// `Ĥ + C` is positive definite above the floor (no escape, no spectrum), else as
/// `escape::escape_step` with the spectrum of `Ĥ + C`; whether it escaped, and that spectrum
/// where it was computed.
pub(crate) fn path_newton_step(
    sys: &mut System,
    (q, part, eval): (&DVector<f64>, &Partition, &Eval),
    formed: Formed,
    guard: Option<&Guard>,
    options: &Options,
) -> (DVector<f64>, bool, Option<Spectrum>) {
    let mut m = formed.hessian;
    m += path_curvature(sys, q, part, eval, formed.basis.as_ref());
    let m = symmetric_part(m);
    if let Some(d) = definite_step(&m, &eval.grad_v) {
        return (d, false, None);
    }
    let (values, vectors) = block_symmetric_eigen(&m);
    let path = Spectrum {
        largest: values.amax(),
        values,
        vectors,
        exact: true,
        negative_by_inertia: None,
        basis: None,
    };
    let (d, escaped, path) = escape_along(sys, q, part, eval, path, guard, options);
    (d, escaped, Some(path))
}

/// `−M⁻¹ g` by Cholesky where every eigenvalue of the symmetric `M` lies above
/// `EIGENVALUE_FLOOR · G`, `G` its largest absolute row sum (module docs); `None` elsewhere.
fn definite_step(m: &DMatrix<f64>, g: &DVector<f64>) -> Option<DVector<f64>> {
    let n = m.nrows();
    let rows = (0..n)
        .map(|i| m.row(i).iter().map(|x| x.abs()).sum::<f64>())
        .fold(0.0, f64::max);
    let floor = EIGENVALUE_FLOOR * rows.max(1e-12);
    let shifted = m - DMatrix::identity(n, n) * floor;
    shifted.cholesky()?;
    let factor = m.clone().cholesky()?;
    Some(-factor.solve(g))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::constraints::Constraints;
    use crate::solver::step::escape::escape_step;
    use crate::solver::step::path_hessian::along_path;
    use crate::solver::step::retraction::tests::ARM;
    use crate::solver::system::Backend;
    use crate::state::State;
    use crate::urdf::{load_str, ImportOptions};

    /// A chain of 12 links at a bent pose, on its tree factors, its first partition.
    fn chain_at(angle: impl Fn(usize) -> f64) -> (crate::model::Model, DVector<f64>) {
        let text = crate::generate::chain(12, false);
        let model = load_str(&text, "c.urdf", &ImportOptions::default())
            .unwrap()
            .model;
        let values: crate::state::JointValues = (0..12)
            .map(|i| (format!("joint{i}"), vec![angle(i)]))
            .collect();
        let q = State::from_joint_values(&model, &values).q;
        (model, q)
    }

    /// Away from the rest, where `Ĥ + C` is positive definite, the Cholesky step equals the
    /// decomposition's magnitude step (module `escape`, from the spectrum of `Ĥ`) to rounding.
    #[test]
    fn cholesky_step_is_the_magnitude_step_where_definite() {
        let (model, q) = chain_at(|i| 0.3 * (i as f64).sin() - 1.2);
        let sys = &mut System::new(&model, Constraints::new(&model, &[]), Backend::Tree);
        let part = sys.partition(&q);
        let eval = sys.evaluate(&q, &part).unwrap();
        let options = Options::default();
        assert!(eval.grad_v.amax() > 1.0, "a point away from the rest");
        assert!(applies(sys, true, eval.grad_v.amax(), 1e-8, false));
        let e = crate::solver::stability::spectrum::spectrum(sys, &q, &part, &eval);
        let path = along_path(sys, &q, &part, &eval, &e);
        assert!(path.values.min() > 0.0, "Ĥ + C positive definite here");
        let (by_spectrum, escaped, _) = escape_step(sys, &q, &part, &eval, &e, None, &options);
        assert!(!escaped);
        let f = formed(sys, &q, &part, &eval);
        let (d, escaped, spectrum) = path_newton_step(sys, (&q, &part, &eval), f, None, &options);
        assert!(!escaped && spectrum.is_none(), "taken by Cholesky");
        let err = (&d - &by_spectrum).amax() / by_spectrum.amax();
        assert!(err < 1e-12, "relative difference {err:e}");
    }

    /// Where `Ĥ + C` has negative curvature (the branched arm of module `retraction`'s tests,
    /// its lift raised), the step falls back to the spectrum of `Ĥ + C` and is the
    /// decomposition's to rounding along every resolved eigen-direction. (The arm has three
    /// neutral ones, `λ` at 0 and 10⁻¹⁶: the magnitude step divides their slopes, at rounding
    /// level, by the floor, so there the two steps differ by their rounding.)
    #[test]
    fn indefinite_path_hessian_falls_back_to_the_spectrum() {
        let model = load_str(ARM, "arm.urdf", &ImportOptions::default())
            .unwrap()
            .model;
        let values: crate::state::JointValues =
            [("pan", 0.4), ("slide", 0.1), ("roll", -0.7), ("lift", 1.1)]
                .iter()
                .map(|(n, v)| (n.to_string(), vec![*v]))
                .collect();
        let q = State::from_joint_values(&model, &values).q;
        let sys = &mut System::new(&model, Constraints::new(&model, &[]), Backend::Tree);
        let part = sys.partition(&q);
        let eval = sys.evaluate(&q, &part).unwrap();
        let options = Options::default();
        let e = crate::solver::stability::spectrum::spectrum(sys, &q, &part, &eval);
        let path = along_path(sys, &q, &part, &eval, &e);
        assert!(
            path.values.min() < -1.0,
            "negative curvature along the path"
        );
        let (by_spectrum, escaped, _) = escape_step(sys, &q, &part, &eval, &e, None, &options);
        let f = formed(sys, &q, &part, &eval);
        let (d, escaped_here, spectrum) =
            path_newton_step(sys, (&q, &part, &eval), f, None, &options);
        let spectrum = spectrum.expect("decomposed where indefinite");
        assert_eq!(escaped_here, escaped);
        let lambda = (&spectrum.values - &path.values).amax() / path.values.amax();
        assert!(lambda < 1e-12, "eigenvalues differ by {lambda:e}");
        let resolved: Vec<usize> = (0..path.values.len())
            .filter(|&i| path.values[i].abs() > 1e-8 * path.largest)
            .collect();
        assert_eq!(resolved.len(), 2);
        let along = |x: &DVector<f64>, i: usize| path.vectors.column(i).dot(x);
        let scale = resolved
            .iter()
            .map(|&i| along(&by_spectrum, i).abs())
            .fold(0.0, f64::max);
        assert!(scale > 0.0);
        for &i in &resolved {
            let err = (along(&d, i) - along(&by_spectrum, i)).abs() / scale;
            assert!(err < 1e-12, "direction {i}: relative difference {err:e}");
        }
    }

    /// Only small trees on their tree factors: not a long chain (tree factors, sparse size),
    /// not a chain with stops, not the dense path.
    #[test]
    fn applies_to_small_trees_only() {
        let (model, q) = chain_at(|_| 0.5);
        let tree = System::new(&model, Constraints::new(&model, &[]), Backend::Tree);
        assert!(applies(&tree, true, 1.0, 1e-8, false));
        assert!(!applies(&tree, true, 1e-9, 1e-8, false), "stationary");
        assert!(
            !applies(&tree, true, 1.0, 1e-8, true),
            "the valley watch looks"
        );
        assert!(
            !applies(&tree, false, 1.0, 1e-8, false),
            "no exact Newton step"
        );
        let dense = System::new(&model, Constraints::new(&model, &[]), Backend::Dense);
        assert!(!applies(&dense, true, 1.0, 1e-8, false));
        let long = crate::generate::chain(41, false);
        let long = load_str(&long, "c.urdf", &ImportOptions::default())
            .unwrap()
            .model;
        let sys = System::new(&long, Constraints::new(&long, &[]), Backend::Tree);
        assert!(!applies(&sys, true, 1.0, 1e-8, false), "41 bodies");
        let limited = include_str!("../../../robots/panda_class.urdf");
        let limited = load_str(limited, "panda.urdf", &ImportOptions::default())
            .unwrap()
            .model;
        let sys = System::new(&limited, Constraints::new(&limited, &[]), Backend::Tree);
        assert!(!applies(&sys, true, 1.0, 1e-8, false), "stops");
        assert!(q.iter().all(|x| x.is_finite()));
    }
}
