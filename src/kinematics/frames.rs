//! Joint frames in the world: the origins and axes of the frames `J` of both sides of a joint,
//! as jets over the pair's 14 coordinates, and the raw rotation angle about the common z axis
//! `atan2(y_i·x_j, x_i·x_j)` in (−π, π].

use crate::jet::{Pair, Scalar, Vec3Jet};
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
    let side = |k: usize| {
        let f = &joint.body_from_joint[k];
        (
            pair.point(k, &f.translation.vector),
            pair.vector(k, &(f.rotation * Vector3::x())),
            pair.vector(k, &(f.rotation * Vector3::y())),
            pair.vector(k, &(f.rotation * Vector3::z())),
        )
    };
    let (o0, x0, y0, z0) = side(0);
    let (o1, x1, y1, z1) = side(1);
    Frames {
        d: o1.sub(&o0),
        x: [x0, x1],
        y: [y0, y1],
        z: [z0, z1],
    }
}

/// The rotation of the child's `x` axis about the parent's `z`: `atan2(y_i·x_j, x_i·x_j)`, in
/// (−π, π] (see [`crate::kinematics::coordinate`] for the unwrapped joint angle).
pub(crate) fn angle(pair: &Pair, f: &Frames) -> Scalar {
    let s = pair.dot(&f.y[0], &f.x[1]);
    let c = pair.dot(&f.x[0], &f.x[1]);
    pair.atan2(&s, &c)
}
