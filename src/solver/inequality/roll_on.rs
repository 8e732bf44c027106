//! A rounded hull rolls on across a hand-over: the step cut at its next vertex goes on from
//! the cut on the new pivot's manifold, towards the point it was heading for.
//!
//! A foot rolling on its pivot (module `patch`) meets its next vertex: the step `q(α)` along
//! the Newton direction `δq` is cut at `α_cut` where that vertex touches (module `guard`), though
//! the step tried, `α_t`, went further. The next round holds the vertex as the pivot's
//! neighbour; the pivot pulls at once and hands over to it (module `release`, no iteration).
//! Without this module the round after that computes a new Newton direction, one iteration per
//! vertex rolled over. Instead that round first goes on towards the end of the step tried,
//!
//! `q_t = R(q₀, δq, α_t)`  (`R` the retraction of module `step::retraction`, from the cut
//! step's start `q₀`),
//!
//! along the change of the scaled independent coordinates that reaches it from the round's
//! start `q`, `d = S⁻¹ (v(q_t) − v(q))` (`v` the independent coordinates of the round's own
//! partition): corrected onto the new pivot's manifold, guarded, and taken only where it
//! descends (`∇fᵀ d < 0`) and its line search is cut at the next inequality (the foot rolls on
//! to its next vertex, or the other leg's: the search stops there as any cut step does). A
//! continuation that reaches no inequality is dropped and the round computes its Newton
//! direction as usual: the old step's end, computed with the old pivot held, is not a minimum
//! on the new manifold (Bolt's continuations that reached no vertex were accepted by Armijo at
//! 0.4 % to 12.5 % of their length, and taking them led its fall into a cycle). A continuation
//! reuses the cut step's direction: it computes no Newton direction and counts as no iteration
//! (the count the same roll on inside one line search would give).
//!
//! Bolt (example-robot-data) servoed about its SRDF `standing` state, rolling over its feet
//! and thighs onto its trunk: 49 → 36 iterations; every other robot of the corpora unchanged
//! (docs/contact.md).

use nalgebra::DVector;

/// The end of a step cut at a rolling hull's next vertex, waiting for the hand-over, then
/// passed to the round after it (module docs).
#[derive(Default)]
pub(crate) struct RollOn {
    /// The end of the last round's step, if that round was cut at a rolling hull's vertex.
    pending: Option<DVector<f64>>,
}

impl RollOn {
    /// After a round that took `iterations`, was cut (`blocked`) or not, released rows
    /// (`released`) or not, and left the end of its cut step `end`: the point the next round
    /// rolls on to, where this round was the hand-over right after a cut one (released at its
    /// start, no step).
    pub(crate) fn after_round(
        &mut self,
        iterations: usize,
        blocked: bool,
        released: bool,
        end: Option<DVector<f64>>,
    ) -> Option<DVector<f64>> {
        let handed = iterations == 0 && !blocked && released;
        std::mem::replace(&mut self.pending, end).filter(|_| handed)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_end_of_a_cut_step_passes_only_across_a_hand_over_without_a_step() {
        let end = || Some(DVector::from_element(2, 1.0));
        // A cut round, then a hand-over at its start: the round after rolls on.
        let mut r = RollOn::default();
        assert!(r.after_round(1, true, false, end()).is_none());
        assert_eq!(r.after_round(0, false, true, None), end());
        // Only once.
        assert!(r.after_round(0, false, true, None).is_none());
        // A hand-over that took a step first, or a round that met another vertex, passes
        // nothing on.
        let mut r = RollOn::default();
        r.after_round(1, true, false, end());
        assert!(r.after_round(1, false, true, None).is_none());
        let mut r = RollOn::default();
        r.after_round(1, true, false, end());
        assert!(r.after_round(0, true, false, end()).is_none());
        // A stationary round (nothing released early) passes nothing on either.
        let mut r = RollOn::default();
        r.after_round(1, true, false, end());
        assert!(r.after_round(0, false, false, None).is_none());
    }
}
