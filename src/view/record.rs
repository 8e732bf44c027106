//! Writing the recording.

use super::contact::{log_balance, log_contacts, log_grounds, log_stops, stop_color};
use super::shapes::{f3, link_paths, log_shape, rr_err, sanitize, transform};
use crate::error::Result;
use crate::model::Model;
use crate::solver::Report;
use crate::state::State;
use nalgebra::{Isometry3, Point3, Vector3};
use std::collections::HashMap;
use std::path::Path;

fn world_pose(model: &Model, state: &State, link: &str) -> Isometry3<f64> {
    state
        .link_pose(model, link)
        .unwrap_or_else(Isometry3::identity)
}

/// Logs the links, springs, loads and centres of mass at `state`.
fn log_pose(
    rec: &rerun::RecordingStream,
    model: &Model,
    state: &State,
    paths: &HashMap<String, String>,
    parent: &HashMap<String, String>,
) -> std::result::Result<(), rerun::RecordingStreamError> {
    for l in &model.links {
        let world = world_pose(model, state, &l.name);
        let rel = match parent.get(&l.name) {
            Some(p) => world_pose(model, state, p).inverse() * world,
            None => world,
        };
        rec.log(paths[&l.name].as_str(), &transform(&rel))?;
    }
    for (i, b) in model.bodies.iter().enumerate() {
        let c = state.body_pose(crate::model::BodyId(i)) * Point3::from(b.com);
        rec.log(
            format!("world/com/{}", sanitize(&b.name)),
            &rerun::Points3D::new([f3(&c.coords)]).with_radii([0.01 * model.length_scale as f32]),
        )?;
    }
    for s in &model.springs {
        let end = |k: usize| {
            let e = &s.ends[k];
            match e.body {
                Some(b) => (state.body_pose(b) * Point3::from(e.point)).coords,
                None => e.point,
            }
        };
        let (a, b) = (end(0), end(1));
        let delta = (b - a).norm() - s.free_length;
        let force = crate::forces::law::evaluate(&s.law, s.mode, delta).map_or(0.0, |x| x.1);
        let color = if force > 0.0 {
            rerun::Color::from_rgb(220, 50, 50)
        } else if force < 0.0 {
            rerun::Color::from_rgb(50, 90, 220)
        } else {
            rerun::Color::from_rgb(150, 150, 150)
        };
        rec.log(
            format!("world/springs/{}", sanitize(&s.name)),
            &rerun::LineStrips3D::new([[f3(&a), f3(&b)]])
                .with_colors([color])
                .with_radii([0.006 * model.length_scale as f32]),
        )?;
    }
    let fmax = model
        .loads
        .iter()
        .map(|l| l.force.norm())
        .fold(0.0, f64::max)
        .max(f64::MIN_POSITIVE);
    for l in &model.loads {
        let p = state.body_pose(l.body) * Point3::from(l.point);
        let v = l.force * (model.length_scale / fmax);
        rec.log(
            format!("world/loads/{}", sanitize(&l.name)),
            &rerun::Arrows3D::from_vectors([f3(&v)])
                .with_origins([f3(&(p.coords - v))])
                .with_colors([rerun::Color::from_rgb(240, 160, 0)]),
        )?;
    }
    Ok(())
}

/// Writes a recording of `report` (with `Options::record_iterates` for the iteration
/// timeline) and the rest pose `state` to `path`; `mode_frames` (e.g. from
/// [`solver::mode_animation`](crate::solver::mode_animation)) are shown on the `mode`
/// timeline.
///
/// # Errors
/// [`Error::Io`](crate::Error::Io) if the file cannot be written.
pub fn write_recording(
    path: &Path,
    model: &Model,
    state: &State,
    report: &Report,
    mode_frames: &[State],
) -> Result<()> {
    let rec = rerun::RecordingStreamBuilder::new("restpose")
        .save(path)
        .map_err(|e| rr_err(path, e))?;
    let (paths, parent) = link_paths(model);
    let l = model.length_scale;
    let go = || -> std::result::Result<(), rerun::RecordingStreamError> {
        rec.log_static("world", &rerun::ViewCoordinates::RIGHT_HAND_Z_UP())?;
        for link in &model.links {
            for (k, g) in link.visuals.iter().enumerate() {
                log_shape(&rec, &format!("{}/visual_{k}", paths[&link.name]), g)?;
            }
        }
        let on_stop = |joint: &str| report.active_limits.iter().any(|a| a.joint == joint);
        for j in model.joints.iter().filter(|j| !j.merged) {
            let Some(link) = model.link(&j.child_link) else {
                continue;
            };
            let link_from_joint = link.body_from_link.inverse() * j.body_from_joint[1];
            let axis = link_from_joint.rotation * Vector3::z() * (0.15 * l);
            rec.log_static(
                format!("{}/joint_{}", paths[&j.child_link], sanitize(&j.name)),
                &rerun::Arrows3D::from_vectors([f3(&axis)])
                    .with_origins([f3(&link_from_joint.translation.vector)])
                    .with_colors([if on_stop(&j.name) {
                        stop_color()
                    } else {
                        rerun::Color::from_rgb(60, 200, 90)
                    }]),
            )?;
        }
        log_grounds(&rec, model, state)?;
        let g = model.gravity;
        if g.norm() > 0.0 {
            rec.log_static(
                "world/gravity",
                &rerun::Arrows3D::from_vectors([f3(&(g / g.norm() * l))])
                    .with_colors([rerun::Color::from_rgb(120, 120, 255)]),
            )?;
        }
        let frames: Vec<State> = if report.iterates.is_empty() {
            vec![state.clone()]
        } else {
            report.iterates.clone()
        };
        for (k, s) in frames.iter().enumerate() {
            rec.set_time_sequence("iteration", k as i64);
            log_pose(&rec, model, s, &paths, &parent)?;
            if let Some(h) = report.history.get(k) {
                rec.log(
                    "plots/potential_energy",
                    &rerun::Scalars::single(h.potential_energy),
                )?;
                rec.log(
                    "plots/gradient_norm",
                    &rerun::Scalars::single(h.gradient_norm),
                )?;
            }
        }
        let last = frames.len().saturating_sub(1) as i64;
        rec.set_time_sequence("iteration", last);
        log_pose(&rec, model, state, &paths, &parent)?;
        let fmax = report
            .reactions
            .iter()
            .map(|(_, r)| Vector3::from(r.force_world).norm())
            .fold(0.0, f64::max)
            .max(f64::MIN_POSITIVE);
        for (name, r) in &report.reactions {
            let Some(j) = model.joint_id(name).map(|id| model.joint(id)) else {
                continue;
            };
            let origin = match j.bodies[1] {
                Some(b) => state.body_pose(b) * j.body_from_joint[1],
                None => j.body_from_joint[1],
            };
            let v = Vector3::from(r.force_world) * (l / fmax);
            rec.log(
                format!("world/reactions/{}", sanitize(name)),
                &rerun::Arrows3D::from_vectors([f3(&v)])
                    .with_origins([f3(&origin.translation.vector)])
                    .with_colors([rerun::Color::from_rgb(200, 40, 200)]),
            )?;
        }
        log_contacts(&rec, model, report)?;
        log_stops(&rec, model, state, report)?;
        log_balance(&rec, model, report)?;
        for (k, s) in mode_frames.iter().enumerate() {
            rec.set_time_sequence("mode", k as i64);
            log_pose(&rec, model, s, &paths, &parent)?;
        }
        Ok(())
    };
    go().map_err(|e| rr_err(path, e))?;
    rec.flush_blocking().map_err(|e| rr_err(path, e))?;
    Ok(())
}
