//! Stability on the critical cone: stops and contacts that touch without carrying a force.
//!
//! At a rest with active inequalities, those that carry a force (`λ > 0`, strongly active)
//! hold to second order like equality rows; those that touch with `λ = 0` (weakly active: a
//! box pressed down over its diagonal rests on two corners, the other two touch without
//! force) only forbid moving into them. The rest is a strict local minimum when the
//! second-order sufficient condition holds on the critical cone
//!
//! ```text
//! dᵀ Ĥ d > 0   for every d ≠ 0 in   C = { d : a_w · d ≥ 0 for every weak w },
//! ```
//!
//! `Ĥ = Zᵀ W Z` the reduced Hessian on the tangent space of the equality rows and the strong
//! inequalities, `a_w = Zᵀ ∇g_w` the weak inequality's gradient in its coordinates (a sticking
//! contact also holds its two tangential rows while it touches: `a_w · d = 0` then forces
//! them to zero too). The minimum of the Rayleigh quotient `dᵀĤd / dᵀd` over `C` lies in the
//! relative interior of a face `F_S = { a_w · d = 0 (w ∈ S), a_w · d > 0 (w ∉ S) }`, where it is
//! a local minimum of the quotient on the subspace `{ a_w · d = 0, w ∈ S }`, hence an
//! eigenvector of the smallest eigenvalue of `Ĥ` restricted to it. So
//!
//! ```text
//! min_C dᵀĤd / dᵀd = min over faces S of λ_min(Ĥ_S), among those whose eigenvector ± lies in C,
//! ```
//!
//! `2^k` faces for `k` weak inequalities. `Ĥ_S` is formed as `P Ĥ P + c (I − P)`, `P` the
//! orthogonal projector onto the subspace (from an SVD of the held rows) and `c` above every
//! eigenvalue of `Ĥ`, so that its smallest eigenvalue is `λ_min(Ĥ_S)`. When that eigenvalue
//! is repeated and no basis vector of its eigenspace lies in `C`, the face counts anyway
//! (conservative: the verdict may then say unstable or neutral where the cone is stable).
//!
//! Where the search path keeps every row, the cone is judged on the Hessian along that path
//! `Ĥ + C` (module `step::path_hessian`; for a tree, the Hessian in the joint coordinates)
//! rather than on `Ĥ`: at a point stationary to `‖∂V/∂v‖ = g`, `Ĥ` reads a direction whose
//! energy is exactly flat (a vertical waist, a finger whose energy is linear in its slide) as
//! `−g·a`, `a` that direction's acceleration in the chart, of either sign and above the
//! tolerance; `Ĥ + C` reads it at rounding. The weak rows leave a reduced gradient `g` on the
//! tangent space of the strong ones (their efforts, of either sign, below the active set's
//! threshold: unresolved): along a unit direction `d` the energy changes by
//! `g·d s + ½ κ s²`, and a curvature `|κ| ≤ ‖g‖∞` decides the sign of that change only beyond
//! `s = 2`, outside the quadratic model. The tolerance here is therefore
//! `t = max(10⁻¹⁰ max(λ_max, 1), ‖g‖∞)` (`λ_max` of `Ĥ`), and that is the `tolerance`
//! reported. (`C` is formed only where `Ĥ`'s smallest eigenvalue is below `t + 10 ‖g‖∞`, the
//! Hessian's error: above, the cone is stable either way.)
//!
//! ## References
//! - J. Nocedal, S. J. Wright, *Numerical Optimization*, 2nd ed., Springer (2006), §12.5
//!   (second-order conditions, the critical cone).

use super::eigen::symmetric_eigen;
use super::spectrum::{Spectrum, EXACT_UP_TO};
use crate::constraints::unilateral::{self, Active};
use crate::constraints::Constraints;
use crate::model::Model;
use crate::solver::report::{Stability, Verdict};
use crate::solver::step::path_hessian::{path_curvature, path_keeps_rows};
use crate::solver::system::{Backend, System};
use crate::State;
use nalgebra::{DMatrix, DVector};

/// Weak inequalities at most for the face enumeration (`2^k` faces); above, the verdict is
/// the one on the tangent space of the strong rows alone (conservative).
pub(crate) const MAX_WEAK: usize = 10;

/// Relative tolerance of `a_w · d ≥ 0` for an eigenvector `d`.
pub(super) const CONE_TOLERANCE: f64 = 1e-9;

