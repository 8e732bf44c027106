//! Joint frames in the world: the origins and axes of the frames `J` of both sides of a joint,
//! as jets over the pair's 14 coordinates, and the raw rotation angle about the common z axis
//! `atan2(y_i·x_j, x_i·x_j)` in (−π, π].

use crate::jet::{Pair, Scalar, Vec3Jet};
use crate::joint::V;
use crate::model::Joint;
use nalgebra::Vector3;

/// Joint-frame points and axes of both sides: `d = o_j − o_i` and the axes `x, y, z`.
pub(crate) struct Frames {
    pub(crate) d: Vec3Jet,
    pub(crate) x: [Vec3Jet; 2],
    pub(crate) y: [Vec3Jet; 2],
    pub(crate) z: [Vec3Jet; 2],
}

/// The joint frames of both sides of `joint` for the body pair `pair`.
pub(crate) fn frames(joint: &Joint, pair: &Pair) -> Frames {
    let v = |v: V| frame_vector(joint, pair, v);
    Frames {
        d: v(V::D),
        x: [v(V::X0), v(V::X1)],
        y: [v(V::Y0), v(V::Y1)],
        z: [v(V::Z0), v(V::Z1)],
    }
}

/// The vector `v` of the joint frames of `joint` for `pair`, alone: the jet [`frames`] holds
/// for it (`d = o₁ − o₀` from both origins).
pub(crate) fn frame_vector(joint: &Joint, pair: &Pair, v: V) -> Vec3Jet {
    let f = &joint.body_from_joint;
    match axis_of(v) {
        Some((k, e)) => pair.vector(k, &(f[k].rotation * e)),
        None => pair
            .point(1, &f[1].translation.vector)
            .sub(&pair.point(0, &f[0].translation.vector)),
    }
}

/// The side and the unit vector (in its joint frame) of an axis `v`; `None` for `d`.
pub(crate) fn axis_of(v: V) -> Option<(usize, Vector3<f64>)> {
    match v {
        V::D => None,
        V::X0 => Some((0, Vector3::x())),
        V::Y0 => Some((0, Vector3::y())),
        V::Z0 => Some((0, Vector3::z())),
        V::X1 => Some((1, Vector3::x())),
        V::Y1 => Some((1, Vector3::y())),
        V::Z1 => Some((1, Vector3::z())),
    }
}

/// The rotation of the child's `x` axis about the parent's `z`: `atan2(y_i·x_j, x_i·x_j)`, in
/// (−π, π] (see [`crate::kinematics::coordinate`] for the unwrapped joint angle).
pub(crate) fn angle(pair: &Pair, f: &Frames) -> Scalar {
    angle_of(pair, &f.y[0], &f.x[0], &f.x[1])
}

/// [`angle`] of the axes `y_i`, `x_i` and `x_j`: `atan2(y_i·x_j, x_i·x_j)`.
pub(crate) fn angle_of(pair: &Pair, y0: &Vec3Jet, x0: &Vec3Jet, x1: &Vec3Jet) -> Scalar {
    let s = pair.dot(y0, x1);
    let c = pair.dot(x0, x1);
    pair.atan2(&s, &c)
}
