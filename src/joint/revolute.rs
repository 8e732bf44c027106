//! Revolute joint: rotation about z, limited. Motion `Rz(θ)`; rows spherical + `z₀·x₁, z₀·y₁`.

use super::spec::{
    angle, at, name, no_values, rz, t, Frame, Read, Spec, TreeMotion, ONE_VALUE, PARALLEL, POS,
};
use super::JointKind;
use nalgebra::Isometry3;

pub(super) const SPEC: Spec = Spec {
    names: &[name("revolute", true, true, false)],
    coordinates: &[angle(Read::Angle)],
    value_counts: &[1],
    units: &["rad"],
    has_limits: true,
    rows: &[POS[0], POS[1], POS[2], PARALLEL[0], PARALLEL[1]],
    row_names: &["pos_x", "pos_y", "pos_z", "axis_x", "axis_y"],
    closed_form: true,
    frame: Frame::Axis,
    tree_motion: TreeMotion::Coordinates,
    configuration: ONE_VALUE,
    values_of_motion: no_values,
    motion,
};

/// `Rz(θ)`.
pub(super) fn motion(_: &JointKind, v: &[f64]) -> Isometry3<f64> {
    Isometry3::from_parts(t(0.0, 0.0, 0.0), rz(at(v, 0)))
}
