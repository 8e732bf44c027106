//! Cylindrical joint: rotation about and translation along z. Motion `Rz(θ) Tz(d)`; rows
//! `z₀·x₁, z₀·y₁, x₀·d, y₀·d`; coordinates `θ`, `d·z₀`.

use super::spec::{
    angle, at, length, name, no_values, rz, t, Frame, Read, Spec, TreeMotion, NOT_IN_URDF, ON_AXIS,
    PARALLEL, V,
};
use super::JointKind;
use nalgebra::Isometry3;

pub(super) const SPEC: Spec = Spec {
    names: &[name("cylindrical", false, true, false)],
    coordinates: &[angle(Read::Angle), length(Read::Dot(V::Z0, V::D))],
    value_counts: &[2],
    units: &["rad", "m"],
    has_limits: true,
    rows: &[PARALLEL[0], PARALLEL[1], ON_AXIS[0], ON_AXIS[1]],
    row_names: &["axis_x", "axis_y", "slide_x", "slide_y"],
    closed_form: true,
    frame: Frame::Axis,
    tree_motion: TreeMotion::Coordinates,
    configuration: NOT_IN_URDF,
    values_of_motion: no_values,
    motion,
};

/// `Tz(d) Rz(θ)`.
fn motion(_: &JointKind, v: &[f64]) -> Isometry3<f64> {
    Isometry3::from_parts(t(0.0, 0.0, at(v, 1)), rz(at(v, 0)))
}
