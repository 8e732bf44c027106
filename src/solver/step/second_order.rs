//! The second-order correction of a trial point (Nocedal & Wright §15.6, §18.3).
//!
//! The point `q_α` at `α` on the search path (module `retraction`) keeps the tree joints, but
//! leaves open the rows the path does not keep (contacts, loop-closing joints) by
//! `Φ(q_α) = ½ α² Φ'' + O(α³)`: the tangent step satisfies them to first order only. The
//! corrector closes them in the dependent coordinates alone, `v` fixed. Where `Φ_u` has little
//! hold on such a row that is a long way for a small residual: the 1,000-link rope's contact at
//! the foot of its hanging part is pivoted on one 5 cm link near the vertical, whose rotation
//! lifts the foot by 1.5 cm per radian, while the 333 links above lift it by
//! `Σ ℓ (1 − cos Δφ_k)`; a residual of 10⁻³ took the chord step to 10⁰ and half-metre steps
//! of the hanging part had no solution for their `v`. The correction closes them in all
//! coordinates instead, by the least change in the metric of the Newton step:
//!
//! `min ½ δq₂ᵀ W δq₂` subject to `Φ_q δq₂ = −Φ(q_α)`, i.e.
//! `[W Φ_qᵀ; Φ_q 0] [δq₂; λ] = [0; −Φ(q_α)]`
//!
//! over the independent rows, solved with the KKT factors of the Newton step at `q` (module
//! `kkt_direction`; one more substitution, no factorization; the augmentation of `W` by
//! `Φ_qᵀ D R D Φ_q` adds a constant on that affine set and leaves the solution alone). `δq₂`
//! satisfies the linearized rows the path keeps (their residual at `q_α` is rounding), so it is
//! a tangent like `δq`: the corrected trial point is the path's point for the tangent
//! `α δq + δq₂`, every tree joint turned by `α θ̇ + θ̇₂`, and the corrector finishes from there.
//! It is taken where the factors are the step's (the KKT direction of the sparse and tree
//! paths), the residual at `q_α` is above the corrector's tolerance (never on a tree without
//! contacts: the path keeps its rows) and the correction lowers it.
//!
//! ## References
//! - J. Nocedal, S. J. Wright, *Numerical Optimization*, 2nd ed., Springer (2006), §15.6
//!   (the second-order correction), §18.3.

use crate::solver::partition::Partition;
use crate::solver::system::System;
use nalgebra::DVector;

/// What [`corrected_point`] leaves: the corrected trial point (`None`: the plain one is the
/// trial), and whether the scratch holds `Φ` of the trial point so chosen (the corrector then
/// starts from it instead of evaluating it again: the same values, module `system::corrector`).
pub(crate) struct Corrected {
    pub(crate) point: Option<DVector<f64>>,
    pub(crate) phi_in_scratch: bool,
}

/// The trial point at `α` along the tangent `dq` from `q` on the search path, corrected to
/// second order where that lowers the residual of the independent rows above `tolerance`
/// (module docs); `point` is `None` when no correction applies (the plain point `qt` is then
/// the trial).
pub(crate) fn corrected_point(
    sys: &mut System,
    part: &Partition,
    (q, dq, alpha): (&DVector<f64>, &DVector<f64>, f64),
    qt: &DVector<f64>,
    tolerance: f64,
) -> Corrected {
    let plain = Corrected {
        point: None,
        phi_in_scratch: true,
    };
    let before = residual(sys, part, qt);
    if !before.is_finite() || before <= tolerance {
        return plain;
    }
    let Some(dq2) = correction(sys, part) else {
        return plain;
    };
    let step = dq * alpha + dq2;
    let qc = sys.problem.retraction.point(q, &step, 1.0);
    let after = residual(sys, part, &qc);
    // The scratch now holds `Φ(q_c)`: of the trial only where the correction is taken.
    let better = after < before;
    Corrected {
        point: better.then_some(qc),
        phi_in_scratch: better,
    }
}

