//! Fixed joint: no relative motion. Rows spherical + `z₀·x₁, z₀·y₁, y₀·x₁` (a URDF fixed tree
//! joint is welded into one body instead and adds no row).

use super::spec::{name, no_values, Configuration, Frame, Row, Spec, TreeMotion, PARALLEL, POS, V};
use super::JointKind;
use nalgebra::Isometry3;

pub(super) const SPEC: Spec = Spec {
    names: &[name("fixed", true, true, false)],
    coordinates: &[],
    value_counts: &[0],
    units: &[],
    has_limits: false,
    rows: &[
        POS[0],
        POS[1],
        POS[2],
        PARALLEL[0],
        PARALLEL[1],
        Row::Dot(V::Y0, V::X1),
    ],
    row_names: &["pos_x", "pos_y", "pos_z", "axis_x", "axis_y", "twist"],
    closed_form: true,
    frame: Frame::Origin,
    tree_motion: TreeMotion::Coordinates,
    configuration: Configuration {
        mujoco: Some(&[]),
        pinocchio: Some(&[]),
    },
    values_of_motion: no_values,
    motion: identity,
};

/// The identity (no relative motion).
pub(super) fn identity(_: &JointKind, _: &[f64]) -> Isometry3<f64> {
    Isometry3::identity()
}
