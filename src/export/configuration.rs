//! A pose as the configuration vector `q` of another tool that reads the same URDF: MuJoCo's
//! `qpos` and Pinocchio's `q`.
//!
//! Both tools walk the URDF joint tree depth first from the root link; they differ in the
//! order of a link's children and in the quaternion convention:
//!
//! | | children of a link | floating base (first) | continuous joint | `spherical` |
//! |---|---|---|---|---|
//! | MuJoCo (`mj_loadXML` of the URDF) | `<joint>` element order | `x y z` + `w x y z` | `θ` | `w x y z` (ball) |
//! | Pinocchio (`buildModelFromUrdf`) | sorted by joint name (urdfdom's `std::map`) | `x y z` + `x y z w` | `cos θ, sin θ` | not read (urdfdom) |
//!
//! Revolute and prismatic joints give one entry `θ` or `d` about or along their axis, as in the
//! URDF; fixed joints give none; a `<mimic>` follower keeps its own entry (its value, which
//! the mimic constraint holds at `m θ_ref + offset`). The floating base is the pose of the
//! root link in the world, `world_from_root = (x, y, z, quaternion)`.

use crate::joint::Entry as Value;
use crate::model::{JointId, JointKind, Model};
use crate::names::NameMap;
use crate::state::State;

/// Whose configuration vector.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Convention {
    /// MuJoCo's `qpos` (children in `<joint>` element order, quaternions `w x y z`).
    Mujoco,
    /// Pinocchio's `q` (children sorted by joint name, quaternions `x y z w`, a continuous
    /// joint as `cos θ, sin θ`).
    Pinocchio,
}

/// One entry of a configuration vector: the joint it belongs to (`None`: the floating base)
/// and its value.
#[derive(Clone, Debug, PartialEq)]
pub struct Entry {
    /// The joint, or `None` for the floating base's seven entries.
    pub joint: Option<JointId>,
    /// The value \[m, rad, or 1 for quaternion and cos/sin components\].
    pub value: f64,
}

/// The configuration vector of `state` in the tool's order, or why the tool cannot describe
/// the model (a joint type its URDF reader does not take, a loop joint).
///
/// # Errors
/// A message naming the joint when a tree joint is of a type the tool does not read from a
/// URDF: other than revolute, continuous, prismatic, fixed, floating (and spherical for
/// MuJoCo). Planar joints are refused too (both tools read them, with their own axes).
pub fn configuration(
    model: &Model,
    state: &State,
    convention: Convention,
) -> Result<Vec<Entry>, String> {
    configuration_of(model, state, &state.joint_values(model), convention)
}

/// [`configuration`] with the joint values of `state` already at hand (`values`, as
/// [`State::joint_values`] gives them).
pub(crate) fn configuration_of(
    model: &Model,
    state: &State,
    values: &[(String, Vec<f64>)],
    convention: Convention,
) -> Result<Vec<Entry>, String> {
    let tree: Vec<usize> = (0..model.joints.len())
        .filter(|&j| model.joints[j].tree)
        .collect();
    // Looked up by name only (never iterated in hash order), hashed by the names' hasher.
    let children_of_joints: NameMap<&str, ()> = tree
        .iter()
        .map(|&j| (model.joints[j].child_link.as_str(), ()))
        .collect();
    let mut children: NameMap<&str, Vec<usize>> = NameMap::default();
    for &j in &tree {
        children
            .entry(model.joints[j].parent_link.as_str())
            .or_default()
            .push(j);
    }
    if convention == Convention::Pinocchio {
        for list in children.values_mut() {
            list.sort_by(|&a, &b| model.joints[a].name.cmp(&model.joints[b].name));
        }
    }
    let mut out = Vec::new();
    let roots: Vec<_> = model
        .links
        .iter()
        .filter(|l| !children_of_joints.contains_key(l.name.as_str()))
        .collect();
    for root in roots {
        if let Some(b) = root.body {
            let pose = state.body_pose(b) * root.body_from_link;
            let t = pose.translation.vector;
            let r = pose.rotation;
            let quat = match convention {
                Convention::Mujoco => [r.w, r.i, r.j, r.k],
                Convention::Pinocchio => [r.i, r.j, r.k, r.w],
            };
            out.extend(
                [t.x, t.y, t.z]
                    .into_iter()
                    .chain(quat)
                    .map(|value| Entry { joint: None, value }),
            );
        }
        let mut stack: Vec<usize> = children
            .get(root.name.as_str())
            .map(|c| c.iter().rev().copied().collect())
            .unwrap_or_default();
        while let Some(j) = stack.pop() {
            let joint = &model.joints[j];
            let v = &values[j].1;
            let entries = joint_entries(joint.kind, v, convention).ok_or_else(|| {
                format!(
                    "joint `{}` is of type {}, which {} does not read from a URDF",
                    joint.name,
                    joint.kind.name(),
                    match convention {
                        Convention::Mujoco => "MuJoCo",
                        Convention::Pinocchio => "Pinocchio",
                    }
                )
            })?;
            out.extend(entries.into_iter().map(|value| Entry {
                joint: Some(JointId(j)),
                value,
            }));
            if let Some(c) = children.get(joint.child_link.as_str()) {
                stack.extend(c.iter().rev().copied());
            }
        }
    }
    Ok(out)
}

/// The values of a vector only.
pub fn values(entries: &[Entry]) -> Vec<f64> {
    entries.iter().map(|e| e.value).collect()
}

/// A joint's entries from its restpose coordinates `v` (see [`State::joint_values`]), as its
/// kind's file says ([`crate::joint::Spec::configuration`]); `None` if the tool does not read
/// the kind from a URDF.
fn joint_entries(kind: JointKind, v: &[f64], convention: Convention) -> Option<Vec<f64>> {
    let at = |i: usize| v.get(i).copied().unwrap_or(0.0);
    let c = kind.spec().configuration;
    let entries = match convention {
        Convention::Mujoco => c.mujoco,
        Convention::Pinocchio => c.pinocchio,
    }?;
    Some(
        entries
            .iter()
            .map(|e| match *e {
                Value::Value(i) => at(i),
                Value::Cos(i) => at(i).cos(),
                Value::Sin(i) => at(i).sin(),
            })
            .collect(),
    )
}
