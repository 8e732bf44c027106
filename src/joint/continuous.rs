//! Continuous joint: rotation about z without position limits; otherwise a revolute joint.

use super::spec::{angle, name, Frame, Read, Spec, PARALLEL, POS};

pub(super) const SPEC: Spec = Spec {
    names: &[name("continuous", true, true, false)],
    coordinates: &[angle(Read::Angle)],
    value_counts: &[1],
    units: &["rad"],
    has_limits: false,
    rows: &[POS[0], POS[1], POS[2], PARALLEL[0], PARALLEL[1]],
    row_names: &["pos_x", "pos_y", "pos_z", "axis_x", "axis_y"],
    closed_form: true,
    frame: Frame::Axis,
    motion: super::revolute::motion,
};
