//! Whether a triangle mesh is closed enough to enclose a volume (`--inertia-from-geometry`).
//!
//! The volume of a mesh is the sum of the signed tetrahedra between each triangle `(a, b, c)`
//! and a reference point `p`, `V(p) = Σ (a − p) · ((b − p) × (c − p)) / 6`. Moving the point by
//! `d` changes it by `V(p + d) − V(p) = −d · S / 3`, where
//!
//! ```text
//! S = Σ (b − a) × (c − a) / 2
//! ```
//!
//! is the mesh's net vector area: zero for a closed surface (every edge shared by two
//! triangles of opposite orientation), whatever the point; the area of the holes otherwise.
//! parry3d sums from the mesh's vertex centroid, one point among those the mesh's bounding box
//! holds, so the volume (and the mass `ρ V`) of a mesh with holes is uncertain by up to
//!
//! ```text
//! u = |S| D / (3 |V|)          D: the bounding box's diagonal
//! ```
//!
//! relative to itself. The import warns above [`OPEN_MESH_TOLERANCE`].

/// The relative volume uncertainty `u` above which a mesh used for mass properties is
/// reported as not closed (0.1 %: far above the rounding of a closed mesh, about 10⁻¹⁵).
pub const OPEN_MESH_TOLERANCE: f64 = 1e-3;

/// `u = |S| D / (3 |V(c)|)` of the mesh (`c` its vertex centroid, as parry3d sums from);
/// infinite when the volume is zero.
#[must_use]
pub fn volume_uncertainty(vertices: &[[f64; 3]], faces: &[[u32; 3]]) -> f64 {
    let n = vertices.len().max(1) as f64;
    let mut c = [0.0; 3];
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for v in vertices {
        for k in 0..3 {
            c[k] += v[k] / n;
            lo[k] = lo[k].min(v[k]);
            hi[k] = hi[k].max(v[k]);
        }
    }
    let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let (mut s, mut six_v) = ([0.0; 3], 0.0);
    for f in faces {
        let [a, b, cc] = f.map(|i| vertices[i as usize]);
        let area2 = cross(sub(b, a), sub(cc, a));
        for k in 0..3 {
            s[k] += area2[k] / 2.0;
        }
        let (pa, pb, pc) = (sub(a, c), sub(b, c), sub(cc, c));
        let x = cross(pb, pc);
        six_v += pa[0] * x[0] + pa[1] * x[1] + pa[2] * x[2];
    }
    let norm = |x: [f64; 3]| (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt();
    let volume = (six_v / 6.0).abs();
    if volume == 0.0 {
        return f64::INFINITY;
    }
    norm(s) * norm(sub(hi, lo)) / (3.0 * volume)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit cube (12 triangles, outward), and the same without its top face.
    fn cube() -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
        let v = vec![
            [-0.5, -0.5, -0.5],
            [0.5, -0.5, -0.5],
            [0.5, 0.5, -0.5],
            [-0.5, 0.5, -0.5],
            [-0.5, -0.5, 0.5],
            [0.5, -0.5, 0.5],
            [0.5, 0.5, 0.5],
            [-0.5, 0.5, 0.5],
        ];
        let f = vec![
            [0, 2, 1],
            [0, 3, 2],
            [4, 5, 6],
            [4, 6, 7],
            [0, 1, 5],
            [0, 5, 4],
            [1, 2, 6],
            [1, 6, 5],
            [2, 3, 7],
            [2, 7, 6],
            [3, 0, 4],
            [3, 4, 7],
        ];
        (v, f)
    }

    #[test]
    fn a_closed_mesh_is_certain_anywhere_and_a_hole_is_measured() {
        let (v, f) = cube();
        assert!(volume_uncertainty(&v, &f) < 1e-15);
        // Moved far from the origin: still closed (the centroid moves with it).
        let far: Vec<[f64; 3]> = v
            .iter()
            .map(|p| [p[0] + 7.0, p[1] - 3.0, p[2] + 11.0])
            .collect();
        assert!(volume_uncertainty(&far, &f) < 1e-14);
        // Without the top face (area 1): S = (0, 0, −1), D = √3; from the centroid of the
        // 8 vertices (the cube's centre) the five faces left enclose 5/6.
        let open: Vec<[u32; 3]> = f
            .iter()
            .copied()
            .filter(|t| *t != [4, 5, 6] && *t != [4, 6, 7])
            .collect();
        assert_eq!(open.len(), 10);
        let u = volume_uncertainty(&v, &open);
        let expected = 3f64.sqrt() / (3.0 * 5.0 / 6.0);
        assert!((u - expected).abs() < 1e-12, "{u} against {expected}");
        assert!(u > OPEN_MESH_TOLERANCE);
    }
}
