//! Prismatic joint: translation along z. Motion `Tz(d)`; rows `z₀·x₁, z₀·y₁, y₀·x₁, x₀·d,
//! y₀·d`; coordinate `d·z₀`.

use super::spec::{
    at, length, name, no_values, t, Frame, Read, Row, Spec, TreeMotion, ONE_VALUE, ON_AXIS,
    PARALLEL, V,
};
use super::JointKind;
use nalgebra::{Isometry3, UnitQuaternion};

pub(super) const SPEC: Spec = Spec {
    names: &[name("prismatic", true, true, false)],
    coordinates: &[length(Read::Dot(V::Z0, V::D))],
    value_counts: &[1],
    units: &["m"],
    has_limits: true,
    rows: &[
        PARALLEL[0],
        PARALLEL[1],
        Row::Dot(V::Y0, V::X1),
        ON_AXIS[0],
        ON_AXIS[1],
    ],
    row_names: &["axis_x", "axis_y", "twist", "slide_x", "slide_y"],
    closed_form: true,
    frame: Frame::Axis,
    tree_motion: TreeMotion::Coordinates,
    configuration: ONE_VALUE,
    values_of_motion: no_values,
    motion,
};

/// `Tz(d)`.
fn motion(_: &JointKind, v: &[f64]) -> Isometry3<f64> {
    Isometry3::from_parts(t(0.0, 0.0, at(v, 0)), UnitQuaternion::identity())
}
