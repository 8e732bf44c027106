//! Convex hulls of meshes as obstacles: the closest point of the hull's surface to a point and
//! the outward normal there, from the hull's triangles (computed by parry3d, module
//! `mesh`).
//!
//! The hull is `{y : n_i·y ≤ d_i}` over its face planes. For `p` with
//! `s = max_i (n_i·p − d_i) ≤ 0` (inside or on the surface) the signed distance is `s`, the
//! closest point `p − s n_k` on the face `k` of the maximum (the distance from an inside point
//! to the boundary of a convex polyhedron is that to its nearest face plane). Outside, the
//! closest point is on a face if the projection `p − s_i n_i` on a face plane with `s_i > 0`
//! lies in the hull (then the distance is `s_i`, the normal `n_i`), else on an edge or a
//! vertex: the nearest point over the hull's edges, `n = (p − c)/|p − c|`. Every case is in
//! closed form, so value and normal are exact to rounding.

use nalgebra::Vector3;

/// A convex hull: its face planes and its edges (shape frame).
#[derive(Clone, Debug, PartialEq)]
pub struct Hull {
    /// Face planes `(n, d)`: `n·y ≤ d` inside, `n` the unit outward normal.
    planes: Vec<(Vector3<f64>, f64)>,
    /// Edges (end points), each once.
    edges: Vec<(Vector3<f64>, Vector3<f64>)>,
    /// Tolerance on plane distances \[m\]: 1e-12 of the hull's size.
    tol: f64,
}

impl Hull {
    /// The hull with vertices `points` and triangles `faces` (outward or inward: the normals
    /// are turned away from the centroid). Degenerate (zero-area) triangles are skipped.
    ///
    /// # Errors
    /// A message if the triangles span no volume (less than 1e-9 of the cube of the hull's
    /// size: a flat mesh).
    pub fn new(points: &[Vector3<f64>], faces: &[[u32; 3]]) -> Result<Self, String> {
        let get = |i: u32| points.get(i as usize).copied();
        let n_pts = points.len().max(1) as f64;
        let centroid = points.iter().sum::<Vector3<f64>>() / n_pts;
        let size = points
            .iter()
            .map(|p| (p - centroid).norm())
            .fold(0.0, f64::max);
        let mut planes = Vec::new();
        let mut edges: Vec<(Vector3<f64>, Vector3<f64>)> = Vec::new();
        let mut seen = std::collections::HashSet::new();
        let mut volume = 0.0;
        for f in faces {
            let (Some(a), Some(b), Some(c)) = (get(f[0]), get(f[1]), get(f[2])) else {
                return Err(format!("hull triangle {f:?} names a missing vertex"));
            };
            let cross = (b - a).cross(&(c - a));
            if cross.norm() <= 1e-12 * size * size {
                continue;
            }
            let mut n = cross.normalize();
            if n.dot(&(a - centroid)) < 0.0 {
                n = -n;
            }
            planes.push((n, n.dot(&a)));
            // The pyramid over the triangle from the centroid.
            volume += cross.norm() / 6.0 * n.dot(&(a - centroid));
            for (i, j) in [(f[0], f[1]), (f[1], f[2]), (f[2], f[0])] {
                if seen.insert((i.min(j), i.max(j))) {
                    edges.push((points[i as usize], points[j as usize]));
                }
            }
        }
        if planes.len() < 4 || !(size > 0.0 && volume > 1e-9 * size.powi(3)) {
            return Err("the convex hull spans no volume".into());
        }
        Ok(Self {
            planes,
            edges,
            tol: 1e-12 * size,
        })
    }

    /// The closest point `c` of the surface to `p` and the outward unit normal `n` there:
    /// `n·(p − c)` is the signed distance (negative inside).
    pub fn closest(&self, p: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
        let excess = |i: usize, y: &Vector3<f64>| self.planes[i].0.dot(y) - self.planes[i].1;
        let (k, s) = (0..self.planes.len())
            .map(|i| (i, excess(i, p)))
            .fold((0, f64::NEG_INFINITY), |a, b| if b.1 > a.1 { b } else { a });
        if s <= self.tol {
            let n = self.planes[k].0;
            return (p - n * s, n);
        }
        // Outside: on a face whose plane projection lies in the hull ...
        for (i, (n, _)) in self.planes.iter().enumerate() {
            let si = excess(i, p);
            if si > self.tol {
                let c = p - n * si;
                if (0..self.planes.len()).all(|j| excess(j, &c) <= self.tol) {
                    return (c, *n);
                }
            }
        }
        // ... else on an edge or a vertex.
        let mut best = (f64::INFINITY, *p);
        for (a, b) in &self.edges {
            let e = b - a;
            let t = ((p - a).dot(&e) / e.norm_squared()).clamp(0.0, 1.0);
            let c = a + e * t;
            let d = (p - c).norm_squared();
            if d < best.0 {
                best = (d, c);
            }
        }
        let c = best.1;
        let d = p - c;
        let l = d.norm();
        let n = if l > 0.0 { d / l } else { self.planes[k].0 };
        (c, n)
    }
}
