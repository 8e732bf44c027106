//! Planar joint: translation in the x-y plane and rotation about its normal z. Motion
//! `T(x, y, 0) Rz(θ)`; rows `z₀·x₁, z₀·y₁, z₀·d`; coordinates `x₀·d, y₀·d, θ`.

use super::spec::{
    angle, at, length, name, no_values, rz, t, Frame, Read, Row, Spec, TreeMotion, NOT_IN_URDF,
    PARALLEL, V,
};
use super::JointKind;
use nalgebra::Isometry3;

pub(super) const SPEC: Spec = Spec {
    names: &[name("planar", true, true, true)],
    coordinates: &[
        length(Read::Dot(V::X0, V::D)),
        length(Read::Dot(V::Y0, V::D)),
        angle(Read::Angle),
    ],
    value_counts: &[3],
    units: &["m", "m", "rad"],
    has_limits: true,
    rows: &[PARALLEL[0], PARALLEL[1], Row::Dot(V::Z0, V::D)],
    row_names: &["normal_x", "normal_y", "plane"],
    closed_form: true,
    frame: Frame::Axis,
    tree_motion: TreeMotion::Coordinates,
    configuration: NOT_IN_URDF,
    values_of_motion: no_values,
    motion,
};

/// `T(x, y, 0) Rz(θ)`.
fn motion(_: &JointKind, v: &[f64]) -> Isometry3<f64> {
    Isometry3::from_parts(t(at(v, 0), at(v, 1), 0.0), rz(at(v, 2)))
}
