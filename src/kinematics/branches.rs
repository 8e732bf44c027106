//! The branch of every joint angle: a reference value `θ_b` per angular joint coordinate, the
//! angle being read as `θ = θ_b + wrap(atan2 − θ_b)` (module [`crate::kinematics`]).
//!
//! A configuration `q` fixes each angle only modulo 2π; the branch says which real number it
//! is. It starts at the initial (or locked, or given) values and is moved along with the
//! configuration after each accepted step ([`Branches::follow`]): `θ_b ← θ(q)`. Steps rotate a
//! joint by much less than π, so the angle is tracked continuously through the solve: a
//! torsion spring on a continuous joint winds up over several turns and its energy uses the
//! unwrapped angle.

use super::coordinate::coordinate_value;
use crate::jet::pair_of;
use crate::model::MAX_SCALAR_COORDINATES;
use crate::model::{JointId, Model};
use nalgebra::DVector;

/// Reference values of the angular joint coordinates \[rad\], by joint and coordinate index;
/// the default (empty) reads every angle in (−π, π].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Branches {
    reference: Vec<[f64; MAX_SCALAR_COORDINATES]>,
}

impl Branches {
    /// The reference of coordinate `dof` of `joint` (0 if none was set).
    pub fn get(&self, joint: JointId, dof: usize) -> f64 {
        self.reference
            .get(joint.0)
            .and_then(|r| r.get(dof))
            .copied()
            .unwrap_or(0.0)
    }

    /// Sets the reference of coordinate `dof` of `joint` (ignored for `dof` beyond
    /// the largest coordinate count or a non-finite value).
    pub fn set(&mut self, joint: JointId, dof: usize, value: f64) {
        if dof >= MAX_SCALAR_COORDINATES || !value.is_finite() {
            return;
        }
        if self.reference.len() <= joint.0 {
            self.reference
                .resize(joint.0 + 1, [0.0; MAX_SCALAR_COORDINATES]);
        }
        self.reference[joint.0][dof] = value;
    }

    /// Moves every reference to the angle of `q` read on the current branch (`θ_b ← θ(q)`);
    /// call after each step, which must turn every joint by less than π.
    pub(crate) fn follow(&mut self, model: &Model, q: &DVector<f64>) {
        for (i, j) in model.joints.iter().enumerate() {
            let n = j.kind.scalar_coordinates();
            if j.merged || !(0..n).any(|d| j.kind.is_angle(d)) {
                continue;
            }
            let pair = pair_of(&j.bodies, q, false);
            for dof in (0..n).filter(|&d| j.kind.is_angle(d)) {
                let id = JointId(i);
                if let Some(v) = coordinate_value(j, &pair, dof, self.get(id, dof)) {
                    self.set(id, dof, v);
                }
            }
        }
    }
}