/// The smallest Rayleigh quotient of `h` over the cone `{ d : weak[w].row(0) · d ≥ 0 }`, where
/// a weak inequality held at zero also holds its other rows (`weak[w]`: rows × dof).
/// `eig_tol` separates repeated eigenvalues.
pub(crate) fn minimum(h: &DMatrix<f64>, weak: &[DMatrix<f64>], eig_tol: f64) -> f64 {
    minimum_with_direction(h, weak, eig_tol).0
}

/// [`minimum`], and a unit direction of the cone that attains it (signed into the cone), where
/// an eigenvector of the minimizing face lies in it (`None` where the face counted only
/// because its eigenvalue is repeated).
pub(crate) fn minimum_with_direction(
    h: &DMatrix<f64>,
    weak: &[DMatrix<f64>],
    eig_tol: f64,
) -> (f64, Option<DVector<f64>>) {
    let dof = h.nrows();
    let k = weak.len();
    let shift = 4.0 * h.amax() + 1.0;
    let mut best = f64::INFINITY;
    let mut direction = None;
    for mask in 0usize..(1 << k) {
        let held: Vec<usize> = (0..k).filter(|w| mask >> w & 1 == 1).collect();
        let rows: usize = held.iter().map(|&w| weak[w].nrows()).sum();
        let mut range = DMatrix::zeros(dof, dof);
        let mut rank = 0;
        if rows > 0 {
            let mut a = DMatrix::zeros(rows, dof);
            let mut r = 0;
            for &w in &held {
                for i in 0..weak[w].nrows() {
                    a.set_row(r, &weak[w].row(i));
                    r += 1;
                }
            }
            let Some(svd) = super::svd::svd(a, false, true) else {
                continue;
            };
            let smax = svd.singular_values.max();
            if let Some(vt) = svd.v_t {
                for (i, &s) in svd.singular_values.iter().enumerate() {
                    if s > 1e-10 * smax && s > 0.0 {
                        let v = vt.row(i).transpose();
                        range += &v * v.transpose();
                        rank += 1;
                    }
                }
            }
        }
        if rank >= dof {
            continue;
        }
        let p = DMatrix::identity(dof, dof) - &range;
        let m = &p * h * &p + range * shift;
        let (vals, vecs) = symmetric_eigen(&m);
        let lam = vals[0];
        if lam >= best {
            continue;
        }
        let in_cone = |d: &DVector<f64>| {
            (0..k).filter(|w| mask >> w & 1 == 0).all(|w| {
                let a = weak[w].row(0);
                a.dot(&d.transpose()) >= -CONE_TOLERANCE * a.norm() * d.norm()
            })
        };
        let repeated: Vec<usize> = (0..dof).take_while(|&i| vals[i] <= lam + eig_tol).collect();
        let feasible = repeated.iter().find_map(|&i| {
            let d = vecs.column(i).into_owned();
            if in_cone(&d) {
                Some(d)
            } else if in_cone(&-&d) {
                Some(-d)
            } else {
                None
            }
        });
        if feasible.is_some() || repeated.len() > 1 {
            best = lam;
            direction = feasible;
        }
    }
    (best, direction)
}

/// The stability verdict at a balanced rest where the stops and contacts `strong` carry a
/// force and `weak` touch without one: the reported eigenvalues and modes are those of the
/// tangent space of all of them (every touching row held), the verdict is the critical
/// cone's. `None` where there is no degree of freedom even without the weak ones;
/// `eigenvalues` as in `solver::stability_of`. `all_held`: the verdict on the tangent space of
/// all of them if already at hand (the active-set round that ended at `state` held every one
/// as a row, and judged it): its eigenvalues and modes are reported instead of judging that
/// space again.
pub(crate) fn stability_touching(
    model: &Model,
    state: &State,
    strong: &[Active],
    weak: &[Active],
    backend: Backend,
    eigenvalues: bool,
    all_held: Option<Stability>,
) -> Option<Stability> {
    let (held, weak) = both_stops_held(strong, weak);
    let (strong, weak) = (held.as_slice(), weak.as_slice());
    if weak.is_empty() {
        return all_held
            .or_else(|| crate::solver::stability_on(model, state, strong, backend, eigenvalues));
    }
    // Too many faces: the tangent space of the strong rows alone, without partitioning it
    // here first (where it has no degree of freedom, neither has that of all rows, and
    // `stability_on` gives both the same answer).
    if weak.len() > MAX_WEAK {
        return crate::solver::stability_on(model, state, strong, backend, eigenvalues);
    }
    let all: Vec<Active> = strong.iter().chain(weak).copied().collect();
    let q = &state.q;
    let (mut sys, part) = strong_system(model, state, strong, backend);
    let dof = part.independent.len();
    if dof == 0 {
        return crate::solver::stability_on(model, state, &all, backend, eigenvalues);
    }
    if dof > EXACT_UP_TO {
        return crate::solver::stability_on(model, state, strong, backend, eigenvalues);
    }
    let eval = sys.evaluate(q, &part)?;
    let (h, vals, tol) = judged_hessian(&mut sys, q, &part, &eval);
    let rows = weak_rows(model, state, &sys, &part, &eval, weak)?;
    let lowest = if vals[0] > tol {
        vals[0]
    } else {
        minimum(&h, &rows, tol)
    };
    let verdict = if lowest < -tol {
        Verdict::Unstable
    } else if lowest <= tol {
        Verdict::Neutral
    } else {
        Verdict::Stable
    };
    let shown = all_held
        .or_else(|| crate::solver::stability_on(model, state, &all, backend, eigenvalues))
        .or_else(|| crate::solver::stability_on(model, state, strong, backend, eigenvalues));
    shown.map(|mut s| {
        s.verdict = verdict;
        s.tolerance = tol;
        s
    })
}

