//! Joints: a kind ([`crate::joint`], one file per kind) and a joint frame `J` on each side.
//!
//! The frame `J` has its z axis along the joint axis (for a universal joint x is the second
//! axis; for a planar joint z is the plane normal). At zero displacement the two `J` frames
//! coincide; the relative motion of the child's `J` in the parent's `J` is given in the
//! kind's file.

use super::{BodyId, JointKind};
use crate::error::SourceLocation;
use nalgebra::Isometry3;

/// Index of a joint in [`crate::Model::joints`].
///
/// Ids come from the model (or [`crate::model::ModelBuilder`]); they cannot be written by
/// hand, so an id always names a joint of the model it came from.
///
/// ```compile_fail
/// let forged = restpose::model::JointId(7);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct JointId(pub(crate) usize);

impl JointId {
    /// Position of the joint in [`crate::Model::joints`].
    pub fn index(self) -> usize {
        self.0
    }
}

/// A joint between a parent and a child body.
#[derive(Clone, Debug)]
pub struct Joint {
    /// Joint name.
    pub name: String,
    /// Joint type.
    pub kind: JointKind,
    /// Parent link name.
    pub parent_link: String,
    /// Child link name.
    pub child_link: String,
    /// Parent and child bodies (`None` = world).
    pub bodies: [Option<BodyId>; 2],
    /// Joint frame `J` in the parent body frame and in the child body frame.
    pub body_from_joint: [Isometry3<f64>; 2],
    /// A spanning-tree edge (`true`) or a loop closure (`false`).
    pub tree: bool,
    /// A fixed joint welded into one body (adds no constraint).
    pub merged: bool,
    /// Position limits `[lower, upper]` of the first coordinate, if any.
    pub limits: Option<[f64; 2]>,
    /// The actuator's effort limit (URDF `<limit effort>`) \[N m or N\]: a joint resting on a
    /// stop with a larger effort is flagged (the actuator cannot hold the pose).
    pub effort_limit: Option<f64>,
    /// The joint's element in the input file (`None` for a joint built in code).
    pub source: Option<SourceLocation>,
}
