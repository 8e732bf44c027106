//! When an active stop or contact leaves the active set: inexact rounds and multiple release.
//!
//! The multipliers `μ` of `Φ_uᵀ μ = V_uᵀ` exist at every iterate of a round, not only at its
//! stationary point: `μ_k` is the rate `∂f/∂g_k` at which the reduced energy falls when row `k`
//! is relaxed with the independent coordinates held. A row whose multiplier pulls (`λ_k < 0`
//! beyond the complementarity tolerance) will leave the set at the round's end anyway; solving
//! the round to `‖∂V/∂v‖∞ ≤ 10⁻⁸` first is wasted. As in the reduced-gradient method of MINOS
//! (its *subspace tolerance*), a round ends early and releases the rows whose multiplier, as an
//! energy per unit of dimensionless gap `e_k = λ_k L` (a stop's torque as it is), pulls by more
//! than `‖∂V/∂v‖∞ / η`: the energy gained by leaving the row then dominates what is left to gain
//! in the current subspace.
//!
//! At a stationary point every row pulling beyond the tolerance leaves at once (not only the
//! one pulling hardest): a hanging humanoid starts with a dozen limits touching at 0 that all
//! pull, and releasing them one per converged round cost a full Newton solve each.
//!
//! Both apply to a row once per solve: a row released before (early or at a stationary point)
//! that a later step pushes back into its bound is re-added by the guard, and then leaves only
//! alone, the most negative at a stationary point, as in the classic method; so the set cannot
//! zigzag between several rows leaving together and coming back.
//!
//! ## References
//! - B. A. Murtagh, M. A. Saunders, "Large-scale linearly constrained optimization",
//!   *Mathematical Programming* 14 (1978) 41–72 (§4: the reduced-gradient tolerance before
//!   pricing, MINOS's subspace tolerance 0.5).
//! - D. P. Bertsekas, "Projected Newton methods for optimization problems with simple
//!   constraints", *SIAM J. Control Optim.* 20 (1982) 221–246 (every bound whose multiplier
//!   estimate is wrong leaves the working set in one iteration).
//! - J. Nocedal, S. J. Wright, *Numerical Optimization*, 2nd ed., Springer (2006), §16.5.

use crate::constraints::unilateral::{Active, Unilateral};
use crate::constraints::BlockKind;
use crate::model::Model;
use crate::solver::partition::Partition;
use crate::solver::system::{Eval, System};

/// The subspace tolerance `η`: a round ends early when a pulling row's energy rate exceeds
/// `‖∂V/∂v‖∞ / η`.
pub(crate) const SUBSPACE_TOLERANCE: f64 = 0.5;

/// The early-release test of one round.
pub(crate) struct Release<'m> {
    model: &'m Model,
    /// Per active inequality (in the order of the round's active list): whether it may leave
    /// before the round is stationary.
    eligible: Vec<bool>,
    /// The complementarity tolerance `force_tolerance · F` \[N\].
    threshold: f64,
}

impl<'m> Release<'m> {
    /// The test for a round whose active list is `active`; `released_before` are the
    /// inequalities already released once in this solve (not eligible again).
    pub(crate) fn new(
        model: &'m Model,
        active: &[Active],
        released_before: &[Unilateral],
        threshold: f64,
    ) -> Self {
        Release {
            model,
            eligible: active
                .iter()
                .map(|a| !released_before.contains(&a.row))
                .collect(),
            threshold,
        }
    }

    /// The active inequalities (indices into the round's active list) to release now, or
    /// `None` to go on with the round: those eligible whose multiplier pulls beyond the
    /// tolerance by an energy rate above `‖∂V/∂v‖∞ / η`.
    pub(crate) fn early(&self, sys: &System, part: &Partition, eval: &Eval) -> Option<Vec<usize>> {
        if !self.eligible.iter().any(|&e| e) {
            return None;
        }
        let gnorm = eval.grad_v.amax();
        let mut position = vec![usize::MAX; sys.problem.cons.len()];
        for (k, &row) in part.rows.iter().enumerate() {
            position[row] = k;
        }
        let mut out = Vec::new();
        let unilateral = sys
            .problem
            .cons
            .blocks
            .iter()
            .filter_map(|b| match &b.kind {
                BlockKind::Unilateral(a) => Some((a, b.first)),
                _ => None,
            });
        for (i, (a, first)) in unilateral.enumerate() {
            let k = position[first];
            if !self.eligible.get(i).copied().unwrap_or(false) || k == usize::MAX {
                continue;
            }
            let scaled = super::active_set::scaled_force(self.model, a, &[eval.mu[k]]);
            let rate = scaled * self.model.length_scale;
            if scaled < -self.threshold && -rate * SUBSPACE_TOLERANCE > gnorm {
                out.push(i);
            }
        }
        (!out.is_empty()).then_some(out)
    }
}

/// Every active inequality (index into the multipliers' list) pulling beyond `threshold`
/// (the scaling of `active_set::scaled_force`), most negative first.
pub(crate) fn all_to_release(
    model: &Model,
    multipliers: &[(Active, Vec<f64>)],
    threshold: f64,
) -> Vec<usize> {
    let mut out: Vec<(usize, f64)> = multipliers
        .iter()
        .enumerate()
        .map(|(i, (a, m))| (i, super::active_set::scaled_force(model, a, m)))
        .filter(|&(_, l)| l < -threshold)
        .collect();
    out.sort_by(|a, b| a.1.total_cmp(&b.1));
    out.into_iter().map(|(i, _)| i).collect()
}