/// The system holding the rows that carry a force (`strong`) at `state`, partitioned there.
pub(super) fn strong_system<'m>(
    model: &'m Model,
    state: &State,
    strong: &[Active],
    backend: Backend,
) -> (System<'m>, crate::solver::partition::Partition) {
    let cons = Constraints::new(model, &crate::solver::lock_values(model))
        .with_active(model, strong)
        .on_branches(state.branches.clone());
    let mut sys = System::new(model, cons, backend);
    let part = sys.partition(&state.q);
    (sys, part)
}

/// The Hessian the cone is judged on, its eigenvalues and the tolerance: the tolerance from
/// `Ĥ`'s spectrum, as on the tangent space of every row, floored at what the weak rows'
/// unresolved efforts leave undecided; the Hessian along the search path where the path keeps
/// every row and `Ĥ`'s smallest eigenvalue is within its error (module docs).
pub(super) fn judged_hessian(
    sys: &mut System,
    q: &DVector<f64>,
    part: &crate::solver::partition::Partition,
    eval: &crate::solver::system::Eval,
) -> (DMatrix<f64>, DVector<f64>, f64) {
    let reduced = sys.reduced_hessian(q, part, eval);
    let (reduced_vals, _) = symmetric_eigen(&reduced);
    let tol = 1e-10 * reduced_vals.amax().max(1.0);
    let unresolved = reduced_vals[0] <= tol + Spectrum::error(eval.grad_v.amax());
    let (h, vals) = if unresolved && path_keeps_rows(sys) {
        let h = crate::solver::system::symmetric_part(
            reduced + path_curvature(sys, q, part, eval, None),
        );
        let (vals, _) = symmetric_eigen(&h);
        (h, vals)
    } else {
        (reduced, reduced_vals)
    };
    (h, vals, tol.max(eval.grad_v.amax()))
}

/// Each weak inequality's rows in the independent coordinates (`Zᵀ ∇g`: rows × dof).
pub(super) fn weak_rows(
    model: &Model,
    state: &State,
    sys: &System,
    part: &crate::solver::partition::Partition,
    eval: &crate::solver::system::Eval,
    weak: &[Active],
) -> Option<Vec<DMatrix<f64>>> {
    let (q, n, dof) = (&state.q, model.coordinate_count(), part.independent.len());
    let mut rows = Vec::with_capacity(weak.len());
    for a in weak {
        let bodies = unilateral::bodies(model, &a.row);
        let pair = crate::jet::pair_of(&bodies, q, false);
        let jets = unilateral::rows(model, a, &pair, &state.branches)?;
        let mut m = DMatrix::zeros(jets.len(), dof);
        for (r, s) in jets.iter().enumerate() {
            let mut y = DVector::zeros(n);
            for i in 0..crate::jet::NL {
                if let Some(g) = crate::jet::global_index(&bodies, i) {
                    y[g] += s.g[i];
                }
            }
            m.set_row(r, &sys.tangent_transpose(part, eval, &y).transpose());
        }
        rows.push(m);
    }
    Some(rows)
}

/// Whether [`stability_touching`] judges `strong` and `weak` without `all_held`: more than
/// [`MAX_WEAK`] weak rows are left once the stops whose other stop touches too are held
/// (Romeo's 24 fingers), and the verdict is the strong rows' alone. An active-set round that
/// ends there need not judge the tangent space of all its rows.
pub(crate) fn ignores_all_held(strong: &[Active], weak: &[Active]) -> bool {
    both_stops_held(strong, weak).1.len() > MAX_WEAK
}

