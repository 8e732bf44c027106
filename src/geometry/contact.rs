//! The contact points of a collision shape: the points (with radii) a convex shape can rest on.

use super::{convex_hull, Geometry, GeometryError, ShapeKind};
use nalgebra::Vector3;

/// Points of a cylinder's rim (each end) used as contact points: the rim is replaced by a
/// regular polygon of this many vertices, so a cylinder lying on its side rests at most
/// `r (1 − cos(π/32)) ≈ 0.0048 r` low.
pub const CYLINDER_RIM_POINTS: usize = 32;

/// The contact points of a shape, in the link frame, with their radii: a sphere's centre (its
/// radius), a capsule's two end centres (its radius), a box's 8 vertices, a cylinder's rims
/// ([`CYLINDER_RIM_POINTS`] each), the vertices of a mesh's convex hull (parry3d). A convex
/// shape rests on a plane exactly when one of these points (minus its radius) touches it.
///
/// # Errors
/// A message naming the mesh if it cannot be read or has no hull.
pub fn contact_points(g: &Geometry) -> Result<Vec<(Vector3<f64>, f64)>, GeometryError> {
    let local: Vec<(Vector3<f64>, f64)> = match &g.shape {
        ShapeKind::Sphere { radius } => vec![(Vector3::zeros(), *radius)],
        ShapeKind::Capsule { radius, length } => vec![
            (Vector3::new(0.0, 0.0, -length / 2.0), *radius),
            (Vector3::new(0.0, 0.0, length / 2.0), *radius),
        ],
        ShapeKind::Box { size } => {
            let h = size / 2.0;
            (0..8)
                .map(|k| {
                    let s = |bit: usize| if k & bit == 0 { -1.0 } else { 1.0 };
                    (Vector3::new(s(1) * h.x, s(2) * h.y, s(4) * h.z), 0.0)
                })
                .collect()
        }
        ShapeKind::Cylinder { radius, length } => {
            let n = CYLINDER_RIM_POINTS;
            (0..2 * n)
                .map(|k| {
                    let a = std::f64::consts::TAU * (k % n) as f64 / n as f64;
                    let z = if k < n { -length / 2.0 } else { length / 2.0 };
                    (Vector3::new(radius * a.cos(), radius * a.sin(), z), 0.0)
                })
                .collect()
        }
        ShapeKind::Mesh {
            path: Some(path),
            scale,
            ..
        } => {
            let (hull, _) = convex_hull(path, scale)?;
            hull.into_iter().map(|p| (p, 0.0)).collect()
        }
        ShapeKind::Mesh {
            uri, path: None, ..
        } => return Err(GeometryError::MeshNotFound { uri: uri.clone() }),
    };
    Ok(local
        .into_iter()
        .map(|(p, r)| ((g.link_from_shape * nalgebra::Point3::from(p)).coords, r))
        .collect())
}
