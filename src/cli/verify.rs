//! `restpose verify`: is a given pose a rest pose? Reads the pose, evaluates it without moving
//! it, prints the report.

use super::args::{coord, VerifyArgs};
use super::exit;
use super::print;
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
    let loaded = loaded?;
    let model = &loaded.model;
    let mut values = values.transpose()?.unwrap_or_default();
    for j in &a.joint {
        let (name, dof, value) = coord(j, "joint")?;
        let id = model
            .joint_id(&name)
            .ok_or_else(|| model.unknown_joint("joint", &name))
            .with_context(|| format!("--joint {j}"))?;
        let n = model.joint(id).kind.scalar_coordinates().max(dof + 1);
        let v = values.entry(name).or_insert_with(|| vec![0.0; n]);
        if v.len() <= dof {
            v.resize(dof + 1, 0.0);
        }
        v[dof] = value;
    }
    if values.is_empty() && a.pose.is_none() {
        bail!("give the pose with --pose FILE or --joint NAME=VALUE");
    }
    // A floating base: its pose comes from the result JSON's `links` (the root link's
    // `position` and `orientation_wxyz`), else from `mech:base` / `--base-xyz`.
    let based;
    let model = match a.pose.as_deref().and_then(|p| base_pose(model, p)) {
        Some(pose) => {
            let mut m = model.clone();
            m.base_pose = Some(pose);
            based = m;
            &based
        }
        None => model,
    };
    let (state, missing) = restpose::verify::pose_state(model, &values)?;
    if !a.quiet && !missing.is_empty() {
        eprintln!(
            "warning: joints not in the pose keep their initial values: {}",
            missing.join(", ")
        );
    }
    let tol = restpose::verify::Tolerances {
        force: a.force_tolerance,
        constraint: a.constraint_tolerance,
        ..Default::default()
    };
    let uni = restpose::verify::Unilaterals {
        limits: a.limits,
        friction: a.friction,
        mu: a.mu,
    };
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
        a.linear_algebra,
        eigenvalues,
    )?;
    if let Some(path) = &a.json {
        print::write_json(path, &serde_json::to_string_pretty(&v)?)?;
    }
    if !a.quiet && !print::is_stdout(a.json.as_ref()) {
        print::verification(&model.name, &v, &tol);
    }
    if v.passed {
        return Ok(0);
    }
    for f in &v.unilateral.failures {
        eprintln!("{}: not a rest pose: {f}", a.file.display());
    }
    // Only the checks that failed: a pose refused for its friction alone is balanced.
    let out_of_balance = v.constraint_residual > tol.constraint
        || v.unassigned > v.effort_tolerance
        || v.imbalance
            .iter()
            .any(|i| i.effort.abs() > v.effort_tolerance);
    if !out_of_balance && !v.unilateral.failures.is_empty() {
        return Ok(exit::NOT_BALANCED);
    }
    if let Some(m) = &v.max_imbalance {
        eprintln!(
            "{}: not a rest pose: largest imbalance {:.3e} at joint `{}` (dof {}), constraint residual {:.3e}",
            a.file.display(),
            m.effort,
            m.joint,
            m.dof,
            v.constraint_residual
        );
    } else {
        eprintln!(
            "{}: not a rest pose: constraint residual {:.3e}",
            a.file.display(),
            v.constraint_residual
        );
    }
    Ok(exit::NOT_BALANCED)
}

/// The pose of the floating root link in a result JSON `path` (`links.ROOT.position` and
/// `orientation_wxyz`), when the model's base floats (a body that no tree joint moves).
fn base_pose(model: &restpose::Model, path: &std::path::Path) -> Option<nalgebra::Isometry3<f64>> {
    // The bodies some tree joint moves, in one pass (a scan of the joints per body was
    // `O(N²)` name comparisons: 10 % of `verify` at 10,000 links).
    let mut moved = vec![false; model.bodies.len()];
    for j in model.joints.iter().filter(|j| j.tree && !j.merged) {
        if let Some(c) = j.bodies[1] {
            moved[c.index()] = true;
        }
    }
    let root = model
        .bodies
        .iter()
        .zip(&moved)
        .find(|(_, &m)| !m)
        .map(|(b, _)| b)?;
    let text = std::fs::read_to_string(path).ok()?;
    let json: serde_json::Value = serde_json::from_str(&text).ok()?;
    let link = json.get("links")?.get(&root.name)?;
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