/// `‖D Φ(q)‖∞` over the independent rows (leaves `Φ(q)` in the scratch).
fn residual(sys: &mut System, part: &Partition, q: &DVector<f64>) -> f64 {
    sys.residual(q);
    sys.problem.scaling.residual_over(&sys.work.phi, &part.rows)
}

/// `δq₂` from the KKT factors of the step for the residual `Φ` in the scratch (module docs).
fn correction(sys: &System, part: &Partition) -> Option<DVector<f64>> {
    let kkt = sys.work.kkt.as_ref()?;
    let n = kkt.coordinates();
    if kkt.rows() != part.rows.len() {
        return None;
    }
    let scaling = &sys.problem.scaling;
    // Scaled: `(D Φ_q S) δq̂₂ = −D Φ`, `δq₂ = S δq̂₂`.
    let mut rhs = vec![0.0; n + part.rows.len()];
    for (k, &r) in part.rows.iter().enumerate() {
        rhs[n + k] = -scaling.rows[r] * sys.work.phi[r];
    }
    if !kkt.solve(&mut rhs, 1e-13) {
        return None;
    }
    let dq2 = DVector::from_iterator(n, (0..n).map(|c| rhs[c] * scaling.columns[c]));
    dq2.iter().all(|x| x.is_finite()).then_some(dq2)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::constraints::Constraints;
    use crate::solver::options::Options;
    use crate::solver::step::kkt_direction::kkt_direction;
    use crate::solver::system::Backend;
    use crate::urdf::{load_str, ImportOptions};

    /// On the spatial four-bar (its universal loop joint is a row the path leaves open) the
    /// plain trial point misses the loop by `O(α²)`, the corrected one by `O(α³)`, lower at
    /// every `α`; the tree joints stay closed.
    #[test]
    fn the_correction_closes_the_open_rows_to_third_order() {
        let text = include_str!("../../../robots/four_bar_spatial.urdf");
        let model = load_str(text, "four_bar.urdf", &ImportOptions::default())
            .unwrap()
            .model;
        let options = Options::default();
        let start = crate::State::initial(&model);
        let mut branches = start.branches.clone();
        let q = crate::solver::assemble::assemble(&model, start.q, &mut branches, &[], &options)
            .unwrap();
        let cons = Constraints::new(&model, &[]).on_branches(branches);
        let mut sys = System::new(&model, cons, Backend::Sparse);
        let part = sys.partition(&q);
        let eval = sys.evaluate(&q, &part).unwrap();
        let (d, _) = kkt_direction(&mut sys, &q, &part, &eval);
        let dq = sys.tangent_step(&part, &eval, &d);
        let dq = &dq * (0.5 / dq.amax());
        let mut plain = Vec::new();
        let mut corrected = Vec::new();
        for alpha in [0.4, 0.2, 0.1, 0.05] {
            let qt = sys.problem.retraction.point(&q, &dq, alpha);
            let before = residual(&mut sys, &part, &qt);
            let got = corrected_point(&mut sys, &part, (&q, &dq, alpha), &qt, 1e-14);
            assert!(got.phi_in_scratch);
            let qc = got.point.expect("the correction lowers the residual");
            let mut phi_c = DVector::zeros(sys.phi().len());
            sys.problem.cons.evaluate(&model, &qc, &mut phi_c, None);
            assert_eq!(sys.phi(), &phi_c, "Φ(q_c) in the scratch");
            let after = residual(&mut sys, &part, &qc);
            assert!(
                after < 0.5 * before,
                "α {alpha}: {before:.3e} -> {after:.3e}"
            );
            plain.push(before);
            corrected.push(after);
        }
        for k in 1..plain.len() {
            let (p, c) = (plain[k - 1] / plain[k], corrected[k - 1] / corrected[k]);
            assert!(
                (3.0..5.0).contains(&p),
                "plain: halving α divides by {p:.2}"
            );
            assert!(
                c > 6.0,
                "corrected: halving α divides by {c:.2} ({corrected:?})"
            );
        }
    }
}
