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

/// Whether `bytes` is a binary STL: an 80-byte header, a triangle count `n` (little-endian
/// `u32`) and exactly `50 n` bytes of triangles. An ASCII file cannot match by accident (its
/// bytes 80–83 are text, a count of at least 0x20202020).
fn is_binary_stl(bytes: &[u8]) -> bool {
    let Some(count) = bytes.get(80..84) else {
        return false;
    };
    let n = u32::from_le_bytes([count[0], count[1], count[2], count[3]]) as u64;
    84 + 50 * n == bytes.len() as u64
}

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
    let bytes = std::fs::read(path).map_err(|e| GeometryError::read(path, &e))?;
    let is_stl = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("stl"));
    let loader = mesh_loader::Loader::default();
    let scene = if is_stl && is_binary_stl(&bytes) {
        // A binary STL whose 80-byte header starts with "solid" is read as ASCII by
        // `mesh-loader` and refused: the header carries no geometry, so it is blanked.
        let mut bytes = bytes;
        bytes[..80].fill(0);
        loader.load_stl_from_slice(&bytes, path)
    } else {
        loader.load_from_slice(&bytes, path)
    }
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A binary STL of one triangle whose header starts with "solid" (as example-robot-data's
    /// `solo_foot.stl`): read as binary, not refused as malformed ASCII.
    #[test]
    fn a_binary_stl_whose_header_says_solid_is_read_as_binary() {
        let mut bytes = vec![0u8; 84];
        bytes[..11].copy_from_slice(b"solid part ");
        bytes[80..84].copy_from_slice(&1u32.to_le_bytes());
        for v in [
            [0.0f32, 0.0, 1.0],
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 2.0, 0.0],
        ] {
            for x in v {
                bytes.extend_from_slice(&x.to_le_bytes());
            }
        }
        bytes.extend_from_slice(&[0, 0]);
        assert!(is_binary_stl(&bytes));
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("foot.stl");
        std::fs::write(&path, &bytes).unwrap();
        let (vertices, faces) = load_mesh(&path, &Vector3::new(1.0, 1.0, 1.0)).unwrap();
        assert_eq!(faces.len(), 1);
        assert!(vertices.contains(&[0.0, 2.0, 0.0]), "{vertices:?}");
        // An ASCII STL is still read as ASCII.
        let ascii = "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 3 0\nendloop\nendfacet\nendsolid t\n";
        assert!(!is_binary_stl(ascii.as_bytes()));
        std::fs::write(&path, ascii).unwrap();
        let (vertices, _) = load_mesh(&path, &Vector3::new(1.0, 1.0, 1.0)).unwrap();
        assert!(vertices.contains(&[0.0, 3.0, 0.0]), "{vertices:?}");
    }
}