/// A joint whose two stops both touch without a force (a `[l, l]` range: urdfdom's reading of
/// a `<limit>` without bounds, as on pybullet_data's minitaur knees) is held both ways:
/// `a · d ≥ 0` and `−a · d ≥ 0` leave `a · d = 0`, which one of its stops held as a row says
/// exactly; a weak stop whose other stop carries a force adds nothing (`a · d = 0` already).
/// Returns the strong list with those rows and the weak ones left. Without this, the eight
/// knees' sixteen weak stops exceed [`MAX_WEAK`] and the verdict fell back to the tangent space
/// of the strong rows alone, where the knees were free: "neutral" with six zero eigenvalues.
pub(super) fn both_stops_held(strong: &[Active], weak: &[Active]) -> (Vec<Active>, Vec<Active>) {
    let stop = |a: &Active| match a.row {
        unilateral::Unilateral::Limit { joint, bound, .. } => Some((joint, bound)),
        unilateral::Unilateral::Contact { .. } => None,
    };
    let mut held = strong.to_vec();
    let mut left = Vec::with_capacity(weak.len());
    for w in weak {
        if let Some((joint, bound)) = stop(w) {
            let opposite = |a: &Active| stop(a).is_some_and(|(j, b)| j == joint && b != bound);
            if held.iter().any(opposite) {
                continue;
            }
            if weak.iter().any(opposite) {
                held.push(*w);
                continue;
            }
        }
        left.push(*w);
    }
    (held, left)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A saddle `diag(−1, 2)`: the cone `{d₁ ≥ 0}` still holds the falling direction; the
    /// cones `{d₁ ≥ 0, −d₁ ≥ 0}` (a corner on each side) and `{d₁ = 0}` do not.
    #[test]
    fn blocks_only_what_a_cone_blocks() {
        let h = DMatrix::from_diagonal(&DVector::from_vec(vec![-1.0, 2.0]));
        let row = |a: f64, b: f64| DMatrix::from_row_slice(1, 2, &[a, b]);
        assert_eq!(minimum(&h, &[row(1.0, 0.0)], 1e-12), -1.0);
        assert_eq!(minimum(&h, &[row(1.0, 0.0), row(-1.0, 0.0)], 1e-12), 2.0);
        // Blocked on one side, and the other side by a tilted row: the minimum over the
        // wedge between them is positive but below 2.
        let wedge = minimum(&h, &[row(1.0, 0.0), row(-1.0, 0.2)], 1e-12);
        assert!(wedge > -1.0 && wedge < 2.0, "{wedge}");
        // The wedge is the arc θ ∈ [atan 5, π/2] of d = (cos θ, sin θ), where
        // dᵀHd = 2 − 3 cos²θ is smallest at atan 5: 2 − 3/26 = 49/26.
        assert!((wedge - 49.0 / 26.0).abs() < 1e-12, "{wedge}");
    }

    /// Random quadratic forms and cones: the face enumeration equals a brute-force minimum
    /// over sampled directions (never above it, and within the sampling's resolution).
    #[test]
    fn equals_sampled_minimum_in_three_dimensions() {
        let mut lcg = crate::lcg::Lcg::new(7);
        let mut next = || lcg.signed();
        for _ in 0..40 {
            let b = DMatrix::from_fn(3, 3, |_, _| next());
            let h = (&b + b.transpose()) * 0.5;
            let weak: Vec<DMatrix<f64>> = (0..3)
                .map(|_| DMatrix::from_fn(1, 3, |_, _| next()))
                .collect();
            let exact = minimum(&h, &weak, 1e-12);
            let mut sampled = f64::INFINITY;
            let n = 400;
            for i in 0..n {
                for j in 0..n {
                    let z = -1.0 + 2.0 * (i as f64 + 0.5) / n as f64;
                    let t = (j as f64 + 0.5) / n as f64 * std::f64::consts::TAU;
                    let r = (1.0 - z * z).sqrt();
                    let d = DVector::from_vec(vec![r * t.cos(), r * t.sin(), z]);
                    if weak.iter().all(|a| (a * &d)[0] >= 0.0) {
                        sampled = sampled.min((d.transpose() * &h * &d)[0]);
                    }
                }
            }
            if sampled.is_finite() {
                assert!(exact <= sampled + 1e-12, "{exact} above sampled {sampled}");
                assert!(
                    sampled - exact < 0.05,
                    "{exact} far below sampled {sampled}"
                );
            }
        }
    }
}
