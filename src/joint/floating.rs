//! Floating joint: six degrees of freedom, no constraint row. Motion `T(x, y, z) R` for values
//! `[x, y, z, rx, ry, rz]` (a rotation vector) or `[x, y, z, w, qx, qy, qz]`.

use super::spec::Entry::Value;
use super::spec::{at, name, quat, rotvec, t, Configuration, Frame, Spec, TreeMotion};
use super::JointKind;
use nalgebra::Isometry3;

pub(super) const SPEC: Spec = Spec {
    names: &[name("floating", true, false, false)],
    coordinates: &[],
    value_counts: &[6, 7],
    units: &["m", "m", "m", "1", "1", "1", "1"],
    has_limits: false,
    rows: &[],
    row_names: &[],
    closed_form: false,
    frame: Frame::Origin,
    tree_motion: TreeMotion::Pose,
    configuration: Configuration {
        mujoco: Some(&[
            Value(0),
            Value(1),
            Value(2),
            Value(3),
            Value(4),
            Value(5),
            Value(6),
        ]),
        pinocchio: Some(&[
            Value(0),
            Value(1),
            Value(2),
            Value(4),
            Value(5),
            Value(6),
            Value(3),
        ]),
    },
    values_of_motion: values,
    motion,
};

/// `T(x, y, z) R(quaternion or rotation vector)`.
fn motion(_: &JointKind, v: &[f64]) -> Isometry3<f64> {
    let at = |i| at(v, i);
    if v.len() == 7 {
        Isometry3::from_parts(t(at(0), at(1), at(2)), quat(at(3), at(4), at(5), at(6)))
    } else {
        Isometry3::from_parts(t(at(0), at(1), at(2)), rotvec(at(3), at(4), at(5)))
    }
}

/// `[x, y, z, w, qx, qy, qz]` of `M`.
fn values(m: &Isometry3<f64>) -> Vec<f64> {
    let (t, r) = (m.translation.vector, m.rotation);
    vec![t.x, t.y, t.z, r.w, r.i, r.j, r.k]
}
