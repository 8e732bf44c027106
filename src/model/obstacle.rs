//! Obstacles: collision shapes of world-fixed links that the moving links' contact points rest
//! on, as on a ground (`<mech:obstacle link="L"/>`).
//!
//! A contact point `x` (radius `ρ`) and a convex obstacle shape `S` have the gap
//!
//! `g(q) = d(x(q), S) − ρ`, `d` the signed distance to the surface of `S` (negative inside),
//!
//! with `∇g = nᵀ ∂x/∂q`, `n` the outward unit normal at the closest point `c` of the surface.
//! The constraint row is evaluated as the plane through `c` with normal `n` (both taken at the
//! current `x`): its value and gradient are exact; its Hessian leaves out the surface's
//! curvature (zero on a face, `1/R` on a sphere), so Newton converges on a face as on a ground
//! and linearly where the curvature counts. Near an edge or a vertex of a box the normal turns
//! (the gap is `C¹` there, not `C²`). Shapes: boxes, spheres and capsules; the closest point is
//! computed in closed form in the shape's frame.

use crate::geometry::ShapeKind;
use nalgebra::{Isometry3, Point3, Vector3};

/// A convex shape fixed in the world.
#[derive(Clone, Debug, PartialEq)]
pub struct Obstacle {
    /// The world-fixed link it belongs to.
    pub link: String,
    /// The shape's frame in the world.
    pub world_from_shape: Isometry3<f64>,
    /// The shape (a box, a sphere or a capsule along z).
    pub shape: ShapeKind,
}

impl Obstacle {
    /// Whether `shape` can be an obstacle.
    pub(crate) fn supported(shape: &ShapeKind) -> bool {
        matches!(
            shape,
            ShapeKind::Box { .. } | ShapeKind::Sphere { .. } | ShapeKind::Capsule { .. }
        )
    }

    /// The closest point `c` of the surface to the world point `x` and the outward unit normal
    /// `n` there (world frame): `n·(x − c)` is the signed distance.
    pub(crate) fn tangent_plane(&self, x: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
        let p = self
            .world_from_shape
            .inverse_transform_point(&Point3::from(*x))
            .coords;
        let (c, n) = match &self.shape {
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
            _ => (Vector3::zeros(), Vector3::z()),
        };
        (
            self.world_from_shape
                .transform_point(&Point3::from(c))
                .coords,
            self.world_from_shape.rotation * n,
        )
    }
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Signed distances against values by hand: a unit cube's face, edge and inside point; a
    /// sphere; a capsule's side and cap.
    #[test]
    fn tangent_planes_give_the_signed_distance() {
        let dist = |o: &Obstacle, x: Vector3<f64>| {
            let (c, n) = o.tangent_plane(&x);
            n.dot(&(x - c))
        };
        let at = Isometry3::translation(1.0, 2.0, 3.0);
        let cube = Obstacle {
            link: "c".into(),
            world_from_shape: at,
            shape: ShapeKind::Box {
                size: Vector3::new(2.0, 2.0, 2.0),
            },
        };
        assert!((dist(&cube, Vector3::new(1.0, 2.0, 4.5)) - 0.5).abs() < 1e-15);
        assert!((dist(&cube, Vector3::new(3.0, 4.0, 3.0)) - 2f64.sqrt()).abs() < 1e-15);
        assert!((dist(&cube, Vector3::new(1.2, 2.0, 3.5)) + 0.5).abs() < 1e-15);
        let ball = Obstacle {
            link: "b".into(),
            world_from_shape: at,
            shape: ShapeKind::Sphere { radius: 0.5 },
        };
        assert!((dist(&ball, Vector3::new(1.0, 4.0, 3.0)) - 1.5).abs() < 1e-15);
        let capsule = Obstacle {
            link: "k".into(),
            world_from_shape: Isometry3::identity(),
            shape: ShapeKind::Capsule {
                radius: 0.1,
                length: 1.0,
            },
        };
        assert!((dist(&capsule, Vector3::new(0.3, 0.0, 0.2)) - 0.2).abs() < 1e-15);
        assert!((dist(&capsule, Vector3::new(0.0, 0.0, 0.8)) - 0.2).abs() < 1e-15);
    }
}
