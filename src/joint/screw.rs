//! Screw joint: rotation about z coupled to translation along z, `d = h θ` for the pitch `h`.
//! Motion `Rz(θ) Tz(h θ)`; rows cylindrical + `d·z₀ − h θ` (the angle read on its branch, so
//! the screw advances over many turns: generic jets, no closed form).

use super::spec::{
    angle, at, name, no_values, rz, t, Frame, Read, Row, Spec, TreeMotion, NOT_IN_URDF, ON_AXIS,
    PARALLEL,
};
use super::JointKind;
use nalgebra::Isometry3;

pub(super) const SPEC: Spec = Spec {
    names: &[name("screw", false, true, true)],
    coordinates: &[angle(Read::Angle)],
    value_counts: &[1],
    units: &["rad"],
    has_limits: true,
    rows: &[
        PARALLEL[0],
        PARALLEL[1],
        ON_AXIS[0],
        ON_AXIS[1],
        Row::Thread,
    ],
    row_names: &["axis_x", "axis_y", "slide_x", "slide_y", "thread"],
    closed_form: false,
    frame: Frame::Axis,
    tree_motion: TreeMotion::Coordinates,
    configuration: NOT_IN_URDF,
    values_of_motion: no_values,
    motion,
};

/// `Tz(h θ) Rz(θ)`.
fn motion(kind: &JointKind, v: &[f64]) -> Isometry3<f64> {
    let pitch = kind.parameter();
    Isometry3::from_parts(t(0.0, 0.0, pitch * at(v, 0)), rz(at(v, 0)))
}
