//! Link geometry (URDF `<visual>` / `<collision>`), mesh files, and mass properties computed
//! from geometry with parry3d. This is the one place that converts parry (glam) types.
//!
//! Mesh URIs are resolved in this order: `package://PKG/…` and `model://PKG/…` through a
//! `--package PKG=DIR` option, then `ROS_PACKAGE_PATH` (`DIR/PKG`) and `AMENT_PREFIX_PATH`
//! (`DIR/share/PKG`), then by walking up from the URDF's folder for a folder named `PKG`;
//! `file://` and plain paths are taken as they are (relative to the URDF's folder). STL, OBJ
//! and COLLADA meshes are read with `mesh-loader`.
//!
//! Mass properties for `--inertia-from-geometry ρ`: each shape's mass `ρ V`, centre of mass
//! and inertia (parry3d), moved to the link frame and summed with the parallel-axis theorem.

use nalgebra::{Isometry3, Matrix3, Vector3};
use parry3d_f64::mass_properties::MassProperties;
use parry3d_f64::math::{Pose, Rotation, Vector};
use parry3d_f64::shape::{Ball, Capsule, Cuboid, Cylinder, Shape, TriMesh};
use std::path::{Path, PathBuf};

/// A geometric shape of a link.
#[derive(Clone, Debug, PartialEq)]
pub enum ShapeKind {
    /// Box with full edge lengths \[m\].
    Box {
        /// Edge lengths along x, y, z.
        size: Vector3<f64>,
    },
    /// Cylinder along z.
    Cylinder {
        /// Radius \[m\].
        radius: f64,
        /// Length \[m\].
        length: f64,
    },
    /// Sphere.
    Sphere {
        /// Radius \[m\].
        radius: f64,
    },
    /// Capsule along z (cylinder of `length` with hemispherical caps).
    Capsule {
        /// Radius \[m\].
        radius: f64,
        /// Length of the cylindrical part \[m\].
        length: f64,
    },
    /// Triangle mesh file.
    Mesh {
        /// The URI as written.
        uri: String,
        /// The file it resolved to (`None`: not found; the import warned).
        path: Option<PathBuf>,
        /// Scale factors.
        scale: Vector3<f64>,
    },
}

/// A shape placed in its link frame.
#[derive(Clone, Debug, PartialEq)]
pub struct Geometry {
    /// Shape frame in the link frame.
    pub link_from_shape: Isometry3<f64>,
    /// The shape.
    pub shape: ShapeKind,
}

/// The end of the message for a `package://` mesh that is not found: a front end that takes
/// package directories in another form (a command-line option) may replace it.
pub const UNKNOWN_PACKAGE_HINT: &str = "give the package's directory in the import options";

/// Where to look for `package://` and `model://` folders.
#[derive(Clone, Debug, Default)]
pub struct PackagePaths {
    /// Package directories given by the user: `(NAME, DIR)`.
    pub explicit: Vec<(String, PathBuf)>,
    /// The URDF's folder (`None` for text without a file).
    pub urdf_dir: Option<PathBuf>,
}

impl PackagePaths {
    /// Resolves a mesh URI to an existing file, or says where it looked.
    pub fn resolve(&self, uri: &str) -> Result<PathBuf, String> {
        let base = self.urdf_dir.clone().unwrap_or_else(|| PathBuf::from("."));
        let found = |p: PathBuf| {
            if p.is_file() {
                Ok(p)
            } else {
                Err(format!("`{}` does not exist", p.display()))
            }
        };
        if let Some(rest) = uri.strip_prefix("file://") {
            let p = PathBuf::from(rest);
            return found(if p.is_absolute() { p } else { base.join(p) });
        }
        let Some(rest) = uri
            .strip_prefix("package://")
            .or_else(|| uri.strip_prefix("model://"))
        else {
            let p = PathBuf::from(uri);
            return found(if p.is_absolute() { p } else { base.join(p) });
        };
        let (pkg, rel) = rest.split_once('/').unwrap_or((rest, ""));
        let mut tried = Vec::new();
        let mut candidates: Vec<PathBuf> = self
            .explicit
            .iter()
            .filter(|(n, _)| n == pkg)
            .map(|(_, d)| d.clone())
            .collect();
        for var in ["ROS_PACKAGE_PATH", "AMENT_PREFIX_PATH"] {
            if let Ok(v) = std::env::var(var) {
                for d in std::env::split_paths(&v) {
                    candidates.push(if var == "AMENT_PREFIX_PATH" {
                        d.join("share").join(pkg)
                    } else {
                        d.join(pkg)
                    });
                }
            }
        }
        let mut up: Option<&Path> = Some(base.as_path());
        while let Some(dir) = up {
            if dir.file_name().is_some_and(|n| n == pkg) {
                candidates.push(dir.to_path_buf());
            }
            candidates.push(dir.join(pkg));
            up = dir.parent();
        }
        for c in candidates {
            let p = c.join(rel);
            if p.is_file() {
                return Ok(p);
            }
            tried.push(c.display().to_string());
        }
        tried.truncate(4);
        Err(format!(
            "package `{pkg}` has no `{rel}` (looked in {}, …; {UNKNOWN_PACKAGE_HINT})",
            tried.join(", ")
        ))
    }
}

/// A triangle mesh: vertices \[m\] and index triples.
pub type Triangles = (Vec<[f64; 3]>, Vec<[u32; 3]>);

/// Largest mesh file read \[bytes\] (256 MiB): a binary STL of 5 million triangles. The
/// reader holds the whole file, so the cap bounds the memory a mesh can take.
pub const MAX_MESH_BYTES: u64 = 256 << 20;

