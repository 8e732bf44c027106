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
    let v = restpose::verify::verify_with_options(model, &state, &tol, &uni)?;
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
