//! Writing the recording.

use crate::error::{Error, Result};
use crate::geometry::{Geometry, ShapeKind};
use crate::model::Model;
use crate::solver::Report;
use crate::state::State;
use nalgebra::{Isometry3, Point3, Vector3};
use std::collections::HashMap;
use std::path::Path;

fn rr_err(path: &Path, e: impl std::fmt::Display) -> Error {
    Error::Io {
        path: path.display().to_string(),
        cause: std::io::Error::other(e.to_string()),
    }
}

fn f3(v: &Vector3<f64>) -> [f32; 3] {
    [v.x as f32, v.y as f32, v.z as f32]
}

fn transform(iso: &Isometry3<f64>) -> rerun::Transform3D {
    let q = iso.rotation;
    rerun::Transform3D::from_translation_rotation(
        f3(&iso.translation.vector),
        rerun::Quaternion::from_xyzw([q.i as f32, q.j as f32, q.k as f32, q.w as f32]),
    )
}

fn sanitize(name: &str) -> String {
    name.chars()
        .map(|c| {
            if c.is_alphanumeric() || c == '_' || c == '-' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// Entity path of every link, nested along the spanning tree (merged fixed joints included).
fn link_paths(model: &Model) -> (HashMap<String, String>, HashMap<String, String>) {
    let mut parent: HashMap<String, String> = HashMap::new();
    for j in model.joints.iter().filter(|j| j.tree) {
        parent.insert(j.child_link.clone(), j.parent_link.clone());
    }
    let mut paths = HashMap::new();
    for l in &model.links {
        let mut chain = vec![sanitize(&l.name)];
        let mut cur = l.name.clone();
        while let Some(p) = parent.get(&cur) {
            if chain.len() > model.links.len() {
                break;
            }
            chain.push(sanitize(p));
            cur = p.clone();
        }
        chain.reverse();
        paths.insert(l.name.clone(), format!("world/robot/{}", chain.join("/")));
    }
    (paths, parent)
}

fn log_shape(
    rec: &rerun::RecordingStream,
    path: &str,
    g: &Geometry,
) -> std::result::Result<(), rerun::RecordingStreamError> {
    let grey = rerun::Color::from_rgb(170, 170, 180);
    rec.log_static(path, &transform(&g.link_from_shape))?;
    match &g.shape {
        ShapeKind::Box { size } => rec.log_static(
            path,
            &rerun::Boxes3D::from_sizes([f3(size)])
                .with_colors([grey])
                .with_fill_mode(rerun::FillMode::Solid),
        ),
        ShapeKind::Cylinder { radius, length } => rec.log_static(
            path,
            &rerun::Cylinders3D::from_lengths_and_radii([*length as f32], [*radius as f32])
                .with_colors([grey])
                .with_fill_mode(rerun::FillMode::Solid),
        ),
        ShapeKind::Sphere { radius } => rec.log_static(
            path,
            &rerun::Ellipsoids3D::from_radii([*radius as f32])
                .with_colors([grey])
                .with_fill_mode(rerun::FillMode::Solid),
        ),
        ShapeKind::Capsule { radius, length } => rec.log_static(
            path,
            &rerun::Capsules3D::from_lengths_and_radii([*length as f32], [*radius as f32])
                .with_translations([[0.0, 0.0, -(*length as f32) / 2.0]])
                .with_colors([grey]),
        ),
        ShapeKind::Mesh {
            path: Some(file),
            scale,
            ..
        } => match crate::geometry::load_mesh(file, scale) {
            Ok((v, f)) => {
                let v: Vec<[f32; 3]> = v
                    .iter()
                    .map(|p| [p[0] as f32, p[1] as f32, p[2] as f32])
                    .collect();
                rec.log_static(
                    path,
                    &rerun::Mesh3D::new(v)
                        .with_triangle_indices(f)
                        .with_albedo_factor(rerun::Rgba32::from_rgb(170, 170, 180)),
                )
            }
            Err(_) => Ok(()),
        },
        ShapeKind::Mesh { path: None, .. } => Ok(()),
    }
}

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
/// timeline) and the rest pose `state` to `path`.
///
/// # Errors
/// [`Error::Io`] if the file cannot be written.
pub fn write_recording(path: &Path, model: &Model, state: &State, report: &Report) -> Result<()> {
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
                    .with_colors([rerun::Color::from_rgb(60, 200, 90)]),
            )?;
        }
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
        // The softest mode as an oscillation about the rest pose.
        if let Some(mode) = report.stability.as_ref().and_then(|s| s.modes.first()) {
            let rest: HashMap<String, Vec<f64>> = state.joint_values(model).into_iter().collect();
            for k in 0..48 {
                let a = 0.15 * (k as f64 / 48.0 * std::f64::consts::TAU).sin();
                let mut values = rest.clone();
                for (name, d) in mode {
                    if let Some(v) = values.get_mut(name) {
                        for (x, dx) in v.iter_mut().zip(d) {
                            *x += a * dx;
                        }
                    }
                }
                let Ok((s, _)) = crate::verify::pose_state(model, &values) else {
                    break;
                };
                let s = crate::verify::assemble(model, &s).unwrap_or(s);
                rec.set_time_sequence("mode", k as i64);
                log_pose(&rec, model, &s, &paths, &parent)?;
            }
        }
        Ok(())
    };
    go().map_err(|e| rr_err(path, e))?;
    rec.flush_blocking().map_err(|e| rr_err(path, e))?;
    Ok(())
}
