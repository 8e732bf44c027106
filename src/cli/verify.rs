//! `restpose verify`: is a given pose a rest pose? Reads the pose, evaluates it without moving
//! it, prints the report.

use super::args::{coord, VerifyArgs};
use super::exit;
use super::report;
use super::{json_out, print};
use anyhow::{bail, Context};
use restpose::urdf::load_file;

/// Runs `verify`: exit 0 when the pose passes, 4 when it does not.
pub(crate) fn run(a: &VerifyArgs) -> anyhow::Result<u8> {
    let options = a.input.options()?;
    // The URDF and the pose file are read at the same time (both are large for large models).
    let (loaded, values) = std::thread::scope(|s| {
        let pose = s.spawn(|| a.pose.as_ref().map(restpose::verify::read_pose));
        let loaded = load_file(&a.file, &options);
        let values = pose
            .join()
            .unwrap_or_else(|panic| std::panic::resume_unwind(panic));
        (loaded, values)
    });
    let loaded = loaded.map_err(|e| a.input.explain(e))?;
    let model = &loaded.model;
    let mut values = values.transpose()?.unwrap_or_default();
    for j in &a.joint {
        let (name, dof, value) = coord(j, "joint")?;
        let id = model
            .joint_id(&name)
            .ok_or_else(|| model.unknown_joint("joint", &name))
            .with_context(|| format!("--joint {j}"))?;
        let n = model
            .get_joint(id)
            .map_or(0, |j| j.kind.scalar_coordinates())
            .max(dof + 1);
        let v = values.entry(name).or_insert_with(|| vec![0.0; n]);
        if v.len() <= dof {
            v.resize(dof + 1, 0.0);
        }
        v[dof] = value;
    }
    // `--lock JOINT=VALUE` sets the value as `--joint` does; every lock holds its coordinate
    // at the pose's value.
    let mut locks = Vec::new();
    for l in &a.lock {
        let (name, dof) = if l.contains('=') {
            let (name, dof, value) = coord(l, "lock")?;
            let v = values
                .entry(name.clone())
                .or_insert_with(|| vec![0.0; dof + 1]);
            if v.len() <= dof {
                v.resize(dof + 1, 0.0);
            }
            v[dof] = value;
            (name, dof)
        } else {
            match l.split_once('[') {
                Some((n, rest)) => (
                    n.to_string(),
                    rest.trim_end_matches(']')
                        .parse()
                        .with_context(|| format!("--lock {l}: bad [DOF]"))?,
                ),
                None => (l.clone(), 0),
            }
        };
        let id = model
            .joint_id(&name)
            .ok_or_else(|| model.unknown_joint("lock", &name))
            .with_context(|| format!("--lock {l}"))?;
        locks.push((id, dof));
    }
    if values.is_empty() && a.pose.is_none() {
        bail!("give the pose with --pose FILE or --joint NAME=VALUE");
    }
    // A floating base: its pose comes from the result JSON's `links` (the root link's
    // `position` and `orientation_wxyz`) or the YAML's `base`, else from `mech:base` /
    // `--base-xyz`.
    let based;
    let model = match a.pose.as_deref().and_then(|p| base_pose(model, p)) {
        Some(pose) => {
            based = model.with_base_pose(pose);
            &based
        }
        None => model,
    };
    // The bodies joint values cannot place (a distance or point-on-line tree joint) from the
    // result JSON's `links`, as `analyze` wrote them.
    let bodies = match a.pose.as_deref() {
        Some(p) => given_bodies(model, p),
        None => Vec::new(),
    };
    let (state, missing) = restpose::verify::pose_state_with_bodies(model, &values, &bodies)?;
    let held;
    let model = if locks.is_empty() {
        model
    } else {
        let mut m = model.clone();
        let now: std::collections::HashMap<String, Vec<f64>> =
            state.joint_values(model).into_iter().collect();
        for (id, dof) in locks {
            let name = model.get_joint(id).map_or("?", |j| j.name.as_str());
            let value = now.get(name).and_then(|v| v.get(dof)).copied();
            let lock = restpose::model::Lock {
                joint: id,
                dof,
                value,
            };
            match (value, m.with_lock(lock)) {
                (Some(_), Some(held)) => m = held,
                _ => bail!("--lock {name}[{dof}]: the joint has no coordinate {dof}"),
            }
        }
        held = m;
        &held
    };
    if !a.quiet && !missing.is_empty() {
        super::print::note!(
            "warning: joints not in the pose keep their initial values: {}",
            missing.join(", ")
        );
    }
    let tol = restpose::verify::Tolerances {
        force: a.force_tolerance,
        constraint: a.constraint_tolerance,
        gap: a.gap_tolerance,
        ..Default::default()
    };
    let uni = a.contact.policy();
    let eigenvalues = if a.eigenvalues {
        restpose::verify::Eigenvalues::Always
    } else {
        restpose::verify::Eigenvalues::WhenCheap
    };
    let v = restpose::verify::verify_reporting(
        model,
        &state,
        &tol,
        &uni,
        a.linear_algebra.into(),
        eigenvalues,
    )?;
    if let Some(path) = &a.json {
        json_out::write(path, |w| json_out::pretty(w, &v))?;
    }
    if !print::is_stdout(a.json.as_ref()) {
        if a.quiet {
            report::verdict(model.name(), &v);
        } else {
            report::verification(model.name(), &v, &tol);
        }
    }
    // The process ends next: its memory goes back whole, without freeing a large model's
    // and report's allocations one by one.
    let passed = v.passed;
    let failures = report::failures(&v.unilateral.failures);
    std::mem::forget((v, state, loaded));
    if passed {
        return Ok(0);
    }
    for line in failures {
        super::print::note!("{}: not a rest pose: {line}", a.file.display());
    }
    Ok(exit::NOT_BALANCED)
}

