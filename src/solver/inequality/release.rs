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
//! `L` is the lever of a unit of dimensionless gap where relaxing a contact moves its body as a
//! whole (a floating base). A contact on a chain held by the world turns the links next to it,
//! whose lever is their own length: a rope of 1,000 links 0.05 m long has `L` = 50 m, and its
//! lift-off contacts, pulling for a few iterations while the hanging part settles, were released
//! one per round and came back one per round (37 rounds where 11 suffice). There the rate is
//! taken per unit of the motion that relaxing the row causes with the independent coordinates
//! held, in the scaled coordinates of the reduced gradient,
//!
//! `e_k = λ_k / ‖S⁻¹ Φ_u⁻¹ e_k‖₂`
//!
//! (`S⁻¹` dividing positions by `ℓ`): the directional derivative of the energy along that
//! motion, comparable with the reduced gradient's components.
//! Applied to the contacts of floating bases as well, the same rate changed the paths of
//! standing robots, for the worse on balance (iCub and Talos `half_sitting` ending at
//! `max_iterations`), so those keep `λ_k L`.
//!
//! At a stationary point every row pulling beyond the tolerance leaves at once (not only the
//! one pulling hardest): a hanging humanoid starts with a dozen limits touching at 0 that all
//! pull, and releasing them one per converged round cost a full Newton solve each.
//!
//! A pivot's neighbour on a rounded hull (module `patch`: a contact without friction rows of
//! its own, within the patch of a sticking pivot) leaves only at a stationary point. When the
//! step that rolls a foot meets the next vertex, the pair transmits the moment that holds the
//! independent coordinates by opposite forces `±M / d` of thousands of newtons, whose sign
//! before the round is stationary depends on the partition: the new vertex was seen pulling,
//! released, and met again by the next step. Bolt falling over on its mesh feet and thighs
//! (example-robot-data, `--servo all=1000` about its SRDF `standing` state) took 78 iterations
//! in 87 rounds, with 8 such returns; held, its pivots hand over as they pull (the foot
//! rolls) and it rests in 51 iterations, 66 rounds; Talos `half_sitting` takes 12 instead of 16
//! to the same rest.
//!
//! Both apply to a row once per solve: a row released before (early or at a stationary point)
//! that a later step pushes back into its bound is re-added by the guard, and then leaves only
//! at a stationary point: alone, the most negative, as in the classic method, unless the step
//! with all the pulling ones released moves off every one of them (module `release_trial`);
//! so the set cannot zigzag between several rows leaving together and coming back.
//!
//! A row that leaves again alone at a stationary point and that the next round's first step
//! meets again at once, the energy falling by less than `RETURN_DECREASE · F L` (`F` the
//! weight and loads, `L` the characteristic length), is a two-round cycle at a degenerate
//! vertex of the active set: the A1 of example-robot-data falling on its legs without servos,
//! sticking (`--friction stick`), released a thigh contact pulling −224 N at a stationary
//! point, and the next round's Newton step (and steepest descent as well, tried) turned it back
//! into the floor after 10⁻⁸ J, 101 times, until `max_iterations` changes of the set: 103
//! iterations, 202 rounds. After [`RETURNS`] such returns in a row the search ends there as
//! `active_set_cycling` (module `active_set`), with the message that names the remedy, unless
//! the row is a sticking contact that has not slid yet (module `slide`).
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
use nalgebra::DVector;

/// The subspace tolerance `η`: a round ends early when a pulling row's energy rate exceeds
/// `‖∂V/∂v‖∞ / η`.
pub(crate) const SUBSPACE_TOLERANCE: f64 = 0.5;

/// Consecutive returns of a row that left again alone at a stationary point after which the
/// search ends as cycling (module docs).
pub(crate) const RETURNS: usize = 3;

/// The largest energy decrease, in units of `F L`, over a release and return that counts as a
/// return without progress (module docs).
pub(crate) const RETURN_DECREASE: f64 = 1e-8;

/// The returns of a row that left again alone at a stationary point (module docs).
#[derive(Default)]
pub(crate) struct Returns {
    /// The row that left last, alone at a stationary point, and the energy there.
    last: Option<(Unilateral, f64)>,
    /// Whether the round after that release has not been met yet.
    armed: bool,
    /// Consecutive returns without progress.
    count: usize,
}

impl Returns {
    /// `row` left again, alone, at a stationary point at energy `energy`.
    pub(crate) fn left(&mut self, row: Unilateral, energy: f64) {
        if self.last.is_none_or(|(r, _)| r != row) {
            self.count = 0;
        }
        self.last = Some((row, energy));
        self.armed = true;
    }

