//! A MuJoCo keyframe of a pose: an MJCF file that loads the URDF (as a model asset, attached
//! to the world with its names unchanged) and holds the pose as
//! `<key name="rest" qpos="…"/>`.
//!
//! `qpos` is [`super::configuration`]'s MuJoCo order: depth first over the URDF tree, a link's
//! children in `<joint>` element order, fixed joints without an entry, a mimic follower with
//! its own entry. A floating base is a `<freejoint>` on a body that carries the URDF's root
//! link, so its seven entries `x y z w x y z` (the root link's pose in the world) come first.
//! A URDF loaded by MuJoCo has no actuators, so the key has no `ctrl`.
//!
//! Opening the file (`mujoco.MjModel.from_xml_path("rest.xml")`, `simulate rest.xml`) loads
//! the robot with the key; `mj_resetDataKeyframe(model, data, 0)` puts it in the rest pose.

use super::configuration::{configuration, values, Convention};
use crate::model::Model;
use crate::state::State;
use std::fmt::Write;

/// The MJCF text of the keyframe; `urdf` is the URDF's path as MuJoCo should open it
/// (relative to the written file's folder, or absolute).
///
/// # Errors
/// A message naming the joint when the model has a joint MuJoCo does not read from a URDF.
pub fn mujoco_key(model: &Model, state: &State, urdf: &str) -> Result<String, String> {
    let q = values(&configuration(model, state, Convention::Mujoco)?);
    let floating = state.floating_base(model).is_some();
    let qpos: Vec<String> = q.iter().map(|v| format!("{v:?}")).collect();
    let mut s = String::new();
    let _ = writeln!(
        s,
        "<!-- rest pose of `{}` written by restpose: MuJoCo opens this file, which loads the \
         URDF, with the pose as keyframe `rest` -->",
        comment(&model.name)
    );
    let _ = writeln!(s, "<mujoco model=\"{}\">", attr(&model.name));
    let _ = writeln!(s, "  <asset>");
    let _ = writeln!(s, "    <model name=\"urdf\" file=\"{}\"/>", attr(urdf));
    let _ = writeln!(s, "  </asset>");
    let _ = writeln!(s, "  <worldbody>");
    // The URDF's world, attached as a frame (its root link a body, or the world itself when
    // the root link is named `world`); names unchanged (no prefix).
    let attach = "<attach model=\"urdf\" prefix=\"\"/>";
    if floating {
        let _ = writeln!(s, "    <body name=\"floating_base\">");
        let _ = writeln!(s, "      <freejoint name=\"floating_base\"/>");
        let _ = writeln!(s, "      {attach}");
        let _ = writeln!(s, "    </body>");
    } else {
        let _ = writeln!(s, "    {attach}");
    }
    let _ = writeln!(s, "  </worldbody>");
    let _ = writeln!(s, "  <keyframe>");
    let _ = writeln!(s, "    <key name=\"rest\" qpos=\"{}\"/>", qpos.join(" "));
    let _ = writeln!(s, "  </keyframe>");
    let _ = writeln!(s, "</mujoco>");
    Ok(s)
}

/// `s` escaped for an XML attribute value in double quotes.
pub fn attr(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// `s` safe inside an XML comment (no `--`).
fn comment(s: &str) -> String {
    s.replace("--", "- -")
}
