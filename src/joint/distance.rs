//! Distance joint: the two joint origins stay `L` apart (a massless rod). Row `d·d − L²`; no
//! coordinate.

use super::spec::{name, no_values, t, Frame, Row, Spec, TreeMotion, NOT_IN_URDF};
use super::JointKind;
use nalgebra::{Isometry3, UnitQuaternion};

pub(super) const SPEC: Spec = Spec {
    names: &[name("distance", false, true, false)],
    coordinates: &[],
    value_counts: &[0],
    units: &[],
    has_limits: false,
    rows: &[Row::Length],
    row_names: &["length"],
    closed_form: true,
    frame: Frame::Origin,
    tree_motion: TreeMotion::Pose,
    configuration: NOT_IN_URDF,
    values_of_motion: no_values,
    motion,
};

/// Placed as a tree edge: the child's point `L` below the parent's along the joint frame's
/// −z (hanging, as a URDF chain does under the default gravity), where the row `‖d‖² − L²`
/// holds and its gradient `2 d` is not zero; at the parent's point (`d = 0`) the row would be
/// violated and its gradient vanish.
fn motion(kind: &JointKind, _: &[f64]) -> Isometry3<f64> {
    Isometry3::from_parts(t(0.0, 0.0, -kind.parameter()), UnitQuaternion::identity())
}
