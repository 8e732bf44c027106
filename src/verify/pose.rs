//! Poses given as joint values: restpose's result JSON, a `{"joint": value}` map (JSON), or a
//! ROS `joint_states`-style document (`name` and `position` lists, JSON or YAML, with
//! restpose's `multi_dof` mapping `JOINT: [values]` for joints with several coordinates). The
//! output of `rostopic echo` / `ros2 topic echo` is accepted: YAML documents separated or
//! ended by `---` lines, of which the last non-empty one is the pose.
//!
//! A pose is turned into a state by forward kinematics along the spanning tree
//! ([`State::from_joint_values`]); loop joints are not moved, so their closure error is part
//! of what verification reports.

use crate::error::{Error, Result};
use crate::model::Model;
use crate::state::{JointValues, State};
use std::path::Path;

/// Reads a pose file (format detected from its content).
///
/// # Errors
/// [`Error::Io`] if unreadable, [`Error::Pose`] naming the file if it is none of the formats.
pub fn read_pose(path: impl AsRef<Path>) -> Result<JointValues> {
    let path = path.as_ref();
    let text = std::fs::read_to_string(path).map_err(|cause| Error::Io {
        path: path.display().to_string(),
        cause,
    })?;
    parse_pose(&text, &path.display().to_string())
}

/// The single-coordinate joints of a pose file as a servos' reference pose
/// (`--servo-reference FILE`), sorted by name.
///
/// # Errors
/// As [`read_pose`].
pub fn read_reference_pose(path: impl AsRef<Path>) -> Result<Vec<(String, f64)>> {
    let mut named: Vec<(String, f64)> = read_pose(path)?
        .into_iter()
        .filter(|(_, v)| v.len() == 1)
        .map(|(n, v)| (n, v[0]))
        .collect();
    named.sort_by(|a, b| a.0.cmp(&b.0));
    Ok(named)
}

fn numbers(v: &serde_json::Value) -> Option<Vec<f64>> {
    match v {
        serde_json::Value::Number(n) => n.as_f64().map(|x| vec![x]),
        serde_json::Value::Array(a) => a.iter().map(|x| x.as_f64()).collect(),
        _ => None,
    }
}

/// Parses pose text; `file` names it in errors.
///
/// # Errors
/// [`Error::Pose`] if the text is not one of the accepted formats.
pub fn parse_pose(text: &str, file: &str) -> Result<JointValues> {
    match result_joints(text) {
        Some(values) => Ok(values),
        None => parse_general(text, file),
    }
}

/// [`parse_pose`] for every accepted format, through a tree of the whole document.
fn parse_general(text: &str, file: &str) -> Result<JointValues> {
    let bad = |why: String| Error::Pose {
        file: file.into(),
        message: why,
    };
    let value: serde_json::Value = match serde_json::from_str(text) {
        Ok(v) => v,
        Err(_) => serde_yaml_ng::from_str(last_document(text))
            .map_err(|e| bad(format!("neither JSON nor YAML ({e})")))?,
    };
    let obj = value
        .as_object()
        .ok_or_else(|| bad("expected an object / mapping at the top".into()))?;
    let mut out = JointValues::new();
    if let (Some(names), Some(pos)) = (obj.get("name"), obj.get("position")) {
        let names = names
            .as_array()
            .ok_or_else(|| bad("`name` must be a list".into()))?;
        let pos = numbers(pos).ok_or_else(|| bad("`position` must be a list of numbers".into()))?;
        if names.len() != pos.len() {
            return Err(bad(format!(
                "{} names but {} positions",
                names.len(),
                pos.len()
            )));
        }
        for (n, p) in names.iter().zip(pos) {
            let n = n
                .as_str()
                .ok_or_else(|| bad("joint names must be strings".into()))?;
            out.insert(n.to_string(), vec![p]);
        }
        if let Some(multi) = obj.get("multi_dof") {
            let multi = multi
                .as_object()
                .ok_or_else(|| bad("`multi_dof` must map joint names to lists".into()))?;
            for (name, v) in multi {
                let p = numbers(v)
                    .ok_or_else(|| bad(format!("multi_dof.{name}: expected a list of numbers")))?;
                out.insert(name.clone(), p);
            }
        }
    } else if let Some(joints) = obj.get("joints").and_then(|j| j.as_object()) {
        for (name, j) in joints {
            let p = j
                .get("position")
                .and_then(numbers)
                .ok_or_else(|| bad(format!("joints.{name}.position must be a list of numbers")))?;
            out.insert(name.clone(), p);
        }
    } else {
        for (name, v) in obj {
            let p = numbers(v)
                .ok_or_else(|| bad(format!("`{name}`: expected a number or a list of numbers")))?;
            out.insert(name.clone(), p);
        }
    }
    if out.values().flatten().any(|x| !x.is_finite()) {
        return Err(bad("non-finite joint value".into()));
    }
    Ok(out)
}

/// The shape of restpose's result JSON, as far as a pose needs it: the other fields (links,
/// reactions, …: most of a large result's bytes) are skipped without being built.
#[derive(serde::Deserialize)]
struct ResultShape {
    name: Option<serde::de::IgnoredAny>,
    position: Option<serde::de::IgnoredAny>,
    joints: Option<std::collections::HashMap<String, JointPosition>>,
}

/// One joint of a result: its coordinate values.
#[derive(serde::Deserialize)]
struct JointPosition {
    position: Vec<f64>,
}

