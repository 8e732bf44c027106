//! The configuration `q`: 7 coordinates per body, `[x, y, z, e0, e1, e2, e3]`.
//!
//! Body poses are `world_from_body = (r, A(p))`; a link's pose is
//! `world_from_link = world_from_body * body_from_link`. Initial states come from forward
//! kinematics along the spanning tree: `world_from_child = world_from_parent * parent_from_J ·
//! M(θ) · (child_from_J)⁻¹` with `M` the joint motion in the joint frame (see
//! [`crate::model::JointKind`]).
//!
//! Joint angles are real numbers, read on the branches the state carries
//! ([`crate::kinematics::Branches`]): a state built with a joint at 3.5 rad reports 3.5, not
//! 3.5 − 2π, and a solve tracks each angle continuously from its start.

use crate::jet::pair_of;
use crate::joint::TreeMotion;
use crate::kinematics::{coordinate_value, motion, Branches};
use crate::math::{euler_parameters, unit_quaternion};
use crate::model::{BodyId, JointId, Model};
use nalgebra::{DVector, Isometry3, Translation3, Vector4};
use std::collections::HashMap;

/// A configuration of the model.
#[derive(Clone, Debug, PartialEq)]
pub struct State {
    /// Coordinates, 7 per body.
    pub q: DVector<f64>,
    /// The branch on which each joint angle is read (which multiple of 2π it carries).
    pub branches: Branches,
}

