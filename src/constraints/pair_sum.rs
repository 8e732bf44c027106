//! The local Hessian of one body pair into which consecutive rows on that pair are summed
//! before it reaches the sink (`Constraints::add_hessian`): `Σ_r w_r ∇²Φ_r` over the 8 Euler
//! parameters of the pair while every row's Hessian is zero elsewhere (the joints of
//! [`crate::jet::closed::euler`]), the full `14 × 14` once a row needs it (the Euler part
//! copied over). The sink adds the Euler form's entries alone
//! ([`HessianSink::add_euler_block`]), which adds what the full form, zero elsewhere, adds
//! to the last bit; the sums themselves are the same additions in the same order.

use crate::jet::{euler_to_local, HessianSink, LMat};
use crate::model::BodyId;
use nalgebra::SMatrix;

/// The pending pair and its sum, over the Euler parameters (`hp`) or full (`acc`): both kept
/// in place (no moves of the `14 × 14` buffer).
pub(super) struct PairSum {
    bodies: Option<[Option<BodyId>; 2]>,
    full: bool,
    hp: SMatrix<f64, 8, 8>,
    acc: LMat,
}

impl PairSum {
    pub(super) fn new() -> Self {
        PairSum {
            bodies: None,
            full: false,
            hp: SMatrix::zeros(),
            acc: LMat::zeros(),
        }
    }

    /// Makes the sum of `bodies` pending: the pending one if it is theirs, else a new one
    /// (over the Euler parameters, zero) after the pending one is added to `h`. Returns it
    /// while it is over the Euler parameters (`None` once full: [`PairSum::full`]).
    pub(super) fn of(
        &mut self,
        bodies: &[Option<BodyId>; 2],
        h: &mut dyn HessianSink,
    ) -> Option<&mut SMatrix<f64, 8, 8>> {
        let same = self.bodies.as_ref().is_some_and(|b| {
            b.iter()
                .map(|x| x.map(|y| y.0))
                .eq(bodies.iter().map(|x| x.map(|y| y.0)))
        });
        if !same {
            self.flush(h);
            self.bodies = Some(*bodies);
            self.full = false;
            self.hp = SMatrix::zeros();
        }
        (!self.full).then_some(&mut self.hp)
    }

    /// The pending sum in full form (converted from the Euler one: the same entries, zero
    /// elsewhere).
    pub(super) fn full(&mut self) -> &mut LMat {
        if !self.full {
            self.acc = euler_to_local(&self.hp);
            self.full = true;
        }
        &mut self.acc
    }

    /// Adds the pending sum to `h`.
    pub(super) fn flush(&mut self, h: &mut dyn HessianSink) {
        if let Some(bodies) = self.bodies.take() {
            if self.full {
                h.add_block(&bodies, &self.acc, 1.0);
            } else {
                h.add_euler_block(&bodies, &self.hp, 1.0);
            }
        }
    }
}
