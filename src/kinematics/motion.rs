//! The relative motion `M(θ)` of a joint in its joint frame, for forward kinematics:
//! `world_from_child = world_from_parent · parent_from_J · M(θ) · (child_from_J)⁻¹`.

use crate::math::unit_quaternion;
use crate::model::JointKind;
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3, Vector4};

/// Relative motion of a joint of this kind in its joint frame for coordinates `v` (see
/// [`JointKind::value_counts`]; missing values are 0). Angles are taken as given: `Rz(θ)`
/// for any real `θ`. A distance joint (no coordinate) holds its child at `length` along −z.
pub(crate) fn motion(kind: JointKind, v: &[f64]) -> Isometry3<f64> {
    let at = |i: usize| v.get(i).copied().unwrap_or(0.0);
    let rz = |a: f64| UnitQuaternion::from_axis_angle(&Vector3::z_axis(), a);
    let rx = |a: f64| UnitQuaternion::from_axis_angle(&Vector3::x_axis(), a);
    let t = |x: f64, y: f64, z: f64| Translation3::new(x, y, z);
    let rotvec = |a: f64, b: f64, c: f64| UnitQuaternion::from_scaled_axis(Vector3::new(a, b, c));
    let quat = |w: f64, x: f64, y: f64, z: f64| unit_quaternion(&Vector4::new(w, x, y, z));
    match kind {
        JointKind::Revolute | JointKind::Continuous => {
            Isometry3::from_parts(t(0.0, 0.0, 0.0), rz(at(0)))
        }
        JointKind::Prismatic => {
            Isometry3::from_parts(t(0.0, 0.0, at(0)), UnitQuaternion::identity())
        }
        JointKind::Cylindrical => Isometry3::from_parts(t(0.0, 0.0, at(1)), rz(at(0))),
        JointKind::Universal => Isometry3::from_parts(t(0.0, 0.0, 0.0), rz(at(0)) * rx(at(1))),
        JointKind::Planar => Isometry3::from_parts(t(at(0), at(1), 0.0), rz(at(2))),
        JointKind::Screw { pitch } => Isometry3::from_parts(t(0.0, 0.0, pitch * at(0)), rz(at(0))),
        JointKind::Spherical if v.len() == 4 => {
            Isometry3::from_parts(t(0.0, 0.0, 0.0), quat(at(0), at(1), at(2), at(3)))
        }
        JointKind::Spherical => {
            Isometry3::from_parts(t(0.0, 0.0, 0.0), rotvec(at(0), at(1), at(2)))
        }
        JointKind::Floating if v.len() == 7 => {
            Isometry3::from_parts(t(at(0), at(1), at(2)), quat(at(3), at(4), at(5), at(6)))
        }
        JointKind::Floating => {
            Isometry3::from_parts(t(at(0), at(1), at(2)), rotvec(at(3), at(4), at(5)))
        }
        // A distance joint placed as a tree edge: the child's point `length` below the
        // parent's along the joint frame's −z (hanging, as a URDF chain does under the default
        // gravity), where the rod's row `‖d‖² − L²` holds and its gradient `2 d` is not zero;
        // at the parent's point (`d = 0`) the row would be violated and its gradient vanish.
        JointKind::Distance { length } => {
            Isometry3::from_parts(t(0.0, 0.0, -length), UnitQuaternion::identity())
        }
        JointKind::Fixed | JointKind::PointOnLine => Isometry3::identity(),
    }
}
