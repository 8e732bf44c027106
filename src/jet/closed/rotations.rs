//! The rotations a joint's closed-form rows are formed from: its bodies' `A(p_k)`
//! ([`crate::math::rotation`]) and its frames' `R_k` (the rotation of `body_from_joint[k]` as a
//! matrix), formed once and read by reference (`A` once per body and evaluation,
//! [`crate::jet::body_rotations`]; `R` once per joint, [`frame_rotations`]).

use crate::jet::Pair;
use crate::math::rotation;
use crate::model::Joint;
use nalgebra::Matrix3;

/// The rotation matrices of the two sides of a pair.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Rotations(pub(crate) [Matrix3<f64>; 2]);

impl Rotations {
    /// The rotations of `pair`.
    pub(crate) fn of(pair: &Pair) -> Self {
        Rotations([rotation(&pair.p[0]), rotation(&pair.p[1])])
    }
}

/// Every rotation a joint's rows are formed from: its bodies' `A(p_k)` and its frames' `R_k`
/// (`body_from_joint[k]`'s rotation as a matrix), read where they were formed: `A` once per
/// body and evaluation, `R` once per joint, by the same functions (the same numbers).
#[derive(Clone, Copy, Debug)]
pub(crate) struct JointRotations<'a> {
    pub(crate) a: [&'a Matrix3<f64>; 2],
    pub(crate) r: &'a [Matrix3<f64>; 2],
}

/// The rotations of a joint at a pair, formed for it (the tests' reference).
#[cfg(test)]
pub(crate) struct OwnedRotations(Rotations, [Matrix3<f64>; 2]);

#[cfg(test)]
impl OwnedRotations {
    /// The rotations of `joint` at `pair`.
    pub(crate) fn of(joint: &Joint, pair: &Pair) -> Self {
        OwnedRotations(Rotations::of(pair), frame_rotations(joint))
    }

    /// The rotations as the closed forms read them.
    pub(crate) fn view(&self) -> JointRotations<'_> {
        JointRotations {
            a: [&self.0 .0[0], &self.0 .0[1]],
            r: &self.1,
        }
    }
}

/// `R_k`, the rotation matrices of `joint`'s frames in its bodies.
pub(crate) fn frame_rotations(joint: &Joint) -> [Matrix3<f64>; 2] {
    let r = |k: usize| {
        *joint.body_from_joint[k]
            .rotation
            .to_rotation_matrix()
            .matrix()
    };
    [r(0), r(1)]
}
