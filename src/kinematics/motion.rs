//! The relative motion `M(θ)` of a joint in its joint frame, for forward kinematics:
//! `world_from_child = world_from_parent · parent_from_J · M(θ) · (child_from_J)⁻¹`.

use crate::model::JointKind;
use nalgebra::Isometry3;

/// Relative motion of a joint of this kind in its joint frame for coordinates `v` (see
/// [`JointKind::value_counts`]; missing values are 0), from the kind's file
/// ([`crate::joint::Spec::motion`]). Angles are taken as given: `Rz(θ)` for any real `θ`. A
/// distance joint (no coordinate) holds its child at `length` along −z.
pub(crate) fn motion(kind: JointKind, v: &[f64]) -> Isometry3<f64> {
    (kind.spec().motion)(&kind, v)
}