    /// The row that left last, alone, at a stationary point.
    pub(crate) fn row(&self) -> Option<Unilateral> {
        self.last.map(|(r, _)| r)
    }

    /// A step met the inequalities `hits` at energy `energy`; `scale` is `F L` \[J\]. Whether
    /// the row that left last has come back [`RETURNS`] times in a row without progress.
    pub(crate) fn met(&mut self, hits: &[Unilateral], energy: f64, scale: f64) -> bool {
        match self.last {
            Some((row, before))
                if self.armed
                    && hits.contains(&row)
                    && before - energy <= RETURN_DECREASE * scale =>
            {
                self.count += 1;
            }
            _ => {
                self.count = 0;
                self.last = None;
            }
        }
        self.armed = false;
        self.count >= RETURNS
    }
}

/// The early-release test of one round, and its stall test (module `stall`).
pub(crate) struct Release<'m> {
    model: &'m Model,
    /// Per active inequality (in the order of the round's active list): whether it may leave
    /// before the round is stationary.
    eligible: Vec<bool>,
    /// Per active inequality: a contact on a body that joints connect to the world (its rate
    /// is taken per unit of motion, module docs).
    held_chain: Vec<bool>,
    /// The complementarity tolerance `force_tolerance · F` \[N\].
    threshold: f64,
    /// Whether the round stalls at an obstacle's edge.
    stall: super::stall::Stall,
    /// The first direction of the round, computed by the release that started it (module
    /// `release_trial`).
    first: Option<super::release_trial::First>,
    /// The end of the last round's step cut at a rolling hull's next vertex (module `roll_on`).
    carry: Option<nalgebra::DVector<f64>>,
    /// Every active inequality is a stop and the solve is not cycling: a converged round is
    /// either left for the next one or, at the end, judged on the critical cone
    /// ([`Release::needs_verdict`]).
    judged_on_cone: bool,
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
        let (root, world) = crate::solver::unbounded::groups(model);
        Release {
            model,
            eligible: active
                .iter()
                .map(|a| !released_before.contains(&a.row))
                .collect(),
            held_chain: active
                .iter()
                .map(|a| match a.row {
                    Unilateral::Contact { point, .. } => {
                        root[model.contact_points[point].body.0] == world
                    }
                    Unilateral::Limit { .. } => false,
                })
                .collect(),
            threshold,
            stall: super::stall::Stall::new(model, active),
            first: None,
            carry: None,
            judged_on_cone: active
                .iter()
                .all(|a| matches!(a.row, Unilateral::Limit { .. })),
        }
    }

    /// The test of a round after which the solve reports cycling (`cycling`) if it ends: its
    /// own verdict is then the reported one.
    pub(crate) fn cycling(mut self, cycling: bool) -> Self {
        self.judged_on_cone &= !cycling;
        self
    }

    /// Whether a round that converged with the active rows' `multipliers` needs its own
    /// verdict, on the tangent space of every active row held: not where every active row is
    /// a stop and more than `MAX_WEAK` of them touch without a force
    /// (`stability::cone::ignores_all_held`). The active set either goes on from that round
    /// (its verdict unused) or ends there without cycling, and then judges the rest on the
    /// strong rows' tangent space alone (module `active_set`, `stability_verdict_after_round`);
    /// with a contact a sticking sphere may be re-anchored instead, and the round's verdict
    /// reported.
    pub(crate) fn needs_verdict(&self, multipliers: &[(Active, Vec<f64>)]) -> bool {
        if !self.judged_on_cone {
            return true;
        }
        let (strong, weak) = super::active_set::split(self.model, multipliers, self.threshold);
        !crate::solver::stability::cone::ignores_all_held(&strong, &weak)
    }

    /// The test with the round's first direction `first` (module `release_trial`).
    pub(crate) fn starting_with(mut self, first: Option<super::release_trial::First>) -> Self {
        self.first = first;
        self
    }

    /// The release with the end of the last round's step to roll on to.
    pub(crate) fn carrying(mut self, carry: Option<nalgebra::DVector<f64>>) -> Self {
        self.carry = carry;
        self
    }

    /// The end of the last round's step to roll on to, if any.
    pub(crate) fn carry(&self) -> Option<&nalgebra::DVector<f64>> {
        self.carry.as_ref()
    }

    /// The round's first direction, where the release that started it computed one.
    pub(crate) fn first(&self) -> Option<&super::release_trial::First> {
        self.first.as_ref()
    }

    /// The test with the neighbours of sticking pivots among `active` (contacts on a pivot's
    /// patch, module `patch`) not eligible to leave early (module docs).
    pub(crate) fn holding_patch_neighbours(mut self, active: &[Active]) -> Self {
        for (e, a) in self.eligible.iter_mut().zip(active) {
            if let (None, Unilateral::Contact { point, ground }) = (a.anchor, a.row) {
                if super::patch::near_pivot(self.model, active, point, ground) {
                    *e = false;
                }
            }
        }
        self
    }

    /// Records an accepted step of length `alpha` (the reduced gradient `before` and `after`
    /// it); whether the round has stalled at an obstacle's edge (module `stall`).
    pub(crate) fn stalled(&self, alpha: f64, before: f64, after: f64) -> bool {
        self.stall.record(alpha, before, after)
    }

    /// At a stall, the active contacts that the tangent step `dq` from `q` carries past an
    /// obstacle's edge (module `stall`).
    pub(crate) fn opened_at_stall(
        &self,
        q: &DVector<f64>,
        dq: &DVector<f64>,
        branches: &crate::kinematics::Branches,
    ) -> Vec<usize> {
        self.stall.opened(self.model, q, dq, branches)
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
            let pulls_hard = |rate: f64| -rate * SUBSPACE_TOLERANCE > gnorm;
            if scaled >= -self.threshold || !pulls_hard(scaled * self.model.length_scale) {
                continue;
            }
            // On a chain held by the world, per unit of the motion (module docs).
            if self.held_chain.get(i).copied().unwrap_or(false)
                && !pulls_hard(eval.mu[k] / motion(sys, part, eval, k))
            {
                continue;
            }
            out.push(i);
        }
        (!out.is_empty()).then_some(out)
    }
}

