//! The Newton step on a small tree: Newton on `Ĥ` far from the rest, the step along the path by
//! Cholesky near it.
//!
//! On the small trees of [`Backend::choose`] (fewer than 40 bodies, open, no stop, contact,
//! lock or mimic: `system::backend::small_tree`) the minimizer steps, as everywhere up to 64
//! degrees of freedom, by the Hessian along the search path `M = Ĥ + C` (module
//! `path_hessian`): the magnitude step `d = −Σ v_i (v_iᵀ∇f) / max(|λ_i|, ε λ_max)` from the
//! spectrum of `M` and the escape along its negative curvature (module `escape`). Three
//! shortcuts take the same steps with less work:
//!
//! 1. **Far from the rest** (`‖∇f‖∞ > τ Σ|V_k|`, `τ` = [`FAR`], `Σ|V_k|` the energy's terms'
//!    magnitudes), where the valley watch does not look (module `valley`), the step is Newton
//!    on `Ĥ` alone, `Ĥ d = −∇f` by Cholesky where `Ĥ` is positive definite above the floor
//!    (below), without `C`: the reduced Newton step of the KKT direction of the larger trees
//!    (module `kkt_direction`), which a small tree forms more cheaply than it builds the KKT
//!    structure for. Far from the rest the step is capped or cut by the line search anyway;
//!    `C ∝ ∇f` matters near it, where Newton on `Ĥ` converges with a larger constant (chain
//!    20 then takes 5 iterations instead of 4). Where `Ĥ` is not positive definite above the
//!    floor, `Ĥ` is decomposed and the step taken as in 3.
//! 2. **Near the rest, away from a stationary point** (`‖∇f‖∞` above the gradient tolerance),
//!    where the valley watch does not look, the spectrum of `Ĥ` is read by nothing: `Ĥ` is
//!    formed and not decomposed and `M` summed from it.
//! 3. Where the spectrum of `Ĥ` is read (the valley watch looks, module `valley`), `M` is
//!    summed from it as `V Λ Vᵀ + C`, the matrix `path_hessian::along_path` decomposes.
//!
//! In 2 and 3, where every eigenvalue of `M` lies above the magnitude step's floor, the step
//! is
//!
//! `M d = −∇f`,   by the Cholesky factor `M = L Lᵀ`,
//!
//! the magnitude step itself (no eigenvalue floored, no negative one to escape along). The
//! floor is `ε G`, `ε = EIGENVALUE_FLOOR`, `G = maxᵢ Σⱼ |M_ij| ≥ |λ|max` (Gershgorin): the
//! Cholesky factorization of `M − ε G I` succeeds only where `λ_min > ε G ≥ ε |λ|max`. Elsewhere
//! `M` is decomposed and the escape taken as before (module `escape`). What the valley watch
//! reads is unchanged: the spectrum of `Ĥ` wherever it looks, and that of `M` where `M` has a
//! neutral direction (`|λ| ≤ 10⁻¹² |λ|max`, `valley::Valley::along_path`), which a Cholesky
//! step's `M` has not (there the watch reads `None` instead of a spectrum it would refuse). At
//! a stationary point the convergence test decomposes `Ĥ` (the verdict's eigenvalues are
//! exact, module `stability::spectrum`).
//!
//! The steps are the decomposition's to rounding in 2 and 3, not to the bit (`M` summed from
//! `Ĥ` instead of `V Λ Vᵀ` in 2, solved by substitution instead of through eigenvectors), and
//! another direction in 1 (without `C`): the reason they are kept to small trees (on G1 and Romeo LAAS
//! small, which have stops, the rounding of `Ĥ` against `V Λ Vᵀ` moved the rests;
//! docs/benchmarks-history.md, session 27). On chains of 3 – 40 links every iteration count
//! and verdict is the decomposition's and every rest and eigenvalue equal to rounding
//! (docs/benchmarks-history.md, session 35).
//!
//! ## References
//! - J. Nocedal and S. J. Wright, *Numerical Optimization*, 2nd ed., Springer (2006), §3.4
//!   (Newton's method with Hessian modification) and A.1 (Cholesky, Gershgorin).

use crate::solver::inequality::active_set::Guard;
use crate::solver::options::Options;
use crate::solver::partition::Partition;
use crate::solver::stability::spectrum::{exact_spectrum, Spectrum};
use crate::solver::step::escape::escape_along;
use crate::solver::step::newton::EIGENVALUE_FLOOR;
use crate::solver::step::path_hessian::{
    path_curvature, path_keeps_rows, path_matrix, spectrum_of,
};
use crate::solver::system::{is_small_tree, symmetric_part, Backend, Eval, System};
use nalgebra::{DMatrix, DVector};

