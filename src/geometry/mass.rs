//! Mass properties from geometry (`--inertia-from-geometry ρ`): each shape's mass `ρ V`,
//! centre of mass and inertia (parry3d), moved to the link frame and summed with the
//! parallel-axis theorem,
//!
//! ```text
//! m = Σ mᵢ,   c = Σ mᵢ cᵢ / m,   I = Σ Rᵢ Iᵢ Rᵢᵀ + mᵢ (|cᵢ − c|² 1 − (cᵢ − c)(cᵢ − c)ᵀ)
//! ```
//!
//! A mesh that is not closed encloses no defined volume: the meshes whose volume is uncertain
//! by more than [`super::closure::OPEN_MESH_TOLERANCE`] are listed with the result
//! ([`GeometryMass::open_meshes`]) for the import to warn.

use super::closure::{volume_uncertainty, OPEN_MESH_TOLERANCE};
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

/// A shape's mass properties, and for a mesh the relative uncertainty of its volume
/// ([`volume_uncertainty`]).
fn shape_mass(
    shape: &ShapeKind,
    density: f64,
) -> Result<(MassProperties, Option<f64>), GeometryError> {
    let mut uncertainty = None;
    let mass = match shape {
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
            uncertainty = Some(volume_uncertainty(&v, &f));
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
    };
    Ok((mass, uncertainty))
}

/// The mass properties of a link's geometry.
#[derive(Clone, Debug, PartialEq)]
pub struct GeometryMass {
    /// Mass \[kg\].
    pub mass: f64,
    /// Centre of mass in the link frame \[m\].
    pub com: Vector3<f64>,
    /// Inertia about the centre of mass, link axes \[kg m²\].
    pub inertia: Matrix3<f64>,
    /// Meshes that are not closed: their URI as written and the relative uncertainty of the
    /// volume they enclose (above [`OPEN_MESH_TOLERANCE`]; module `closure`).
    pub open_meshes: Vec<(String, f64)>,
}

/// Mass \[kg\], centre of mass and inertia about it (link frame) of `geometry` at `density`
/// \[kg/m³\], and the meshes among it that are not closed.
///
/// # Errors
/// A message if a mesh cannot be read or the result is not a positive mass.
pub fn mass_properties(geometry: &[Geometry], density: f64) -> Result<GeometryMass, GeometryError> {
    let mut total: Option<MassProperties> = None;
    let mut open_meshes = Vec::new();
    for g in geometry {
        let (mp, uncertainty) = shape_mass(&g.shape, density)?;
        if let (Some(u), ShapeKind::Mesh { uri, .. }) = (uncertainty, &g.shape) {
            if u > OPEN_MESH_TOLERANCE || u.is_nan() {
                open_meshes.push((uri.clone(), u));
            }
        }
        let mp = mp.transform_by(&pose(&g.link_from_shape));
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
    Ok(GeometryMass {
        mass,
        com: Vector3::new(c.x, c.y, c.z),
        inertia: Matrix3::from_column_slice(&cols),
        open_meshes,
    })
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
        let GeometryMass {
            mass: m,
            com: c,
            inertia: i,
            ..
        } = mass_properties(
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
        let GeometryMass {
            mass: m,
            inertia: i,
            ..
        } = mass_properties(
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