/// Joint coordinate values by joint name (see [`crate::model::JointKind`] for the order of coordinates).
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
        State::from_joint_values_and_bodies(model, values, &[])
    }

    /// [`State::from_joint_values`] with the world poses of some bodies given: they are placed
    /// there, and their subtrees from them. A pose file needs them for a body that a tree
    /// joint without coordinates places (a distance or point-on-line joint, which leaves the
    /// body free to move but reports no value).
    pub fn from_joint_values_and_bodies(
        model: &Model,
        values: &JointValues,
        bodies: &[(BodyId, Isometry3<f64>)],
    ) -> State {
        let mut s = State {
            q: DVector::zeros(model.coordinate_count()),
            branches: Branches::default(),
        };
        for (name, v) in values {
            if let Some(id) = model.joint_id(name) {
                let kind = model.joint(id).kind;
                let n = kind.scalar_coordinates();
                for (dof, &x) in v.iter().enumerate().take(n) {
                    if kind.is_angle(dof) {
                        s.branches.set(id, dof, x);
                    }
                }
            }
        }
        for b in 0..model.bodies.len() {
            s.q[7 * b + 3] = 1.0;
        }
        // A body that is no tree joint's child (a floating base) stays at the world origin, or
        // at the base pose, and places its subtree.
        let mut placed = vec![true; model.bodies.len()];
        for j in model.joints.iter().filter(|j| j.tree && !j.merged) {
            if let Some(child) = j.bodies[1] {
                placed[child.0] = false;
            }
        }
        // The floating base starts at the model's base pose (`mech:base`): its root link there.
        if let Some(base) = model.base_pose {
            for (b, body) in model.bodies.iter().enumerate() {
                let root_link = model.links.iter().find(|l| l.name == body.name);
                if let (true, Some(l)) = (placed[b], root_link) {
                    s.set_body_pose(
                        crate::model::BodyId(b),
                        &(base * l.body_from_link.inverse()),
                    );
                }
            }
        }
        for (b, pose) in bodies {
            if b.0 < model.bodies.len() {
                s.set_body_pose(*b, pose);
                placed[b.0] = true;
            }
        }
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

    /// The bodies a tree joint without coordinates places (distance, point-on-line): their
    /// poses are not carried by joint values (see [`State::from_joint_values_and_bodies`]).
    pub fn bodies_without_values(model: &Model) -> Vec<BodyId> {
        model
            .joints
            .iter()
            .filter(|j| j.tree && !j.merged)
            .filter(|j| j.kind.spec().tree_motion == TreeMotion::Pose && j.kind.position_len() == 0)
            .filter_map(|j| j.bodies[1])
            .collect()
    }

    /// The initial guess: forward kinematics with the model's initial values (see
    /// [`initial_values`]).
    pub fn initial(model: &Model) -> State {
        State::from_joint_values(model, &initial_values(model))
    }

    /// The floating base: the root link (the first link that no tree joint moves) and its
    /// pose in the world, when that link is on a body (the base floats); `None` for a base
    /// welded to the world.
    pub fn floating_base<'m>(&self, model: &'m Model) -> Option<(&'m str, Isometry3<f64>)> {
        let moved: std::collections::HashSet<&str> = model
            .joints
            .iter()
            .filter(|j| j.tree)
            .map(|j| j.child_link.as_str())
            .collect();
        let root = model
            .links
            .iter()
            .find(|l| !moved.contains(l.name.as_str()))?;
        let body = root.body?;
        (self.q.len() == model.coordinate_count()).then(|| {
            (
                root.name.as_str(),
                self.body_pose(body) * root.body_from_link,
            )
        })
    }

    /// Coordinates of every joint, as reported in the result: scalar coordinates for
    /// revolute-like joints, the relative rotation `[w, x, y, z]` of a spherical joint,
    /// `[x, y, z, w, qx, qy, qz]` of a floating joint, `[]` otherwise.
    pub fn joint_values(&self, model: &Model) -> Vec<(String, Vec<f64>)> {
        model
            .joints
            .iter()
            .enumerate()
            .map(|(i, j)| (j.name.clone(), self.values_of(model, JointId(i))))
            .collect()
    }

    /// Coordinates of the joint `name` as in [`State::joint_values`] (angles unwrapped on the
    /// state's branches), or `None` if the model has no such joint.
    ///
    /// ```
    /// let loaded = restpose::urdf::load_file("robots/pendulum.urdf", &Default::default())?;
    /// let (state, _) = restpose::solve(&loaded.model, &Default::default())?;
    /// let theta = state.joint(&loaded.model, "pivot").unwrap();
    /// assert_eq!(theta.len(), 1);
    /// # Ok::<(), restpose::Error>(())
    /// ```
    pub fn joint(&self, model: &Model, name: &str) -> Option<Vec<f64>> {
        model.joint_id(name).map(|id| self.values_of(model, id))
    }

    fn values_of(&self, model: &Model, id: JointId) -> Vec<f64> {
        let j = model.joint(id);
        if self.q.len() != model.coordinate_count() {
            return vec![];
        }
        let pair = pair_of(&j.bodies, &self.q, false);
        let n = j.kind.scalar_coordinates();
        if n > 0 {
            // The values alone: bit for bit the coordinates' jets' values.
            (0..n)
                .map(|d| coordinate_value(j, &pair, d, self.branches.get(id, d)).unwrap_or(0.0))
                .collect()
        } else {
            let pose = |k: usize| match j.bodies[k] {
                Some(b) => self.body_pose(b) * j.body_from_joint[k],
                None => j.body_from_joint[k],
            };
            (j.kind.spec().values_of_motion)(&(pose(0).inverse() * pose(1)))
        }
    }
}

/// The model's initial values by joint (missing coordinates 0), a lock's value replacing the
/// initial value of the coordinate it holds (the start is then on the lock's branch: a lock at
/// 3.2 rad is not read as 3.2 − 2π).
pub fn initial_values(model: &Model) -> JointValues {
    let mut values = JointValues::new();
    let given = model
        .initial
        .iter()
        .map(|i| (i.joint, i.dof, i.value))
        .chain(
            model
                .locks
                .iter()
                .filter_map(|l| l.value.map(|v| (l.joint, l.dof, v))),
        );
    for (joint, dof, value) in given {
        let Some(j) = model.joints.get(joint.0) else {
            continue;
        };
        let v = values
            .entry(j.name.clone())
            .or_insert_with(|| vec![0.0; j.kind.scalar_coordinates()]);
        if v.len() <= dof {
            v.resize(dof + 1, 0.0);
        }
        v[dof] = value;
    }
    values
}