/// The world pose of the link named like body `b` in a result JSON (`links.NAME.position`
/// and `orientation_wxyz`), as the pose of the body.
fn link_pose(
    model: &restpose::Model,
    json: &serde_json::Value,
    b: restpose::model::BodyId,
) -> Option<nalgebra::Isometry3<f64>> {
    let body = model.bodies().get(b.index())?;
    let link = json.get("links")?.get(&body.name)?;
    let v = |key: &str, n: usize| -> Option<Vec<f64>> {
        let a = link.get(key)?.as_array()?;
        let v: Option<Vec<f64>> = a.iter().map(|x| x.as_f64()).collect();
        v.filter(|v| v.len() == n && v.iter().all(|x| x.is_finite()))
    };
    let (p, o) = (v("position", 3)?, v("orientation_wxyz", 4)?);
    let q = nalgebra::Quaternion::new(o[0], o[1], o[2], o[3]);
    let body_from_link = model.link(&body.name)?.body_from_link;
    (q.norm() > 0.0).then(|| {
        nalgebra::Isometry3::from_parts(
            nalgebra::Translation3::new(p[0], p[1], p[2]),
            nalgebra::UnitQuaternion::from_quaternion(q),
        ) * body_from_link.inverse()
    })
}

/// The pose file as JSON, when it is one.
fn read_json(path: &std::path::Path) -> Option<serde_json::Value> {
    let text = std::fs::read_to_string(path).ok()?;
    serde_json::from_str(&text).ok()
}

/// The world poses of the bodies joint values cannot place
/// ([`restpose::State::bodies_without_values`]) in a result JSON `path`.
fn given_bodies(
    model: &restpose::Model,
    path: &std::path::Path,
) -> Vec<(restpose::model::BodyId, nalgebra::Isometry3<f64>)> {
    let wanted = restpose::State::bodies_without_values(model);
    if wanted.is_empty() {
        return Vec::new();
    }
    let Some(json) = read_json(path) else {
        return Vec::new();
    };
    wanted
        .into_iter()
        .filter_map(|b| link_pose(model, &json, b).map(|p| (b, p)))
        .collect()
}

/// The pose of the floating root link in a result JSON `path` (`links.ROOT.position` and
/// `orientation_wxyz`) or a joint-states YAML (`base.position` and `orientation_wxyz`, with
/// `base.link` the root link), when the model's base floats (a body that no tree joint moves).
fn base_pose(model: &restpose::Model, path: &std::path::Path) -> Option<nalgebra::Isometry3<f64>> {
    // The bodies some tree joint moves, in one pass (a scan of the joints per body was
    // `O(N²)` name comparisons: 10 % of `verify` at 10,000 links).
    let mut moved = vec![false; model.bodies().len()];
    for j in model.joints().iter().filter(|j| j.tree && !j.merged) {
        if let Some(c) = j.bodies[1] {
            moved[c.index()] = true;
        }
    }
    let root = model
        .bodies()
        .iter()
        .zip(&moved)
        .find(|(_, &m)| !m)
        .map(|(b, _)| b)?;
    let text = std::fs::read_to_string(path).ok()?;
    // JSON, or YAML (a joint-states file with restpose's `base` section).
    let json: serde_json::Value = serde_json::from_str(&text)
        .ok()
        .or_else(|| serde_yaml_ng::from_str(&text).ok())?;
    let link = match json.get("base") {
        Some(b) if b.get("link").and_then(|l| l.as_str()) == Some(root.name.as_str()) => b,
        _ => json.get("links")?.get(&root.name)?,
    };
    let v = |key: &str, n: usize| -> Option<Vec<f64>> {
        let a = link.get(key)?.as_array()?;
        let v: Option<Vec<f64>> = a.iter().map(|x| x.as_f64()).collect();
        v.filter(|v| v.len() == n && v.iter().all(|x| x.is_finite()))
    };
    let (p, o) = (v("position", 3)?, v("orientation_wxyz", 4)?);
    let q = nalgebra::Quaternion::new(o[0], o[1], o[2], o[3]);
    (q.norm() > 0.0).then(|| {
        nalgebra::Isometry3::from_parts(
            nalgebra::Translation3::new(p[0], p[1], p[2]),
            nalgebra::UnitQuaternion::from_quaternion(q),
        )
    })
}
