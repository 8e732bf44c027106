//! Position servos from the import options (`--servo`), and named reference poses from SRDF
//! `group_state` elements.
//!
//! A servo on a single-coordinate joint is the joint spring `τ = −k (θ − θ_ref)`: the
//! actuator of a position-controlled joint at stiffness `k`, holding it about `θ_ref`. Its
//! reference is, first found: the one given with the servo, the joint's value in the
//! reference pose (`ImportOptions::servo_reference`), the joint's initial value, 0.

use super::import::Builder;
use super::ImportOptions;
use crate::error::{Error, Result};
use crate::model::JointKind;
use std::path::Path;

/// A position servo requested by name (or on every actuated joint).
#[derive(Clone, Debug, PartialEq)]
pub struct ServoRequest {
    /// The joint; `None`: every revolute, continuous and prismatic joint that is neither
    /// locked nor a mimic.
    pub joint: Option<String>,
    /// Stiffness \[N m/rad or N/m\].
    pub stiffness: f64,
    /// Reference \[rad or m\]; `None`: from the reference pose, else the initial value.
    pub reference: Option<f64>,
}

/// Where the servos' references make the start `(joint, value)`: the reference pose
/// (`ImportOptions::servo_reference`), then the reference given with a named joint's servo
/// (`--servo JOINT=K@REF`; a later one wins). A robot held about a crouch starts crouched, as
/// one held about an SRDF state starts in it.
pub(super) fn starts(options: &ImportOptions) -> Vec<(String, f64)> {
    let mut out = options.servo_reference.clone();
    for r in &options.servos {
        if let (Some(joint), Some(value)) = (&r.joint, r.reference) {
            out.retain(|(n, _)| n != joint);
            out.push((joint.clone(), value));
        }
    }
    out
}

/// Adds the servos of `options` to the model being built (later requests replace earlier ones
/// on the same joint, so `all=K` followed by `JOINT=K2` gives JOINT the stiffness K2).
pub(super) fn add(b: &mut Builder, options: &ImportOptions) -> Result<()> {
    for r in &options.servos {
        if !(r.stiffness.is_finite() && r.stiffness > 0.0) {
            return Err(Error::Pose {
                file: "servo".into(),
                message: format!(
                    "servo {}: stiffness {} must be positive and finite",
                    r.joint.as_deref().unwrap_or("all"),
                    r.stiffness
                ),
            });
        }
        let model = b.model.partial();
        let actuated = |id: usize| {
            let j = &model.joints[id];
            !j.merged
                && matches!(
                    j.kind,
                    JointKind::Revolute | JointKind::Continuous | JointKind::Prismatic
                )
        };
        let ids: Vec<usize> = match &r.joint {
            None => (0..model.joints.len())
                .filter(|&id| actuated(id))
                .filter(|&id| !model.locks.iter().any(|l| l.joint.0 == id))
                .filter(|&id| !model.mimics.iter().any(|m| m.joint.0 == id))
                .collect(),
            Some(name) => {
                let id = model
                    .joint_id(name)
                    .ok_or_else(|| model.unknown_joint("servo", name))?;
                if !actuated(id.0) {
                    return Err(Error::Pose {
                        file: "servo".into(),
                        message: format!(
                            "servo on joint `{name}`: a servo holds a revolute, continuous or prismatic joint, `{name}` is {}",
                            model.joints[id.0].kind.name()
                        ),
                    });
                }
                vec![id.0]
            }
        };
        let servos: Vec<_> = ids
            .into_iter()
            .map(|id| {
                let j = &model.joints[id];
                let reference = r
                    .reference
                    .or_else(|| {
                        options
                            .servo_reference
                            .iter()
                            .find(|(n, _)| *n == j.name)
                            .map(|x| x.1)
                    })
                    .or_else(|| {
                        model
                            .initial
                            .iter()
                            .find(|i| i.joint.0 == id && i.dof == 0)
                            .map(|i| i.value)
                    })
                    .unwrap_or(0.0);
                (crate::model::JointId(id), reference)
            })
            .collect();
        for (id, reference) in servos {
            b.model.add_servo(id, r.stiffness, reference);
        }
    }
    Ok(())
}

/// The joint values of the SRDF `<group_state name="STATE">` in `path`, in file order.
///
/// # Errors
/// [`Error::Io`] if unreadable, [`Error::Input`] (with line and column) for malformed XML or a
/// joint value that is not a number, [`Error::Pose`] if the file has no such state (naming
/// the states it has).
pub fn srdf_state(path: impl AsRef<Path>, state: &str) -> Result<Vec<(String, f64)>> {
    let path = path.as_ref();
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|cause| Error::Io {
        path: file.clone(),
        cause,
    })?;
    let doc = roxmltree::Document::parse(&text).map_err(|e| Error::Input {
        file: file.clone(),
        line: e.pos().row,
        col: e.pos().col,
        message: format!("malformed SRDF: {e}"),
        element: String::new(),
    })?;
    let states: Vec<_> = doc
        .descendants()
        .filter(|n| n.has_tag_name("group_state"))
        .collect();
    let Some(node) = states.iter().find(|n| n.attribute("name") == Some(state)) else {
        let names: Vec<_> = states.iter().filter_map(|n| n.attribute("name")).collect();
        return Err(Error::Pose {
            file,
            message: format!(
                "no <group_state name=\"{state}\"> (the file has: {})",
                if names.is_empty() {
                    "none".to_string()
                } else {
                    names.join(", ")
                }
            ),
        });
    };
    let mut out = Vec::new();
    for j in node.children().filter(|n| n.has_tag_name("joint")) {
        let at = doc.text_pos_at(j.range().start);
        let bad = |message: String| Error::Input {
            file: file.clone(),
            line: at.row,
            col: at.col,
            message,
            element: "joint".to_string(),
        };
        let name = j
            .attribute("name")
            .ok_or_else(|| bad("<joint> of a group_state without `name`".into()))?;
        let value = j.attribute("value").unwrap_or("");
        // A multi-valued joint (floating base) lists several numbers: only single values are
        // servo references.
        let mut numbers = value.split_whitespace().map(str::parse::<f64>);
        match (numbers.next(), numbers.next()) {
            (Some(Ok(x)), None) if x.is_finite() => out.push((name.to_string(), x)),
            (Some(Ok(_)), Some(_)) => {}
            _ => {
                return Err(bad(format!(
                    "joint `{name}` of group_state `{state}`: value \"{value}\" is not a number"
                )))
            }
        }
    }
    Ok(out)
}
