//! Continuous joint: rotation about z without position limits; otherwise a revolute joint.

use super::spec::{
    angle, name, no_values, Configuration, Entry, Frame, Read, Spec, TreeMotion, PARALLEL, POS,
};

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
    tree_motion: TreeMotion::Coordinates,
    configuration: Configuration {
        mujoco: Some(&[Entry::Value(0)]),
        pinocchio: Some(&[Entry::Cos(0), Entry::Sin(0)]),
    },
    values_of_motion: no_values,
    motion: super::revolute::motion,
};
