//! ROS `joint_states`-style YAML: `name` and `position` lists of the single-coordinate joints
//! (revolute, continuous, prismatic, screw), the joints a `sensor_msgs/JointState` describes.

use crate::model::Model;
use crate::state::State;
use std::fmt::Write;

/// YAML text of the single-coordinate joints of `state`, in model order.
pub fn joint_states_yaml(model: &Model, state: &State) -> String {
    let mut names = Vec::new();
    let mut positions = Vec::new();
    for ((name, values), joint) in state.joint_values(model).into_iter().zip(&model.joints) {
        if joint.kind.scalar_coordinates() == 1 && values.len() == 1 {
            names.push(format!("\"{}\"", name.replace('"', "\\\"")));
            positions.push(format!("{}", values[0]));
        }
    }
    let mut s = String::new();
    let _ = writeln!(s, "# rest pose of `{}` written by restpose", model.name);
    let _ = writeln!(s, "name: [{}]", names.join(", "));
    let _ = writeln!(s, "position: [{}]", positions.join(", "));
    s
}