/// `‖S⁻¹ Φ_u⁻¹ e_k‖₂`: the motion of the dependent coordinates, scaled as the reduced
/// gradient's, when row `k` of `Φ_u` is relaxed by one unit with the independent coordinates
/// held (infinite if `Φ_u` cannot be solved).
fn motion(sys: &System, part: &Partition, eval: &Eval, k: usize) -> f64 {
    let mut e = DVector::zeros(part.rows.len());
    e[k] = 1.0;
    eval.factors.solve(&e).map_or(f64::INFINITY, |x| {
        x.iter()
            .zip(&part.dependent)
            .map(|(v, &c)| (v / sys.problem.scaling.columns[c]).powi(2))
            .sum::<f64>()
            .sqrt()
    })
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

/// The active rows at the ascending positions `gone` leave the set: each is recorded as
/// released once (above), a link's nearby vertices take over from a sticking pivot that left
/// (module `patch`), and the touches of sticking contacts are renewed (module `rolling`);
/// returns how many left (changes of the set).
pub(super) fn leave(
    (model, options, q): (&Model, &crate::solver::options::Options, &DVector<f64>),
    gone: &[usize],
    active: &mut Vec<Active>,
    released_before: &mut Vec<Unilateral>,
    touched: &mut Vec<super::rolling::Touch>,
) -> usize {
    let removed: Vec<Active> = gone.iter().map(|&i| active[i]).collect();
    for &i in gone.iter().rev() {
        released_before.push(active[i].row);
        active.remove(i);
    }
    super::patch::promote(model, options, active, &removed, q);
    super::rolling::record_touches(model, active, q, touched);
    gone.len()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_row_that_comes_straight_back_without_progress_is_a_cycle_at_the_third_return() {
        let row = Unilateral::Contact {
            point: 1,
            ground: 0,
        };
        let other = Unilateral::Contact {
            point: 2,
            ground: 0,
        };
        let mut r = Returns::default();
        for k in 1..=RETURNS {
            r.left(row, 10.0);
            assert_eq!(
                r.met(&[other, row], 10.0 - 0.5e-8, 1.0),
                k == RETURNS,
                "{k}"
            );
        }
        // With progress (the energy falls by more than 10⁻⁸ F L), never.
        let mut r = Returns::default();
        for _ in 0..2 * RETURNS {
            r.left(row, 10.0);
            assert!(!r.met(&[row], 10.0 - 2e-8, 1.0));
        }
        // Another row met in between, or a step that meets something before the release,
        // starts the count again.
        let mut r = Returns::default();
        for k in 0..3 * RETURNS {
            r.left(row, 10.0);
            let hits = if k % RETURNS == 1 { [other] } else { [row] };
            assert!(!r.met(&hits, 10.0, 1.0), "{k}");
        }
        let mut r = Returns::default();
        r.left(row, 10.0);
        assert!(!r.met(&[row], 10.0, 1.0));
        assert!(!r.met(&[row], 10.0, 1.0));
        r.left(row, 10.0);
        assert!(!r.met(&[row], 10.0, 1.0));
    }
}

#[cfg(test)]
#[path = "release_verdict_tests.rs"]
mod verdict_tests;
