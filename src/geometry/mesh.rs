//! Mesh files (STL, OBJ, COLLADA by `mesh-loader`) to triangles, and convex hulls (parry3d).

use super::GeometryError;
use nalgebra::Vector3;
use parry3d_f64::math::Vector;
use std::path::Path;

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
pub fn load_mesh(path: &Path, scale: &Vector3<f64>) -> Result<Triangles, GeometryError> {
    let meta = std::fs::metadata(path).map_err(|e| GeometryError::read(path, &e))?;
    if !meta.is_file() {
        return Err(GeometryError::NotAFile {
            path: path.to_path_buf(),
        });
    }
    if meta.len() > MAX_MESH_BYTES {
        return Err(GeometryError::TooLarge {
            path: path.to_path_buf(),
            bytes: meta.len(),
        });
    }
    let scene = mesh_loader::Loader::default()
        .load(path)
        .map_err(|e| GeometryError::read(path, &e))?;
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
        return Err(GeometryError::NoTriangles {
            path: path.to_path_buf(),
        });
    }
    Ok((vertices, faces))
}

/// The convex hull (parry3d) of a mesh file's vertices, scaled: its vertices and its
/// triangles (index triples, counter-clockwise seen from outside).
///
/// # Errors
/// A message naming the mesh if it cannot be read or its vertices span no volume.
pub fn convex_hull(path: &Path, scale: &Vector3<f64>) -> Result<Triangles3, GeometryError> {
    let (v, _) = load_mesh(path, scale)?;
    let pts: Vec<Vector3<f64>> = v.iter().map(|p| Vector3::new(p[0], p[1], p[2])).collect();
    convex_hull_of(&pts).map_err(|e| match e {
        GeometryError::NoHull { reason, .. } => GeometryError::NoHull {
            path: Some(path.to_path_buf()),
            reason,
        },
        other => other,
    })
}

/// The convex hull (parry3d) of `points`: its vertices and triangles.
///
/// # Errors
/// A message if parry finds no hull.
pub fn convex_hull_of(points: &[Vector3<f64>]) -> Result<Triangles3, GeometryError> {
    let pts: Vec<Vector> = points.iter().map(|p| Vector::new(p.x, p.y, p.z)).collect();
    let (hull, faces) =
        parry3d_f64::transformation::try_convex_hull(&pts).map_err(|e| GeometryError::NoHull {
            path: None,
            reason: format!("{e:?}"),
        })?;
    Ok((
        hull.iter().map(|p| Vector3::new(p.x, p.y, p.z)).collect(),
        faces,
    ))
}

/// Vertices and index triples of a convex hull.
pub type Triangles3 = (Vec<Vector3<f64>>, Vec<[u32; 3]>);