/// Far from the rest: `‖∇f‖∞` above this fraction of `Σ|V_k|` (module docs, 1). The
/// generated chains of 2 – 40 links keep every iteration count and rest (to 10⁻¹² relative)
/// from 0.1 to 1; at 0.03 chains 5 – 9 rest 3·10⁻¹² … 4·10⁻¹⁰ apart and chain 9 takes 4
/// iterations instead of 3 (measured with the KKT direction far from the rest, the same step
/// to rounding; docs/benchmarks-history.md, session 35).
pub(crate) const FAR: f64 = 0.3;

/// How the convergence test prepares the step on a small tree away from a stationary point
/// where the valley watch does not look (module docs): `Ĥ` formed and not decomposed, for
/// Newton on `Ĥ` far from the rest (1) or along the path near it (2).
pub(crate) enum Plan {
    /// Far from the rest (module docs, 1).
    Far(Formed),
    /// Near it (module docs, 2).
    Near(Formed),
}

/// The reduced Hessian `Ĥ` formed and not decomposed, with the null-space basis `Z` it was
/// formed with where it was kept (`System::reduced_hessian_and_basis`).
pub(crate) struct Formed {
    pub(crate) hessian: DMatrix<f64>,
    pub(crate) basis: Option<DMatrix<f64>>,
}

/// Whether `sys` is a small tree on its tree factors whose path keeps every row, stepped by
/// the exact Newton step (`dense_newton`: the method is Newton, at most 64 degrees of
/// freedom): where the steps of this module are taken (module docs).
pub(crate) fn small_tree(sys: &System, dense_newton: bool) -> bool {
    dense_newton
        && sys.backend == Backend::Tree
        && is_small_tree(sys.problem.model)
        && path_keeps_rows(sys)
}

/// The step's plan at `(q, part, eval)` with reduced gradient norm `gnorm` (tolerance `gtol`)
/// where `sys` is a small tree (`small`, [`small_tree`]) and the valley watch does not look
/// (`watched` false): `Ĥ` formed, far from the rest or near it (module docs); `None`
/// elsewhere (the convergence test decomposes `Ĥ` as before).
pub(crate) fn plan(
    sys: &mut System,
    (q, part, eval): (&DVector<f64>, &Partition, &Eval),
    small: bool,
    (gnorm, gtol): (f64, f64),
    watched: bool,
) -> Option<Plan> {
    if !small || gnorm <= gtol || watched || part.independent.is_empty() {
        return None;
    }
    let (hessian, basis) = sys.reduced_hessian_and_basis(q, part, eval);
    let formed = Formed { hessian, basis };
    Some(match gnorm > FAR * eval.energy.magnitude {
        true => Plan::Far(formed),
        false => Plan::Near(formed),
    })
}

/// The step of `plan` at `q` (module docs): far from the rest Newton on `Ĥ` by Cholesky, or
/// where `Ĥ` is not positive definite above the floor the step along the path from its
/// spectrum ([`spectrum_step`]); near it [`formed_step`]. The step, whether it escaped along
/// a direction of negative curvature, and the spectrum of `Ĥ + C` where it was computed.
pub(crate) fn planned_step(
    sys: &mut System,
    at: (&DVector<f64>, &Partition, &Eval),
    plan: Plan,
    guard: Option<&Guard>,
    options: &Options,
) -> (DVector<f64>, bool, Option<Spectrum>) {
    match plan {
        Plan::Far(formed) => match definite_step(&formed.hessian, &at.2.grad_v) {
            Some(d) => (d, false, None),
            None => {
                let e = exact_spectrum(&formed.hessian, formed.basis);
                spectrum_step(sys, at, &e, guard, options)
            }
        },
        Plan::Near(formed) => formed_step(sys, at, formed, guard, options),
    }
}

/// The Newton step along the path at `q` from `Ĥ` formed (module docs, 2): see [`step`].
pub(crate) fn formed_step(
    sys: &mut System,
    (q, part, eval): (&DVector<f64>, &Partition, &Eval),
    formed: Formed,
    guard: Option<&Guard>,
    options: &Options,
) -> (DVector<f64>, bool, Option<Spectrum>) {
    let mut m = formed.hessian;
    m += path_curvature(sys, q, part, eval, formed.basis.as_ref());
    step(sys, (q, part, eval), symmetric_part(m), guard, options)
}

