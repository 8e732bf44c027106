//! Conversions to rerun types, and the links' visual shapes.

use crate::error::Error;
use crate::geometry::{Geometry, ShapeKind};
use crate::model::Model;
use nalgebra::{Isometry3, Vector3};
use std::collections::HashMap;
use std::path::Path;

pub(super) fn rr_err(path: &Path, e: impl std::fmt::Display) -> Error {
    Error::Io {
        path: path.display().to_string(),
        cause: std::io::Error::other(e.to_string()),
    }
}

pub(super) fn f3(v: &Vector3<f64>) -> [f32; 3] {
    [v.x as f32, v.y as f32, v.z as f32]
}

pub(super) fn transform(iso: &Isometry3<f64>) -> rerun::Transform3D {
    let q = iso.rotation;
    rerun::Transform3D::from_translation_rotation(
        f3(&iso.translation.vector),
        rerun::Quaternion::from_xyzw([q.i as f32, q.j as f32, q.k as f32, q.w as f32]),
    )
}

pub(super) fn sanitize(name: &str) -> String {
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
pub(super) fn link_paths(model: &Model) -> (HashMap<String, String>, HashMap<String, String>) {
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

pub(super) fn log_shape(
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
