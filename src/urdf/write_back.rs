//! Writing a pose back into the input file as `mech:initial` values, so that the next run (or
//! a simulator that reads them) starts at rest.
//!
//! The text is edited, not regenerated: every existing `mech:initial` element is removed and
//! one element per joint is inserted before `</robot>`, so comments, formatting and foreign
//! elements survive. Scalar coordinates are written one per element (`dof` when not 0);
//! spherical and floating joints get their whole coordinate vector in one `value` list
//! (quaternion `w x y z`; `x y z w qx qy qz`), a restpose extension of the format.
//! A floating base's pose (its root link in the world) replaces any `mech:base` as
//! `<mech:base xyz quat_xyzw/>`, so that `--floating-base` starts there. Names are escaped
//! (`&`, `<`, `>`, `"`, `'`) in attribute values.

use super::xml::MECH_NS;
use crate::error::Result;
use crate::model::{JointKind, Model};
use crate::state::State;
use std::fmt::Write;

/// The URDF `text` (named `file` in errors) with `state`'s joint values as `mech:initial`.
///
/// # Errors
/// [`crate::Error::Input`] if `text` is not well-formed XML.
pub fn with_initial_pose(text: &str, file: &str, model: &Model, state: &State) -> Result<String> {
    let mut warnings = Vec::new();
    let mut repaired = None;
    let doc = super::text::parse(text, file, &mut warnings, &mut repaired)?;
    let text = doc.input_text();
    let robot = doc.root_element();
    let prefix = robot.lookup_prefix(MECH_NS).map(str::to_string);
    let tag = prefix.clone().map_or("mech".to_string(), |p| p);
    let base = state.floating_base(model);
    // Byte ranges to delete: existing initial values with the whitespace before them.
    let mut cut: Vec<(usize, usize)> = robot
        .children()
        .filter(|c| {
            c.is_element()
                && c.tag_name().namespace() == Some(MECH_NS)
                && (c.tag_name().name() == "initial"
                    || (c.tag_name().name() == "base" && base.is_some()))
        })
        .map(|c| {
            let r = c.range();
            let start = text[..r.start].trim_end_matches([' ', '\t']).len();
            let start = if text[..start].ends_with('\n') {
                start - 1
            } else {
                start
            };
            (start, r.end)
        })
        .collect();
    cut.sort_unstable();
    let end = robot.range().end;
    let close = text[..end].rfind("</").unwrap_or(end);
    let mut block = String::new();
    if let Some((_, pose)) = base {
        let t = pose.translation.vector;
        let r = pose.rotation;
        let _ = writeln!(
            block,
            "  <{tag}:base xyz=\"{:?} {:?} {:?}\" quat_xyzw=\"{:?} {:?} {:?} {:?}\"/>",
            t.x, t.y, t.z, r.i, r.j, r.k, r.w
        );
    }
    for ((name, values), joint) in state.joint_values(model).into_iter().zip(&model.joints) {
        let name = escape(&name);
        if joint.merged
            || values.is_empty()
            || matches!(joint.kind, JointKind::Fixed | JointKind::Distance { .. })
        {
            continue;
        }
        if matches!(joint.kind, JointKind::Spherical | JointKind::Floating) {
            let list: Vec<String> = values.iter().map(|v| format!("{v}")).collect();
            let _ = writeln!(
                block,
                "  <{tag}:initial joint=\"{name}\" value=\"{}\"/>",
                list.join(" ")
            );
        } else {
            for (dof, v) in values.iter().enumerate() {
                let d = if dof > 0 {
                    format!(" dof=\"{dof}\"")
                } else {
                    String::new()
                };
                let _ = writeln!(
                    block,
                    "  <{tag}:initial joint=\"{name}\"{d} value=\"{v}\"/>"
                );
            }
        }
    }
    let mut out = String::with_capacity(text.len() + block.len() + 64);
    let mut pos = 0;
    for (a, b) in cut {
        out.push_str(&text[pos..a]);
        pos = b;
    }
    out.push_str(&text[pos..close]);
    if !out.ends_with('\n') {
        out.push('\n');
    }
    out.push_str(&block);
    out.push_str(&text[close..]);
    if prefix.is_none() {
        if let Some(at) = out.find("<robot") {
            out.insert_str(at + "<robot".len(), &format!(" xmlns:mech=\"{MECH_NS}\""));
        }
    }
    Ok(out)
}

/// `s` escaped for an attribute value in double or single quotes.
pub(super) fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
        .replace('\'', "&apos;")
}
