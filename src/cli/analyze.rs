//! `restpose analyze`: solve for the rest pose, write the requested files, print a summary.

use super::args::{coord, AnalyzeArgs};
use super::{exit, json_out, print};
use restpose::export::json::AnalysisResult;
use restpose::urdf::load_file;
use std::mem::ManuallyDrop;

/// Runs `analyze`: exit 0 when converged, 3 when not, 2 for two outputs to standard output.
pub(crate) fn run(a: &AnalyzeArgs) -> anyhow::Result<u8> {
    if let Err(e) = a.check_outputs() {
        let _ = e.print();
        return Ok(exit::USAGE);
    }
    let mut opts = a.input.options()?;
    for l in &a.lock {
        let (n, d, v) = coord(l, "lock")?;
        opts.locks.push((n, d, Some(v)));
    }
    for l in &a.initial {
        opts.initial.push(coord(l, "initial")?);
    }
    let import_started = std::time::Instant::now();
    // The model, the state, the report and the result live until the process ends, which
    // returns their memory at once: they are not freed one allocation at a time (on a chain
    // of 10,000 links that took 2 % of the run).
    let loaded = ManuallyDrop::new(load_file(&a.file, &opts).map_err(|e| with_option(a, e))?);
    let import = import_started.elapsed().as_secs_f64();
    if !a.quiet {
        for w in &loaded.warnings {
            print::warning(w);
        }
        if a.verbose {
            for i in &loaded.ignored {
                super::print::note!("ignored: {}:{i}", a.file.display());
            }
        }
    }
    let model = &loaded.model;
    let mut solver_options = a.solver_options();
    let progress = super::progress::Line::start();
    if let Some(line) = &progress {
        solver_options.progress = line.callback();
    }
    let solved = restpose::solve(model, &solver_options);
    if let Some(line) = progress {
        line.finish();
    }
    let (state, report) = solved.map_err(|e| match e {
        restpose::Error::ConstantEnergy { .. } if a.input.inertia_from_geometry.is_none() => {
            anyhow::anyhow!(
                "{e}; links without <inertial> can get masses from their geometry with \
                 --inertia-from-geometry DENSITY"
            )
        }
        restpose::Error::ConstantEnergy { .. } => {
            // --inertia-from-geometry was given and weighed nothing: say why even under -q,
            // which keeps the import's warnings off standard error.
            let why: Vec<&String> = loaded
                .warnings
                .iter()
                .filter(|w| w.contains("no mass from geometry"))
                .collect();
            match why.first() {
                Some(first) => anyhow::anyhow!(
                    "{e}; --inertia-from-geometry could not weigh {} link(s), the first: {first}",
                    why.len()
                ),
                None => anyhow::anyhow!(
                    "{e}; --inertia-from-geometry found no link without <inertial> that has \
                     geometry"
                ),
            }
        }
        restpose::Error::Assembly { ref remedy, .. } if remedy.contains("mech:base") => {
            anyhow::anyhow!(
                "{e}; on the command line: --base-xyz X Y Z (and --base-rpy) for the base, \
                 --initial JOINT=VALUE for the joints"
            )
        }
        restpose::Error::Assembly { ref remedy, .. } if remedy.contains("nearly dependent") => {
            anyhow::anyhow!(
                "{e}; on the command line: without --initial the servos' references \
                 (--servo JOINT=K@REF, --srdf-state) are the start; --friction none for \
                 sliding contacts"
            )
        }
        restpose::Error::Inconsistent { ref row, .. }
            if row.contains(".contact[") && (row.ends_with(".t1") || row.ends_with(".t2")) =>
        {
            anyhow::anyhow!(
                "{e}; it is a sticking contact's tangential row, redundant with other sticking \
                 points of the same links, each held where it touched: their anchors disagree \
                 (nearly dependent sticking rows, a leg lying on the ground); on the command \
                 line: without --initial the servos' references (--servo JOINT=K@REF, \
                 --srdf-state) are the start; --friction none for sliding contacts"
            )
        }
        e => e.into(),
    })?;
    let (state, mut report) = (ManuallyDrop::new(state), ManuallyDrop::new(report));
    report.diagnostics.timings.import = import;
    // Never converged on a pose `verify` rejects (module `confirm`).
    let rejected = if report.converged() {
        let confirming = std::time::Instant::now();
        let why = super::confirm::rejection(a, model, &state);
        report.diagnostics.timings.self_check = confirming.elapsed().as_secs_f64();
        why
    } else {
        None
    };
    if rejected.is_some() {
        report.termination = restpose::solver::Termination::RejectedByVerify;
    }
    let export_started = std::time::Instant::now();
    let mut result = ManuallyDrop::new(AnalysisResult::new(model, &state, &report));
    result.diagnostics.timings.export = export_started.elapsed().as_secs_f64();
    if let Some(path) = &a.json {
        json_out::write(path, |w| result.write_json(w))?;
    }
    if let Some(path) = &a.rrd {
        write_rrd(path, model, &state, &report)?;
    }
    if result.converged {
        if let Some(path) = &a.write_urdf {
            let text = restpose::urdf::read_urdf_text(&a.file, &opts)?;
            let name = a.file.display().to_string();
            let mut out = restpose::urdf::with_initial_pose(&text, &name, model, &state)?;
            // Relative mesh names resolve from the written file's folder as from the input's.
            if path.as_os_str() != "-" {
                let folder = |p: &std::path::Path| match p.parent() {
                    Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
                    _ => std::path::PathBuf::from("."),
                };
                out = restpose::urdf::relocated(
                    &out,
                    &name,
                    &folder(&a.file),
                    &folder(path),
                    &opts.packages,
                )?;
            }
            print::write_output(path, &out)?;
            if let Some(note) = super::written::moved_servo_references(&opts, model, &state) {
                super::print::note!("{note}");
            }
        }
        if let Some(path) = &a.write_joint_states {
            let out = restpose::export::joint_states::joint_states_yaml(model, &state);
            print::write_output(path, &out)?;
        }
        super::formats::write(a, model, &state)?;
    } else if a.write_urdf.is_some()
        || a.write_joint_states.is_some()
        || a.formats.write_mujoco_key.is_some()
        || a.formats.write_srdf.is_some()
    {
        super::print::note!(
            "note: --write-urdf / --write-joint-states / --write-mujoco-key / --write-srdf are \
             written only for a converged rest pose"
        );
    }
    if !a.quiet && a.stdout_outputs().is_empty() {
        print::analysis(&result);
    }
    if !a.quiet && result.converged && !result.buried_bodies.is_empty() {
        let buried = &result.buried_bodies;
        let worst: Vec<String> = buried
            .iter()
            .take(3)
            .map(|b| format!("`{}` {:.4} m inside `{}`", b.body, b.depth, b.ground))
            .collect();
        let more = if buried.len() > 3 { ", …" } else { "" };
        let count = match buried.len() {
            1 => "1 body without contact points rests with its".to_string(),
            n => format!("{n} bodies without contact points rest with their"),
        };
        super::print::note!(
            "warning: {count} centre of mass inside a ground ({}{more}): only links with \
             contact points touch the grounds; give them collision geometry or hold the \
             joints (--servo all=K)",
            worst.join(", ")
        );
    }
    if let Some(why) = &rejected {
        super::print::note!(
            "error: {}: the solver's answer fails verify's independent checks ({why}); not reported as a rest pose",
            a.file.display()
        );
        return Ok(exit::NOT_CONVERGED);
    }
    if !result.converged {
        super::print::note!(
            "error: {}: did not converge ({}) after {} iterations; ‖∂V/∂v‖∞ = {:.3e}, ‖Φ‖∞ = {:.3e}, corrector failures {}, step halvings {}, re-partitions {}",
            a.file.display(),
            result.termination,
            result.iterations,
            result.diagnostics.gradient_norm,
            result.diagnostics.constraint_residual,
            result.diagnostics.corrector_failures,
            result.diagnostics.step_halvings,
            result.diagnostics.repartitions
        );
        if !result.diagnostics.free_directions.is_empty() {
            super::print::note!(
                "  the energy falls without bound along: {}",
                result.diagnostics.free_directions.join(", ")
            );
        }
        if a.input.floating_base && !model.grounds().is_empty() {
            let free = unheld_joints(model);
            if let Some(first) = free.first() {
                super::print::note!(
                    "  {} joints are held by no servo, spring or lock (`{first}`, …): a robot \
                     without actuation collapses on the ground, and no rest was found for its \
                     fall; to stand it, hold them like position servos: --servo all=K (about a \
                     named state: --srdf FILE --srdf-state NAME)",
                    free.len()
                );
            }
        }
        return Ok(exit::NOT_CONVERGED);
    }
    Ok(0)
}

