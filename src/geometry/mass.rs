//! Mass properties from geometry (`--inertia-from-geometry ρ`): each shape's mass `ρ V`,
//! centre of mass and inertia (parry3d), moved to the link frame and summed with the
//! parallel-axis theorem.

use super::{load_mesh, Geometry, GeometryError, ShapeKind};
use nalgebra::{Isometry3, Matrix3, Vector3};
use parry3d_f64::mass_properties::MassProperties;
use parry3d_f64::math::{Pose, Rotation, Vector};
use parry3d_f64::shape::{Ball, Capsule, Cuboid, Cylinder, Shape, TriMesh};

fn pose(iso: &Isometry3<f64>) -> Pose {
    let t = iso.translation.vector;
    let r = iso.rotation;
    Pose::from_parts(
        Vector::new(t.x, t.y, t.z),
        Rotation::from_xyzw(r.i, r.j, r.k, r.w),
    )
}

fn shape_mass(shape: &ShapeKind, density: f64) -> Result<MassProperties, GeometryError> {
    Ok(match shape {
        ShapeKind::Box { size } => {
            Cuboid::new(Vector::new(size.x / 2.0, size.y / 2.0, size.z / 2.0))
                .mass_properties(density)
        }
        // parry's cylinders and capsules are along y: turn them onto z.
        ShapeKind::Cylinder { radius, length } => Cylinder::new(length / 2.0, *radius)
            .mass_properties(density)
            .transform_by(&pose(&Isometry3::rotation(
                Vector3::x() * std::f64::consts::FRAC_PI_2,
            ))),
        ShapeKind::Capsule { radius, length } => {
            Capsule::new_z(length / 2.0, *radius).mass_properties(density)
        }
        ShapeKind::Sphere { radius } => Ball::new(*radius).mass_properties(density),
        ShapeKind::Mesh {
            path: Some(path),
            scale,
            ..
        } => {
            let (v, f) = load_mesh(path, scale)?;
            let v = v
                .into_iter()
                .map(|p| Vector::new(p[0], p[1], p[2]))
                .collect();
            TriMesh::new(v, f)
                .map_err(|e| GeometryError::BadMesh {
                    path: path.to_path_buf(),
                    reason: format!("{e:?}"),
                })?
                .mass_properties(density)
        }
        ShapeKind::Mesh {
            uri, path: None, ..
        } => return Err(GeometryError::MeshNotFound { uri: uri.clone() }),
    })
}

/// Mass \[kg\], centre of mass and inertia about it (link frame) of `geometry` at `density`
/// \[kg/m³\].
///
/// # Errors
/// A message if a mesh cannot be read or the result is not a positive mass.
pub fn mass_properties(
    geometry: &[Geometry],
    density: f64,
) -> Result<(f64, Vector3<f64>, Matrix3<f64>), GeometryError> {
    let mut total: Option<MassProperties> = None;
    for g in geometry {
        let mp = shape_mass(&g.shape, density)?.transform_by(&pose(&g.link_from_shape));
        total = Some(match total {
            Some(t) => t + mp,
            None => mp,
        });
    }
    let mp = total.ok_or(GeometryError::NoGeometry)?;
    let mass = mp.mass();
    if !(mass.is_finite() && mass > 0.0) {
        return Err(GeometryError::NotPositiveMass { mass });
    }
    let c = mp.local_com;
    let i = mp.reconstruct_inertia_matrix();
    let cols = i.to_cols_array();
    Ok((
        mass,
        Vector3::new(c.x, c.y, c.z),
        Matrix3::from_column_slice(&cols),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Closed forms: a box m (b² + c²)/12, a cylinder along z m r²/2 about z.
    #[test]
    fn primitive_mass_properties() {
        let g = |shape, x: f64| Geometry {
            link_from_shape: Isometry3::translation(x, 0.0, 0.0),
            shape,
        };
        let (m, c, i) = mass_properties(
            &[g(
                ShapeKind::Box {
                    size: Vector3::new(1.0, 2.0, 3.0),
                },
                0.5,
            )],
            10.0,
        )
        .unwrap();
        assert!((m - 60.0).abs() < 1e-9);
        assert!((c - Vector3::new(0.5, 0.0, 0.0)).norm() < 1e-12);
        assert!((i[(0, 0)] - 60.0 * (4.0 + 9.0) / 12.0).abs() < 1e-9);
        let (m, _, i) = mass_properties(
            &[g(
                ShapeKind::Cylinder {
                    radius: 0.5,
                    length: 2.0,
                },
                0.0,
            )],
            1.0,
        )
        .unwrap();
        assert!((m - std::f64::consts::PI * 0.25 * 2.0).abs() < 1e-9);
        assert!(
            (i[(2, 2)] - m * 0.25 / 2.0).abs() < 1e-9,
            "about the cylinder axis z"
        );
        assert!((i[(0, 0)] - m * (3.0 * 0.25 + 4.0) / 12.0).abs() < 1e-9);
    }
}