/// The joint values of a restpose result JSON by a typed parse; `None` for anything else (or
/// anything wrong), which the general path then reads or reports. Same answer as the general
/// path (`joints.NAME.position`, unless `name` and `position` lists are present), without
/// building a tree of the whole document.
fn result_joints(text: &str) -> Option<JointValues> {
    let r: ResultShape = serde_json::from_str(text).ok()?;
    if r.name.is_some() && r.position.is_some() {
        return None;
    }
    let values: JointValues = r
        .joints?
        .into_iter()
        .map(|(name, j)| (name, j.position))
        .collect();
    values
        .values()
        .flatten()
        .all(|x| x.is_finite())
        .then_some(values)
}

/// The last non-empty YAML document of `text`: documents are separated or ended by `---`
/// lines (`rostopic echo` ends each message with one) and may end with `...`.
fn last_document(text: &str) -> &str {
    let mut last = text;
    let mut start = 0;
    let mut pos = 0;
    for line in text.split_inclusive('\n') {
        let marker = line.trim_end();
        if marker == "---" || marker == "..." {
            let doc = &text[start..pos];
            if has_content(doc) {
                last = doc;
            }
            start = pos + line.len();
        }
        pos += line.len();
    }
    let tail = &text[start..];
    if has_content(tail) {
        last = tail;
    }
    last
}

/// Whether a YAML document has anything besides blank lines and comments.
fn has_content(doc: &str) -> bool {
    doc.lines()
        .map(str::trim)
        .any(|l| !l.is_empty() && !l.starts_with('#'))
}

/// The state of a pose: forward kinematics with the given values; joints not given keep their
/// initial-guess values. Returns the state and the names of the movable tree joints that were
/// not given.
///
/// # Errors
/// [`Error::UnknownJoint`] for a joint the model does not have, [`Error::ValueCount`] for a
/// value list of the wrong length.
pub fn pose_state(model: &Model, values: &JointValues) -> Result<(State, Vec<String>)> {
    pose_state_with_bodies(model, values, &[])
}

/// [`pose_state`] with the world poses of the bodies that joint values cannot place
/// ([`State::bodies_without_values`]), as a result JSON's `links` give them.
/// # Errors
/// As [`pose_state`].
pub fn pose_state_with_bodies(
    model: &Model,
    values: &JointValues,
    bodies: &[(crate::model::BodyId, nalgebra::Isometry3<f64>)],
) -> Result<(State, Vec<String>)> {
    let initial = crate::solver::initial_values(model);
    // `joint_id` looks names up in the model's map: a pose names every joint.
    for (name, v) in values {
        let id = model
            .joint_id(name)
            .ok_or_else(|| model.unknown_joint("pose", name))?;
        let j = model.joint(id);
        let expected = j.kind.value_counts();
        if !expected.contains(&v.len()) {
            return Err(Error::ValueCount {
                file: "pose".into(),
                joint: name.clone(),
                kind: j.kind.name().into(),
                expected: expected.to_vec(),
                got: v.len(),
            });
        }
    }
    // The given values over the initial ones: the given map itself where it names every
    // joint with an initial value (a result JSON names them all), without copying it.
    let all = if initial.keys().all(|k| values.contains_key(k)) {
        std::borrow::Cow::Borrowed(values)
    } else {
        let mut all = initial;
        for (name, v) in values {
            all.insert(name.clone(), v.clone());
        }
        std::borrow::Cow::Owned(all)
    };
    let missing = model
        .joints
        .iter()
        .filter(|j| {
            j.tree
                && !j.merged
                && j.kind != crate::model::JointKind::Fixed
                && !values.contains_key(&j.name)
        })
        .map(|j| j.name.clone())
        .collect();
    Ok((
        State::from_joint_values_and_bodies(model, &all, bodies),
        missing,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The typed parse of a result JSON gives what the general path gives, and declines the
    /// other formats (and results it cannot read), which the general path then handles.
    #[test]
    fn typed_result_parse_equals_the_general_path() {
        let result = r#"{"robot": "r", "links": {"a": {"position": [1, 2, 3]}},
            "joints": {"j1": {"position": [0.5], "unit": "rad"}, "s": {"position": [1, 0, 0, 0]},
                       "k": {"position": [2]}},
            "stability": {"verdict": "stable", "eigenvalues": [1.0]}}"#;
        let typed = result_joints(result).expect("a result is read by the typed parse");
        assert_eq!(typed, parse_general(result, "f").unwrap());
        assert_eq!(typed["s"], vec![1.0, 0.0, 0.0, 0.0]);
        for other in [
            r#"{"name": ["a"], "position": [1.0], "joints": {"a": {"position": [2.0]}}}"#,
            r#"{"a": 1.0, "b": [1, 2]}"#,
            r#"{"joints": {"a": {"position": null}}}"#,
            r#"{"joints": [1, 2]}"#,
            "name: [a]\nposition: [1.0]\n",
        ] {
            assert!(result_joints(other).is_none(), "{other}");
        }
        let ros = r#"{"name": ["a"], "position": [1.0], "joints": {"a": {"position": [2.0]}}}"#;
        assert_eq!(parse_pose(ros, "f").unwrap()["a"], vec![1.0]);
        assert!(parse_pose(r#"{"joints": {"a": {"position": null}}}"#, "f").is_err());
    }
}