/// The Newton step along the path at `q` from the exact spectrum `e` of `Ĥ` (module docs, 3):
/// see [`step`].
pub(crate) fn spectrum_step(
    sys: &mut System,
    (q, part, eval): (&DVector<f64>, &Partition, &Eval),
    e: &Spectrum,
    guard: Option<&Guard>,
    options: &Options,
) -> (DVector<f64>, bool, Option<Spectrum>) {
    let m = path_matrix(sys, q, part, eval, e);
    step(sys, (q, part, eval), m, guard, options)
}

/// The Newton step `d` along the path at `q` with the symmetric `M = Ĥ + C`: by Cholesky where
/// `M` is positive definite above the floor (no escape, no spectrum), else as
/// `escape::escape_step` with the spectrum of `M`; whether it escaped, and that spectrum where
/// it was computed.
fn step(
    sys: &mut System,
    (q, part, eval): (&DVector<f64>, &Partition, &Eval),
    m: DMatrix<f64>,
    guard: Option<&Guard>,
    options: &Options,
) -> (DVector<f64>, bool, Option<Spectrum>) {
    if let Some(d) = definite_step(&m, &eval.grad_v) {
        return (d, false, None);
    }
    let (d, escaped, path) = escape_along(sys, q, part, eval, spectrum_of(&m), guard, options);
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
    use crate::solver::step::kkt_direction::kkt_direction;
    use crate::solver::step::path_hessian::along_path;
    use crate::solver::step::retraction::tests::ARM;
    use crate::solver::system::Backend;
    use crate::solver::valley::Valley;
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

    /// `(Ĥ, Z)` formed at `q` (module docs, 2).
    fn formed(sys: &mut System, q: &DVector<f64>, part: &Partition, eval: &Eval) -> Formed {
        let (hessian, basis) = sys.reduced_hessian_and_basis(q, part, eval);
        Formed { hessian, basis }
    }

    /// Away from the rest, where `Ĥ + C` is positive definite, the Cholesky step (from `Ĥ`
    /// formed, and from the spectrum of `Ĥ`) equals the decomposition's magnitude step (module
    /// `escape`, from the spectrum of `Ĥ`) to 10⁻¹²; the spectrum of `Ĥ + C` it does not
    /// compute would give the valley watch nothing (no neutral direction).
    #[test]
    fn cholesky_step_is_the_magnitude_step_where_definite() {
        let (model, q) = chain_at(|i| 0.3 * (i as f64).sin() - 1.2);
        let sys = &mut System::new(&model, Constraints::new(&model, &[]), Backend::Tree);
        let part = sys.partition(&q);
        let eval = sys.evaluate(&q, &part).unwrap();
        let options = Options::default();
        assert!(eval.grad_v.amax() > 1.0, "a point away from the rest");
        assert!(small_tree(sys, true));
        let e = crate::solver::stability::spectrum::spectrum(sys, &q, &part, &eval);
        let path = along_path(sys, &q, &part, &eval, &e);
        assert!(path.values.min() > 0.0, "Ĥ + C positive definite here");
        assert!(Valley::along_path(&path).is_none());
        let (by_spectrum, escaped, _) = escape_step(sys, &q, &part, &eval, &e, None, &options);
        assert!(!escaped);
        let f = formed(sys, &q, &part, &eval);
        let at = (&q, &part, &eval);
        let (d, escaped, spectrum) = formed_step(sys, at, f, None, &options);
        assert!(!escaped && spectrum.is_none(), "taken by Cholesky");
        let err = (&d - &by_spectrum).amax() / by_spectrum.amax();
        assert!(err < 1e-12, "from Ĥ formed: relative difference {err:e}");
        let (d, escaped, spectrum) = spectrum_step(sys, at, &e, None, &options);
        assert!(!escaped && spectrum.is_none(), "taken by Cholesky");
        let err = (&d - &by_spectrum).amax() / by_spectrum.amax();
        assert!(
            err < 1e-12,
            "from the spectrum: relative difference {err:e}"
        );
    }

    /// Where `Ĥ + C` has negative curvature (the branched arm of module `retraction`'s tests,
    /// its lift raised), the step falls back to the spectrum of `Ĥ + C` and is the
    /// decomposition's to rounding along every resolved eigen-direction. (The arm has three
    /// neutral ones, `λ` at 0 and 10⁻¹⁶: the magnitude step divides their slopes, at rounding
    /// level, by the floor, so there the two steps differ by their rounding.) From the spectrum
    /// of `Ĥ` it is the decomposition's step to the bit, and hands the valley watch the same
    /// spectrum of `Ĥ + C`.
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
        let at = (&q, &part, &eval);
        let (d, escaped_here, spectrum) = spectrum_step(sys, at, &e, None, &options);
        assert_eq!((d.clone(), escaped_here), (by_spectrum.clone(), escaped));
        let spectrum = spectrum.expect("decomposed where indefinite");
        assert_eq!(
            (&spectrum.values, &spectrum.vectors),
            (&path.values, &path.vectors)
        );
        let f = formed(sys, &q, &part, &eval);
        let (d, escaped_here, spectrum) = formed_step(sys, at, f, None, &options);
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

    /// The plan: far from the rest Newton on `Ĥ` (the reduced KKT step, module
    /// `kkt_direction`, to 10⁻¹²), near it the step along the path; none at a stationary
    /// point or where the valley watch looks.
    #[test]
    fn far_from_the_rest_newton_on_the_reduced_hessian() {
        let (model, q) = chain_at(|_| 0.5);
        let sys = &mut System::new(&model, Constraints::new(&model, &[]), Backend::Tree);
        let part = sys.partition(&q);
        let eval = sys.evaluate(&q, &part).unwrap();
        let options = Options::default();
        let at = (&q, &part, &eval);
        let far = FAR * eval.energy.magnitude;
        assert!(far > 1.0);
        let gtol = 1e-8;
        let Some(Plan::Far(f)) = plan(sys, at, true, (2.0 * far, gtol), false) else {
            panic!("far from the rest");
        };
        assert_eq!(f.hessian, formed(sys, &q, &part, &eval).hessian);
        let (d, escaped, spectrum) = planned_step(sys, at, Plan::Far(f), None, &options);
        assert!(!escaped && spectrum.is_none(), "taken by Cholesky");
        let (by_kkt, definite) = kkt_direction(sys, &q, &part, &eval);
        assert!(definite, "Ĥ positive definite here");
        let err = (&d - &by_kkt).amax() / by_kkt.amax();
        assert!(err < 1e-12, "relative difference {err:e}");
        let Some(Plan::Near(f)) = plan(sys, at, true, (0.5 * far, gtol), false) else {
            panic!("near the rest");
        };
        let (d, _, _) = planned_step(sys, at, Plan::Near(f), None, &options);
        let f = formed(sys, &q, &part, &eval);
        let (by_path, _, _) = formed_step(sys, at, f, None, &options);
        assert_eq!(d, by_path);
        assert!(
            (&d - &by_kkt).amax() > 1e-6 * by_kkt.amax(),
            "C changes the step"
        );
        assert!(
            plan(sys, at, true, (1e-9, gtol), false).is_none(),
            "stationary"
        );
        assert!(
            plan(sys, at, true, (2.0 * far, gtol), true).is_none(),
            "watched"
        );
        assert!(
            plan(sys, at, false, (2.0 * far, gtol), false).is_none(),
            "no small tree"
        );
    }

    /// Only small trees on their tree factors with the exact Newton step: not a long chain
    /// (tree factors, sparse size), not a chain with stops, not the dense path, not BFGS.
    #[test]
    fn applies_to_small_trees_only() {
        let (model, _) = chain_at(|_| 0.5);
        let tree = System::new(&model, Constraints::new(&model, &[]), Backend::Tree);
        assert!(small_tree(&tree, true));
        assert!(!small_tree(&tree, false), "no exact Newton step");
        let dense = System::new(&model, Constraints::new(&model, &[]), Backend::Dense);
        assert!(!small_tree(&dense, true));
        let long = crate::generate::chain(41, false);
        let long = load_str(&long, "c.urdf", &ImportOptions::default())
            .unwrap()
            .model;
        let sys = System::new(&long, Constraints::new(&long, &[]), Backend::Tree);
        assert!(!small_tree(&sys, true), "41 bodies");
        let limited = include_str!("../../../robots/panda_class.urdf");
        let limited = load_str(limited, "panda.urdf", &ImportOptions::default())
            .unwrap()
            .model;
        let sys = System::new(&limited, Constraints::new(&limited, &[]), Backend::Tree);
        assert!(!small_tree(&sys, true), "stops");
    }
}