/// The revolute, continuous and prismatic joints that no servo, joint spring, lock or mimic
/// holds, in file order.
fn unheld_joints(model: &restpose::Model) -> Vec<String> {
    use restpose::model::JointKind;
    model
        .joints()
        .iter()
        .enumerate()
        .filter(|(_, j)| {
            !j.merged
                && matches!(
                    j.kind,
                    JointKind::Revolute | JointKind::Continuous | JointKind::Prismatic
                )
        })
        .filter(|(id, _)| {
            !model.servos().iter().any(|s| s.joint.index() == *id)
                && !model.joint_springs().iter().any(|s| s.joint.index() == *id)
                && !model.locks().iter().any(|l| l.joint.index() == *id)
                && !model.mimics().iter().any(|m| m.joint.index() == *id)
        })
        .map(|(_, j)| j.name.clone())
        .collect()
}

/// A joint named by `--lock` or `--initial` that the model lacks: the error names the option.
fn with_option(a: &AnalyzeArgs, e: restpose::Error) -> anyhow::Error {
    let restpose::Error::UnknownJoint { name, .. } = &e else {
        return a.input.explain(e);
    };
    let given =
        (a.lock.iter().map(|s| ("lock", s))).chain(a.initial.iter().map(|s| ("initial", s)));
    for (option, s) in given {
        if coord(s, option).is_ok_and(|(n, _, _)| &n == name) {
            return anyhow::Error::from(e).context(format!("--{option} {s}"));
        }
    }
    e.into()
}

#[cfg(feature = "viewer")]
fn write_rrd(
    path: &std::path::Path,
    model: &restpose::Model,
    state: &restpose::State,
    report: &restpose::Report,
) -> anyhow::Result<()> {
    // The softest mode as an oscillation about the rest pose (48 frames, 0.15 amplitude).
    let mode_frames = report
        .stability
        .as_ref()
        .and_then(|s| s.modes.first())
        .map(|mode| restpose::solver::mode_animation(model, state, mode, 48, 0.15))
        .unwrap_or_default();
    restpose::view::write_recording(path, model, state, report, &mode_frames)?;
    Ok(())
}

#[cfg(not(feature = "viewer"))]
fn write_rrd(
    path: &std::path::Path,
    _: &restpose::Model,
    _: &restpose::State,
    _: &restpose::Report,
) -> anyhow::Result<()> {
    anyhow::bail!(
        "{}: this restpose was built without the `viewer` feature; rebuild with `cargo build --release --features viewer`",
        path.display()
    )
}
