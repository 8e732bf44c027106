//! The signed distance to a convex shape's surface: the closest point `c` of the surface to a
//! point `x` and the outward unit normal `n` there (the tangent plane), `d = n·(x − c)`
//! (negative inside). Obstacles' gap rows use it (`model::Obstacle`, `constraints::unilateral`):
//!
//! `g(q) = d(x(q), S) − ρ`, `∇g = nᵀ ∂x/∂q`,
//!
//! the row evaluated as the plane through `c` with normal `n` (both taken at the current `x`):
//! its value and gradient are exact, and its Hessian gets the surface's curvature `K = ∇²d`
//! added (module `curvature`). A zero-radius point exactly on an edge or a vertex has a gap
//! that is `C¹` there, not `C²`.
//!
//! Shapes: boxes, spheres, capsules and cylinders (closed forms in the shape's frame below) and
//! meshes, by their convex hull (closest points in module `hull`). The closed forms are kept
//! rather than parry's point projection: on the surface (where a resting contact is) they give
//! the face's exact normal, where a projection has only `x − c = 0`; the unit tests check them
//! against parry's projections.

use super::{Hull, ShapeKind};
use nalgebra::{Isometry3, Point3, Vector3};

/// The closest point `c` of the surface of `shape` (placed at `world_from_shape`; a mesh by
/// its convex `hull`) to the world point `x`, and the outward unit normal `n` there (world
/// frame): `n·(x − c)` is the signed distance.
pub(crate) fn tangent_plane(
    world_from_shape: &Isometry3<f64>,
    shape: &ShapeKind,
    hull: Option<&Hull>,
    x: &Vector3<f64>,
) -> (Vector3<f64>, Vector3<f64>) {
    let p = world_from_shape
        .inverse_transform_point(&Point3::from(*x))
        .coords;
    let (c, n) = match shape {
        ShapeKind::Sphere { radius } => {
            let n = unit_or_z(&p);
            (n * *radius, n)
        }
        ShapeKind::Capsule { radius, length } => {
            let z = p.z.clamp(-length / 2.0, length / 2.0);
            let axis = Vector3::new(0.0, 0.0, z);
            let n = unit_or_z(&(p - axis));
            (axis + n * *radius, n)
        }
        ShapeKind::Box { size } => box_plane(&p, &(size / 2.0)),
        ShapeKind::Cylinder { radius, length } => cylinder_plane(&p, *radius, length / 2.0),
        ShapeKind::Mesh { .. } => match hull {
            Some(hull) => hull.closest(&p),
            // Not reached: `model::Obstacle::new` makes the hull of every mesh.
            None => (Vector3::zeros(), Vector3::z()),
        },
    };
    (
        world_from_shape.transform_point(&Point3::from(c)).coords,
        world_from_shape.rotation * n,
    )
}

fn unit_or_z(v: &Vector3<f64>) -> Vector3<f64> {
    let l = v.norm();
    if l > 0.0 {
        v / l
    } else {
        Vector3::z()
    }
}

/// Closest surface point and outward normal of the box `[−h, h]` to `p` (shape frame). Outside
/// the box the closest point is `p` clamped to it; on or inside it, the face with the largest
/// `|p_i| − h_i`.
fn box_plane(p: &Vector3<f64>, h: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
    let excess = p.abs() - h;
    let scale = 1e-12 * h.amax();
    let k = excess.imax();
    let outside: Vec<usize> = (0..3).filter(|&i| excess[i] > scale).collect();
    if outside.len() <= 1 {
        // On a face (or inside): the face `k`.
        let mut n = Vector3::zeros();
        n[k] = p[k].signum();
        let mut c = *p;
        c[k] = p[k].signum() * h[k];
        return (c, n);
    }
    let c = Vector3::from_fn(|i, _| p[i].clamp(-h[i], h[i]));
    (c, unit_or_z(&(p - c)))
}

