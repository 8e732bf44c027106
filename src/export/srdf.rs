//! A pose as a MoveIt SRDF named state: `<group_state name="STATE" group="GROUP">` with one
//! `<joint name value/>` per moving joint, after the group's definition (every moving URDF
//! joint) and, when the base floats, a `<virtual_joint type="floating">` from the world to
//! the root link.
//!
//! Values are what MoveIt and Pinocchio's `loadReferenceConfigurations` read: an angle or a
//! length per revolute, continuous or prismatic joint (Pinocchio turns a continuous joint's
//! `θ` into its `cos θ, sin θ`); the floating base (virtual joint `root_joint`, Pinocchio's name
//! for its free flyer) as `x y z qx qy qz qw`, the root link's pose in the world. A model with
//! a joint Pinocchio does not read from a URDF (spherical, planar, restpose's extensions) is
//! refused, naming the joint.

use super::configuration::{configuration, Convention};
use super::mujoco::attr;
use crate::model::{JointKind, Model};
use crate::state::State;
use std::fmt::Write;

/// Name of the floating base's virtual joint (Pinocchio's default root joint name).
pub const ROOT_JOINT: &str = "root_joint";

/// The SRDF text of `state` as named state `state_name` of group `group`.
///
/// # Errors
/// A message naming the joint when the model has a joint type the SRDF cannot describe.
pub fn srdf(model: &Model, state: &State, group: &str, state_name: &str) -> Result<String, String> {
    // Pinocchio's q, grouped back by joint (its entries of one joint are consecutive).
    let q = configuration(model, state, Convention::Pinocchio)?;
    let mut joints: Vec<(String, Vec<f64>)> = Vec::new();
    let mut last = None;
    for e in &q {
        match joints.last_mut() {
            Some((_, v)) if last == Some(e.joint) => v.push(e.value),
            _ => {
                let name = e.joint.map_or(ROOT_JOINT, |j| model.joint(j).name.as_str());
                joints.push((name.to_string(), vec![e.value]));
            }
        }
        last = Some(e.joint);
    }
    let values = state.joint_values(model);
    let mut s = String::new();
    let _ = writeln!(s, "<?xml version=\"1.0\"?>");
    let _ = writeln!(
        s,
        "<!-- rest pose of `{}` written by restpose -->",
        model.name.replace("--", "- -")
    );
    let _ = writeln!(s, "<robot name=\"{}\">", attr(&model.name));
    if let Some((root, _)) = state.floating_base(model) {
        let _ = writeln!(
            s,
            "  <virtual_joint name=\"{ROOT_JOINT}\" type=\"floating\" parent_frame=\"world\" child_link=\"{}\"/>",
            attr(root)
        );
    }
    let _ = writeln!(s, "  <group name=\"{}\">", attr(group));
    for (name, _) in &joints {
        let _ = writeln!(s, "    <joint name=\"{}\"/>", attr(name));
    }
    let _ = writeln!(s, "  </group>");
    let _ = writeln!(
        s,
        "  <group_state name=\"{}\" group=\"{}\">",
        attr(state_name),
        attr(group)
    );
    for (name, v) in &joints {
        // A continuous joint's angle, not Pinocchio's cos/sin pair.
        let kind = model.joint_id(name).map(|id| model.joint(id).kind);
        let v = match kind {
            Some(JointKind::Continuous) => model
                .joint_id(name)
                .map(|id| values[id.index()].1.clone())
                .unwrap_or_default(),
            _ => v.clone(),
        };
        let text: Vec<String> = v.iter().map(|x| format!("{x:?}")).collect();
        let _ = writeln!(
            s,
            "    <joint name=\"{}\" value=\"{}\"/>",
            attr(name),
            text.join(" ")
        );
    }
    let _ = writeln!(s, "  </group_state>");
    let _ = writeln!(s, "</robot>");
    Ok(s)
}
