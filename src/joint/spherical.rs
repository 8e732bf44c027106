//! Spherical (ball) joint: rotation about a common point. Rows `d = 0`; motion a rotation
//! given as a rotation vector (3 values) or a quaternion `[w, x, y, z]` (4).

use super::spec::Entry::Value;
use super::spec::{at, name, quat, rotvec, t, Configuration, Frame, Spec, TreeMotion, POS};
use super::JointKind;
use nalgebra::Isometry3;

pub(super) const SPEC: Spec = Spec {
    names: &[
        name("spherical", true, true, false),
        name("ball", true, true, true),
    ],
    coordinates: &[],
    value_counts: &[3, 4],
    units: &["1"; 4],
    has_limits: false,
    rows: &POS,
    row_names: &["pos_x", "pos_y", "pos_z"],
    closed_form: true,
    frame: Frame::Origin,
    tree_motion: TreeMotion::Rotation,
    configuration: Configuration {
        mujoco: Some(&[Value(0), Value(1), Value(2), Value(3)]),
        pinocchio: None,
    },
    values_of_motion: values,
    motion,
};

/// `R(quaternion or rotation vector)`.
fn motion(_: &JointKind, v: &[f64]) -> Isometry3<f64> {
    let at = |i| at(v, i);
    if v.len() == 4 {
        Isometry3::from_parts(t(0.0, 0.0, 0.0), quat(at(0), at(1), at(2), at(3)))
    } else {
        Isometry3::from_parts(t(0.0, 0.0, 0.0), rotvec(at(0), at(1), at(2)))
    }
}

/// The quaternion `[w, x, y, z]` of `M`.
fn values(m: &Isometry3<f64>) -> Vec<f64> {
    let r = m.rotation;
    vec![r.w, r.i, r.j, r.k]
}