/// Closest surface point and outward normal of the cylinder of `radius` and half-length `h`
/// along z to `p` (shape frame): outside both the side and the caps, on the rim; otherwise on
/// the side (`ρ − r`) or a cap (`|z| − h`), whichever is larger (inside: the nearer).
fn cylinder_plane(p: &Vector3<f64>, radius: f64, h: f64) -> (Vector3<f64>, Vector3<f64>) {
    let rho = p.xy().norm();
    let u = if rho > 0.0 {
        Vector3::new(p.x / rho, p.y / rho, 0.0)
    } else {
        Vector3::x()
    };
    let (er, ez) = (rho - radius, p.z.abs() - h);
    let scale = 1e-12 * radius.max(h);
    let zs = p.z.signum();
    if er > scale && ez > scale {
        let c = u * radius + Vector3::z() * (zs * h);
        return (c, unit_or_z(&(p - c)));
    }
    if er >= ez {
        (u * radius + Vector3::z() * p.z.clamp(-h, h), u)
    } else {
        let r = rho.min(radius);
        (u * r + Vector3::z() * (zs * h), Vector3::z() * zs)
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;

    /// A shape placed in the world (the geometry of a `model::Obstacle`).
    pub(in crate::geometry) struct Placed {
        pub(in crate::geometry) world_from_shape: Isometry3<f64>,
        pub(in crate::geometry) shape: ShapeKind,
        pub(in crate::geometry) hull: Option<Hull>,
    }

    impl Placed {
        pub(in crate::geometry) fn tangent_plane(
            &self,
            x: &Vector3<f64>,
        ) -> (Vector3<f64>, Vector3<f64>) {
            tangent_plane(&self.world_from_shape, &self.shape, self.hull.as_ref(), x)
        }
    }

    /// Signed distances against values by hand: a unit cube's face, edge and inside point; a
    /// sphere; a capsule's side and cap.
    #[test]
    fn tangent_planes_give_the_signed_distance() {
        let dist = |o: &Placed, x: Vector3<f64>| {
            let (c, n) = o.tangent_plane(&x);
            n.dot(&(x - c))
        };
        let at = Isometry3::translation(1.0, 2.0, 3.0);
        let cube = Placed {
            world_from_shape: at,
            shape: ShapeKind::Box {
                size: Vector3::new(2.0, 2.0, 2.0),
            },
            hull: None,
        };
        assert!((dist(&cube, Vector3::new(1.0, 2.0, 4.5)) - 0.5).abs() < 1e-15);
        assert!((dist(&cube, Vector3::new(3.0, 4.0, 3.0)) - 2f64.sqrt()).abs() < 1e-15);
        assert!((dist(&cube, Vector3::new(1.2, 2.0, 3.5)) + 0.5).abs() < 1e-15);
        let ball = Placed {
            world_from_shape: at,
            shape: ShapeKind::Sphere { radius: 0.5 },
            hull: None,
        };
        assert!((dist(&ball, Vector3::new(1.0, 4.0, 3.0)) - 1.5).abs() < 1e-15);
        let capsule = Placed {
            world_from_shape: Isometry3::identity(),
            shape: ShapeKind::Capsule {
                radius: 0.1,
                length: 1.0,
            },
            hull: None,
        };
        assert!((dist(&capsule, Vector3::new(0.3, 0.0, 0.2)) - 0.2).abs() < 1e-15);
        assert!((dist(&capsule, Vector3::new(0.0, 0.0, 0.8)) - 0.2).abs() < 1e-15);
    }

    fn at(shape: ShapeKind, hull: Option<Hull>) -> Placed {
        Placed {
            world_from_shape: Isometry3::new(
                Vector3::new(0.3, -0.2, 0.1),
                Vector3::new(0.2, -0.4, 0.3),
            ),
            shape,
            hull,
        }
    }

    fn hull_of(points: &[Vector3<f64>]) -> Hull {
        let (v, f) = super::super::convex_hull_of(points).unwrap();
        Hull::new(&v, &f).unwrap()
    }

    /// A wedge (triangular prism along x): bottom `z = 0`, `|y| ≤ 0.2`, ridge over `y = −0.2`
    /// at `z = 0.15`; its slanted face meets the bottom at an acute edge.
    fn wedge() -> Vec<Vector3<f64>> {
        let mut v = Vec::new();
        for x in [-0.3, 0.3] {
            v.push(Vector3::new(x, -0.2, 0.0));
            v.push(Vector3::new(x, 0.2, 0.0));
            v.push(Vector3::new(x, -0.2, 0.15));
        }
        v
    }

    fn corners(h: Vector3<f64>) -> Vec<Vector3<f64>> {
        (0..8)
            .map(|k| {
                let s = |bit: usize| if k & bit == 0 { -1.0 } else { 1.0 };
                Vector3::new(s(1) * h.x, s(2) * h.y, s(4) * h.z)
            })
            .collect()
    }

    /// Shape-frame points around and inside a shape of size about `r`, pseudo-random.
    fn cloud(r: f64) -> Vec<Vector3<f64>> {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        (0..400)
            .map(|_| Vector3::new(next(), next(), next()) * (1.6 * r))
            .collect()
    }

    /// The signed distance and the closest point in the shape frame.
    fn local(o: &Placed, p: &Vector3<f64>) -> (f64, Vector3<f64>) {
        let x = o.world_from_shape.transform_point(&Point3::from(*p)).coords;
        let (c, n) = o.tangent_plane(&x);
        (n.dot(&(x - c)), c)
    }

    /// Every shape: the signed distance equals parry3d's projection (the hulls, the box as the
    /// hull of its corners, the cylinder) or the closed form (sphere, capsule); the normal is a
    /// unit vector equal to central differences of the signed distance (step 1e-7, away from
    /// the edges where the gap is not differentiable), and the closest point is on the normal
    /// line: `x − c = d n`.
    #[test]
    fn signed_distances_match_parry_and_normals_match_finite_differences() {
        let hb = Vector3::new(0.25, 0.15, 0.1);
        let wedge = wedge();
        let box_pts = corners(hb);
        let cases: Vec<(Placed, Reference)> = vec![
            (
                at(ShapeKind::Box { size: hb * 2.0 }, None),
                Box::new(move |p| super::super::parry_signed_distance(&box_pts, p).unwrap()),
            ),
            (
                at(
                    ShapeKind::Cylinder {
                        radius: 0.2,
                        length: 0.5,
                    },
                    None,
                ),
                Box::new(|p| super::super::parry_cylinder_signed_distance(0.2, 0.5, p)),
            ),
            (
                at(ShapeKind::Sphere { radius: 0.2 }, None),
                Box::new(|p| p.norm() - 0.2),
            ),
            (
                at(
                    ShapeKind::Capsule {
                        radius: 0.1,
                        length: 0.3,
                    },
                    None,
                ),
                Box::new(|p| (p - Vector3::new(0.0, 0.0, p.z.clamp(-0.15, 0.15))).norm() - 0.1),
            ),
            (
                at(mesh(), Some(hull_of(&wedge))),
                Box::new(move |p| super::super::parry_signed_distance(&wedge, p).unwrap()),
            ),
            (
                at(mesh(), Some(hull_of(&corners(hb)))),
                Box::new(move |p| super::super::parry_signed_distance(&corners(hb), p).unwrap()),
            ),
        ];
        for (o, reference) in &cases {
            // The cloud, and 1e-4 outside and inside the closest point of each cloud point (on
            // a face, or next to an edge or a vertex).
            let mut probes = cloud(0.3);
            for p in cloud(0.3) {
                let x = o.world_from_shape.transform_point(&Point3::from(p)).coords;
                let (c, n) = o.tangent_plane(&x);
                for off in [1e-4, -1e-4] {
                    let y = c + n * off;
                    probes.push(
                        o.world_from_shape
                            .inverse_transform_point(&Point3::from(y))
                            .coords,
                    );
                }
            }
            let mut compared = 0;
            for &p in &probes {
                let (d, _) = local(o, &p);
                let want = reference(&p);
                assert!(
                    (d - want).abs() < 1e-9,
                    "{:?} at {p:?}: {d} vs parry {want}",
                    o.shape
                );
                let x = o.world_from_shape.transform_point(&Point3::from(p)).coords;
                let (c, n) = o.tangent_plane(&x);
                assert!((n.norm() - 1.0).abs() < 1e-14);
                assert!((x - c - n * d).norm() < 1e-12, "{:?} at {p:?}", o.shape);
                let h = 1e-7;
                let fd = Vector3::from_fn(|i, _| {
                    let mut e = Vector3::zeros();
                    e[i] = h;
                    let sd = |y: Vector3<f64>| {
                        let (c, n) = o.tangent_plane(&y);
                        n.dot(&(y - c))
                    };
                    (sd(x + e) - sd(x - e)) / (2.0 * h)
                });
                // Within the step of an edge (or, inside, of points equidistant from two
                // faces) the one-sided normals differ and the differences are not a unit
                // vector; skip those.
                if (fd.norm() - 1.0).abs() < 1e-6 {
                    compared += 1;
                    assert!(
                        (fd - n).norm() < 1e-6,
                        "{:?} at {p:?}: {fd:?} vs {n:?}",
                        o.shape
                    );
                }
            }
            assert!(
                compared * 100 >= probes.len() * 95,
                "{:?}: {compared}",
                o.shape
            );
        }
    }

    /// An independent signed distance (shape frame).
    type Reference = Box<dyn Fn(&Vector3<f64>) -> f64>;

    fn mesh() -> ShapeKind {
        ShapeKind::Mesh {
            uri: "test".into(),
            path: None,
            scale: Vector3::repeat(1.0),
        }
    }

    /// Points on and just off the faces, edges and vertices: the hull of a box's corners gives
    /// the box's closed form (closest point and normal) to rounding, the wedge its slanted face's
    /// normal on that face, and on a face the normal is the face's (not `x − c = 0`).
    #[test]
    fn hull_matches_the_box_closed_form_near_faces_edges_and_vertices() {
        let h = Vector3::new(0.25, 0.15, 0.1);
        let hull = hull_of(&corners(h));
        for corner in corners(h) {
            for dir in corners(Vector3::new(1.0, 1.0, 1.0)) {
                for off in [0.0, 1e-9, 1e-4, -1e-4, 0.05] {
                    for mask in 1..8usize {
                        // Move along the directions in `mask` only: onto faces, edges, vertex.
                        let step = Vector3::from_fn(|i, _| {
                            if mask & (1 << i) != 0 {
                                dir[i] * off
                            } else {
                                -corner[i] * 0.5
                            }
                        });
                        let p = corner + step;
                        let (c, n) = hull.closest(&p);
                        let (cb, nb) = box_plane(&p, &h);
                        let (d, db) = (n.dot(&(p - c)), nb.dot(&(p - cb)));
                        assert!((d - db).abs() < 1e-14, "{p:?}: {d} vs {db}");
                        // The normal is unique outside, and on or inside where one face is
                        // nearest (not on an edge or equidistant from two faces).
                        let mut ex: Vec<f64> = (p.abs() - h).iter().copied().collect();
                        ex.sort_by(|a, b| b.total_cmp(a));
                        if d > 1e-6 || (d <= 0.0 && ex[0] - ex[1] > 1e-6) {
                            assert!((n - nb).norm() < 1e-9, "{p:?}: {n:?} vs {nb:?}");
                        }
                    }
                }
            }
        }
        let slant: Vector3<f64> = Vector3::new(0.0, 0.15, 0.4).normalize();
        let wedge = hull_of(&wedge());
        let on = Vector3::new(0.1, 0.0, 0.075);
        assert!(slant.dot(&(on - Vector3::new(0.0, -0.2, 0.15))).abs() < 1e-15);
        for p in [on, on + slant * 1e-9, on - slant * 1e-3, on + slant * 0.01] {
            let (c, n) = wedge.closest(&p);
            assert!((n - slant).norm() < 1e-14, "{n:?}");
            assert!((c - on).norm() < 1e-14);
        }
    }

    /// The cylinder's closed form on its side, cap and rim, by hand.
    #[test]
    fn cylinder_closest_points_by_hand() {
        let (c, n) = cylinder_plane(&Vector3::new(0.0, 0.5, 0.1), 0.2, 0.25);
        assert_eq!((c, n), (Vector3::new(0.0, 0.2, 0.1), Vector3::y()));
        let (c, n) = cylinder_plane(&Vector3::new(0.1, 0.0, -0.4), 0.2, 0.25);
        assert_eq!((c, n), (Vector3::new(0.1, 0.0, -0.25), -Vector3::z()));
        let (c, n) = cylinder_plane(&Vector3::new(0.5, 0.0, 0.65), 0.2, 0.25);
        assert!((c - Vector3::new(0.2, 0.0, 0.25)).norm() < 1e-15);
        assert!((n - Vector3::new(0.6, 0.0, 0.8)).norm() < 1e-15);
        // Inside, nearer the side than the cap.
        let (c, n) = cylinder_plane(&Vector3::new(0.15, 0.0, 0.0), 0.2, 0.25);
        assert!((c - Vector3::new(0.2, 0.0, 0.0)).norm() < 1e-15 && n == Vector3::x());
    }
}
