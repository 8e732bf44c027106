//! The configuration `q`: 7 coordinates per body, `[x, y, z, e0, e1, e2, e3]`.
//!
//! Body poses are `world_from_body = (r, A(p))`; a link's pose is
//! `world_from_link = world_from_body * body_from_link`. Initial states come from forward
//! kinematics along the spanning tree: `world_from_child = world_from_parent * parent_from_J ·
//! M(θ) · (child_from_J)⁻¹` with `M` the joint motion in the joint frame (see
//! [`crate::model::JointKind`]).

use crate::constraints::joint;
use crate::jet::pair_of;
use crate::math::{euler_parameters, unit_quaternion};
use crate::model::{BodyId, JointKind, Model};
use nalgebra::{DVector, Isometry3, Translation3, UnitQuaternion, Vector3, Vector4};
use std::collections::HashMap;

/// A configuration of the model.
#[derive(Clone, Debug, PartialEq)]
pub struct State {
    /// Coordinates, 7 per body.
    pub q: DVector<f64>,
}

/// Joint coordinate values by joint name (see [`JointKind`] for the order of coordinates).
pub type JointValues = HashMap<String, Vec<f64>>;

impl State {
    /// Pose of a body in the world (Euler parameters normalized).
    pub fn body_pose(&self, b: BodyId) -> Isometry3<f64> {
        let i = 7 * b.0;
        let p = Vector4::new(self.q[i + 3], self.q[i + 4], self.q[i + 5], self.q[i + 6]);
        Isometry3::from_parts(
            Translation3::new(self.q[i], self.q[i + 1], self.q[i + 2]),
            unit_quaternion(&p),
        )
    }

    /// Pose of the link `name` in the world, if the link exists.
    pub fn link_pose(&self, model: &Model, name: &str) -> Option<Isometry3<f64>> {
        let link = model.link(name)?;
        Some(match link.body {
            Some(b) => self.body_pose(b) * link.body_from_link,
            None => link.body_from_link,
        })
    }

    fn set_body_pose(&mut self, b: BodyId, pose: &Isometry3<f64>) {
        let i = 7 * b.0;
        self.q
            .fixed_rows_mut::<3>(i)
            .copy_from(&pose.translation.vector);
        self.q
            .fixed_rows_mut::<4>(i + 3)
            .copy_from(&euler_parameters(&pose.rotation));
    }

    /// Forward kinematics along the spanning tree with the given joint values (missing
    /// coordinates are zero). Bodies not reached from the world start at the identity.
    pub fn from_joint_values(model: &Model, values: &JointValues) -> State {
        let mut s = State {
            q: DVector::zeros(model.coordinate_count()),
        };
        for b in 0..model.bodies.len() {
            s.q[7 * b + 3] = 1.0;
        }
        let mut placed = vec![false; model.bodies.len()];
        let mut changed = true;
        while changed {
            changed = false;
            for j in model.joints.iter().filter(|j| j.tree && !j.merged) {
                let Some(child) = j.bodies[1] else { continue };
                if placed[child.0] {
                    continue;
                }
                let parent_pose = match j.bodies[0] {
                    None => Isometry3::identity(),
                    Some(p) if placed[p.0] => s.body_pose(p),
                    Some(_) => continue,
                };
                let v = values.get(&j.name).map(Vec::as_slice).unwrap_or(&[]);
                let pose = parent_pose
                    * j.body_from_joint[0]
                    * motion(j.kind, v)
                    * j.body_from_joint[1].inverse();
                s.set_body_pose(child, &pose);
                placed[child.0] = true;
                changed = true;
            }
        }
        s
    }

    /// The initial guess: forward kinematics with the model's initial values.
    pub fn initial(model: &Model) -> State {
        State::from_joint_values(model, &initial_values(model))
    }

    /// Coordinates of every joint, as reported in the result: scalar coordinates for
    /// revolute-like joints, the relative rotation `[w, x, y, z]` of a spherical joint,
    /// `[x, y, z, w, qx, qy, qz]` of a floating joint, `[]` otherwise.
    pub fn joint_values(&self, model: &Model) -> Vec<(String, Vec<f64>)> {
        model
            .joints
            .iter()
            .map(|j| {
                let pair = pair_of(&j.bodies, &self.q, false);
                let n = j.kind.scalar_coordinates();
                let v = if n > 0 {
                    (0..n)
                        .map(|d| {
                            let x = joint::coordinate(j, &pair, d).map_or(0.0, |s| s.v);
                            if crate::forces::is_angle(j.kind, d) {
                                crate::math::wrap_angle(x)
                            } else {
                                x
                            }
                        })
                        .collect()
                } else {
                    let pose = |k: usize| match j.bodies[k] {
                        Some(b) => self.body_pose(b) * j.body_from_joint[k],
                        None => j.body_from_joint[k],
                    };
                    let rel = pose(0).inverse() * pose(1);
                    let r = rel.rotation;
                    match j.kind {
                        JointKind::Spherical => vec![r.w, r.i, r.j, r.k],
                        JointKind::Floating => {
                            let t = rel.translation.vector;
                            vec![t.x, t.y, t.z, r.w, r.i, r.j, r.k]
                        }
                        _ => vec![],
                    }
                };
                (j.name.clone(), v)
            })
            .collect()
    }
}

/// The model's initial values by joint (`mech:initial`; missing coordinates 0).
pub(crate) fn initial_values(model: &Model) -> JointValues {
    let mut values = JointValues::new();
    for i in &model.initial {
        let Some(j) = model.joints.get(i.joint.0) else {
            continue;
        };
        let v = values
            .entry(j.name.clone())
            .or_insert_with(|| vec![0.0; j.kind.scalar_coordinates()]);
        if v.len() <= i.dof {
            v.resize(i.dof + 1, 0.0);
        }
        v[i.dof] = i.value;
    }
    values
}

/// Relative motion of a joint of this kind in its joint frame for coordinates `v` (the
/// coordinates of [`State::joint_values`]; a spherical joint also takes a rotation vector of 3
/// values, a floating joint `[x, y, z, rx, ry, rz]`).
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
        JointKind::Fixed | JointKind::Distance { .. } | JointKind::PointOnLine => {
            Isometry3::identity()
        }
    }
}
