//! ROS `joint_states`-style YAML of a pose.
//!
//! `name` and `position` list the single-coordinate joints (revolute, continuous, prismatic,
//! screw), the joints a `sensor_msgs/JointState` describes. Joints with several coordinates
//! (universal, cylindrical, planar, spherical, floating), which `sensor_msgs/JointState`
//! cannot carry, follow in a `multi_dof` mapping `JOINT: [values]`, in the order and units of
//! the result JSON's `joints.*.position` (a spherical joint's quaternion `[w, x, y, z]`, a
//! floating joint's `[x, y, z, w, qx, qy, qz]`). `restpose verify --pose` reads both back.
//! Joints without coordinates (fixed, distance, point-on-line) are not listed.
//! A floating base adds a `base` mapping: the root link's name, `position` \[m\] and
//! `orientation_wxyz` in the world, as in the result JSON's `links`, which `verify
//! --floating-base --pose` reads back.

use crate::model::Model;
use crate::state::State;
use std::fmt::Write;

/// YAML text of `state`'s joint coordinates, in model order.
pub fn joint_states_yaml(model: &Model, state: &State) -> String {
    let quote = |name: &str| format!("\"{}\"", name.replace('\\', "\\\\").replace('"', "\\\""));
    let mut names = Vec::new();
    let mut positions = Vec::new();
    let mut multi = Vec::new();
    for ((name, values), joint) in state.joint_values(model).into_iter().zip(&model.joints) {
        if joint.kind.scalar_coordinates() == 1 && values.len() == 1 {
            names.push(quote(&name));
            positions.push(format!("{}", values[0]));
        } else if !values.is_empty() {
            let v: Vec<String> = values.iter().map(|x| format!("{x}")).collect();
            multi.push(format!("  {}: [{}]", quote(&name), v.join(", ")));
        }
    }
    let mut s = String::new();
    let _ = writeln!(s, "# rest pose of `{}` written by restpose", model.name);
    let _ = writeln!(s, "name: [{}]", names.join(", "));
    let _ = writeln!(s, "position: [{}]", positions.join(", "));
    if let Some((link, pose)) = state.floating_base(model) {
        let t = pose.translation.vector;
        let r = pose.rotation;
        let _ = writeln!(
            s,
            "# the floating base: its root link's pose in the world (position [m], unit quaternion w x y z)"
        );
        let _ = writeln!(s, "base:");
        let _ = writeln!(s, "  link: {}", quote(link));
        let _ = writeln!(s, "  position: [{:?}, {:?}, {:?}]", t.x, t.y, t.z);
        let _ = writeln!(
            s,
            "  orientation_wxyz: [{:?}, {:?}, {:?}, {:?}]",
            r.w, r.i, r.j, r.k
        );
    }
    if !multi.is_empty() {
        let _ = writeln!(
            s,
            "# joints with several coordinates, as in the result JSON's joints.*.position"
        );
        let _ = writeln!(s, "multi_dof:");
        for line in multi {
            let _ = writeln!(s, "{line}");
        }
    }
    s
}
