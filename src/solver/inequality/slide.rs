//! A sticking contact that keeps coming back slides: it rejoins the active set frictionless.
//!
//! Releasing a sticking contact frees its tangential rows as well, and where its tangential force
//! exceeds its pulling normal force the step with the point free follows it into the floor: HyQ on
//! servos of 30 N m/rad (example-robot-data, `--servo all=30` about its SRDF `standing` state)
//! released `rh_foot` pulling −240 N with (−388, 31) N tangential, and the next step met it again
//! 1–2 nm from its anchor after 1.7·10⁻⁷ J, three times (B1 likewise, −5,887 N with 77,696 N
//! tangential). At its [`RETURNS`](super::release::RETURNS)-th return such a contact rejoins
//! without its anchor, frictionless (as a patch neighbour, module `patch`), for the rest of the
//! solve: a rest where it pushes along its normal only is a rest with it sticking (a zero
//! tangential force is within any friction cone). Each contact slides once; a slid contact that
//! comes back three times again ends the search. After a slide no sphere is re-anchored where it
//! has rolled (module `rolling`): the round after a re-anchoring starts on the new anchors without
//! a guard, and carried the A1's released thigh 1.3·10⁻⁴ m into the floor. HyQ then rests in 68
//! iterations, B1 in 35, the A1 without servos in 27 (each accepted by `verify`).
//!
//! The returns are those of module `release` ([`Returns`]): a row that left again alone at a
//! stationary point and that the next round's first step meets at once, the energy falling by
//! less than `RETURN_DECREASE · F L`, [`RETURNS`](super::release::RETURNS) times in a row.

use super::release::Returns;
use crate::constraints::unilateral::{Active, Unilateral};

/// The sticking contacts that slide (module docs).
#[derive(Default)]
pub(crate) struct Slid(Vec<Unilateral>);

impl Slid {
    /// Whether the row of `returns` slides now, after it `returned` for the last time: a
    /// contact that has not slid yet (then recorded, and the returns counted afresh). A stop,
    /// or a contact that slid before, does not: the search ends as cycling.
    pub(crate) fn now(&mut self, returned: bool, returns: &mut Returns) -> bool {
        let row = returns
            .row()
            .filter(|r| returned && matches!(r, Unilateral::Contact { .. }) && !self.0.contains(r));
        if let Some(r) = row {
            self.0.push(r);
            *returns = Returns::default();
        }
        row.is_some()
    }

    /// `a` as it joins the set: without its anchor (its tangential rows) if it slides.
    pub(crate) fn joining(&self, mut a: Active) -> Active {
        if self.0.contains(&a.row) {
            a.anchor = None;
        }
        a
    }

    /// Whether some contact slides: no sphere is re-anchored then (module docs).
    pub(crate) fn any(&self) -> bool {
        !self.0.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_returning_contact_slides_once_and_a_stop_never() {
        let contact = Unilateral::Contact {
            point: 3,
            ground: 0,
        };
        let anchored = Active {
            row: contact,
            anchor: Some(crate::constraints::unilateral::Anchor {
                world: nalgebra::Vector3::zeros(),
                body: nalgebra::Vector3::zeros(),
            }),
        };
        let mut slid = Slid::default();
        let mut returns = Returns::default();
        // Not returned yet: nothing slides, the anchor stays.
        returns.left(contact, 1.0);
        assert!(!slid.now(false, &mut returns));
        assert!(!slid.any());
        assert!(slid.joining(anchored).anchor.is_some());
        // Returned: it slides, and rejoins without its anchor from then on.
        assert!(slid.now(true, &mut returns));
        assert!(slid.any());
        assert!(slid.joining(anchored).anchor.is_none());
        assert_eq!(slid.joining(anchored).row_count(), 1);
        // Returned again after it slid: it does not slide twice (the search ends as cycling).
        returns.left(contact, 1.0);
        assert!(!slid.now(true, &mut returns));
        // A stop that returns never slides.
        let stop = Unilateral::Limit {
            joint: crate::model::JointId(0),
            bound: crate::constraints::unilateral::Bound::Lower,
            value: 0.0,
        };
        let mut returns = Returns::default();
        returns.left(stop, 1.0);
        assert!(!Slid::default().now(true, &mut returns));
    }
}