/// Triangles of a mesh file, scaled.
///
/// # Errors
/// A message naming the file if it cannot be read, is larger than [`MAX_MESH_BYTES`] or
/// holds no triangles.
pub fn load_mesh(path: &Path, scale: &Vector3<f64>) -> Result<Triangles, String> {
    let meta = std::fs::metadata(path).map_err(|e| format!("{}: {e}", path.display()))?;
    if !meta.is_file() {
        return Err(format!("{}: not a regular file", path.display()));
    }
    if meta.len() > MAX_MESH_BYTES {
        return Err(format!(
            "{}: the mesh has {} bytes, more than the {MAX_MESH_BYTES} bytes (256 MiB) restpose reads",
            path.display(),
            meta.len()
        ));
    }
    let scene = mesh_loader::Loader::default()
        .load(path)
        .map_err(|e| format!("{}: {e}", path.display()))?;
    let mut vertices = Vec::new();
    let mut faces = Vec::new();
    for m in &scene.meshes {
        let offset = vertices.len() as u32;
        vertices.extend(m.vertices.iter().map(|v| {
            [
                v[0] as f64 * scale.x,
                v[1] as f64 * scale.y,
                v[2] as f64 * scale.z,
            ]
        }));
        faces.extend(
            m.faces
                .iter()
                .map(|f| [f[0] + offset, f[1] + offset, f[2] + offset]),
        );
    }
    if faces.is_empty() {
        return Err(format!("{}: no triangles", path.display()));
    }
    Ok((vertices, faces))
}

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
pub fn contact_points(g: &Geometry) -> Result<Vec<(Vector3<f64>, f64)>, String> {
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
        } => return Err(format!("mesh `{uri}` was not found")),
    };
    Ok(local
        .into_iter()
        .map(|(p, r)| ((g.link_from_shape * nalgebra::Point3::from(p)).coords, r))
        .collect())
}

/// The convex hull (parry3d) of a mesh file's vertices, scaled: its vertices and its
/// triangles (index triples, counter-clockwise seen from outside).
///
/// # Errors
/// A message naming the mesh if it cannot be read or its vertices span no volume.
pub fn convex_hull(path: &Path, scale: &Vector3<f64>) -> Result<Triangles3, String> {
    let (v, _) = load_mesh(path, scale)?;
    let pts: Vec<Vector3<f64>> = v.iter().map(|p| Vector3::new(p[0], p[1], p[2])).collect();
    convex_hull_of(&pts).map_err(|e| format!("{}: {e}", path.display()))
}

/// The convex hull (parry3d) of `points`: its vertices and triangles.
///
/// # Errors
/// A message if parry finds no hull.
pub fn convex_hull_of(points: &[Vector3<f64>]) -> Result<Triangles3, String> {
    let pts: Vec<Vector> = points.iter().map(|p| Vector::new(p.x, p.y, p.z)).collect();
    let (hull, faces) = parry3d_f64::transformation::try_convex_hull(&pts)
        .map_err(|e| format!("no convex hull ({e:?})"))?;
    Ok((
        hull.iter().map(|p| Vector3::new(p.x, p.y, p.z)).collect(),
        faces,
    ))
}

/// Vertices and index triples of a convex hull.
pub type Triangles3 = (Vec<Vector3<f64>>, Vec<[u32; 3]>);

/// parry3d's projection of `p` on the convex hull of `points` (as a solid, GJK/EPA): the
/// signed distance (negative inside). An independent check of the obstacles' closest points.
pub fn parry_signed_distance(points: &[Vector3<f64>], p: &Vector3<f64>) -> Option<f64> {
    use parry3d_f64::query::PointQuery;
    let pts: Vec<Vector> = points.iter().map(|q| Vector::new(q.x, q.y, q.z)).collect();
    let poly = parry3d_f64::shape::ConvexPolyhedron::from_convex_hull(&pts)?;
    let x = Vector::new(p.x, p.y, p.z);
    let proj = poly.project_local_point(x, false);
    let d = (x - proj.point).length();
    Some(if proj.is_inside { -d } else { d })
}

/// parry3d's signed distance from `p` to a cylinder of `radius` and `length` along z.
pub fn parry_cylinder_signed_distance(radius: f64, length: f64, p: &Vector3<f64>) -> f64 {
    use parry3d_f64::query::PointQuery;
    // parry's cylinders are along y: turn the point by −90° about x (z onto y).
    let c = Cylinder::new(length / 2.0, radius);
    let x = Vector::new(p.x, p.z, -p.y);
    let proj = c.project_local_point(x, false);
    let d = (x - proj.point).length();
    if proj.is_inside {
        -d
    } else {
        d
    }
}

fn pose(iso: &Isometry3<f64>) -> Pose {
    let t = iso.translation.vector;
    let r = iso.rotation;
    Pose::from_parts(
        Vector::new(t.x, t.y, t.z),
        Rotation::from_xyzw(r.i, r.j, r.k, r.w),
    )
}

fn shape_mass(shape: &ShapeKind, density: f64) -> Result<MassProperties, String> {
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
                .map_err(|e| format!("{}: {e:?}", path.display()))?
                .mass_properties(density)
        }
        ShapeKind::Mesh {
            uri, path: None, ..
        } => return Err(format!("mesh `{uri}` was not found")),
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
) -> Result<(f64, Vector3<f64>, Matrix3<f64>), String> {
    let mut total: Option<MassProperties> = None;
    for g in geometry {
        let mp = shape_mass(&g.shape, density)?.transform_by(&pose(&g.link_from_shape));
        total = Some(match total {
            Some(t) => t + mp,
            None => mp,
        });
    }
    let mp = total.ok_or("no geometry")?;
    let mass = mp.mass();
    if !(mass.is_finite() && mass > 0.0) {
        return Err(format!(
            "geometry gives a mass of {mass} kg (is the mesh closed and outward-facing?)"
        ));
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
