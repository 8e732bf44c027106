//! Curvature of an obstacle's signed distance: the Hessian `K = ∇²d(x)` that the gap row
//! `g = d(x(q)) − ρ` needs beyond its tangent plane (module `surface`):
//!
//! `∇²g = (∂x/∂q)ᵀ K (∂x/∂q) + Σ_k n_k ∇²x_k`.
//!
//! `d` is the distance to a point, a line or a circle near a vertex, an edge or a rim, to a
//! plane on a face (in the shape frame, `n` the outward normal at the closest point `c`):
//! - sphere (`d = |p| − R`) and a capsule's cap: `K = (I − n nᵀ) / r`, `r` the distance to the
//!   centre;
//! - a capsule's or a cylinder's side (`d = ϱ − R`, `ϱ` the distance to the axis):
//!   `K = e_φ e_φᵀ / ϱ`, `e_φ = e_z × u` (`u` the radial unit vector);
//! - a cylinder's rim (distance `f` to the circle of radius `R`):
//!   `K = (I − n nᵀ − e_φ e_φᵀ) / f + (n·u) e_φ e_φᵀ / ϱ`;
//! - a box's edge along axis `t`: `K = (I − n nᵀ − t tᵀ) / |p − c|`; its vertex
//!   `K = (I − n nᵀ) / |p − c|`;
//! - a box's face, a cylinder's cap: `K = 0`.
//!
//! A mesh's hull gives `K = 0` (exact on its faces; its edges and vertices keep the tangent
//! plane's Hessian). Where `d` is not twice differentiable (a point exactly on an edge,
//! a vertex or the axis) `K = 0` too.

use super::ShapeKind;
use nalgebra::{Isometry3, Matrix3, Point3, Vector3};

/// The Hessian of the signed distance to the surface of `shape` (placed at
/// `world_from_shape`) at the world point `x` (world frame).
pub(crate) fn curvature(
    world_from_shape: &Isometry3<f64>,
    shape: &ShapeKind,
    x: &Vector3<f64>,
) -> Matrix3<f64> {
    let p = world_from_shape
        .inverse_transform_point(&Point3::from(*x))
        .coords;
    let k = match shape {
        ShapeKind::Sphere { .. } => point(&p, &Vector3::zeros()),
        ShapeKind::Capsule { length, .. } => {
            let h = length / 2.0;
            if p.z.abs() < h {
                side(&p)
            } else {
                point(&p, &Vector3::new(0.0, 0.0, p.z.clamp(-h, h)))
            }
        }
        ShapeKind::Box { size } => box_curvature(&p, &(size / 2.0)),
        ShapeKind::Cylinder { radius, length } => cylinder(&p, *radius, length / 2.0),
        ShapeKind::Mesh { .. } => Matrix3::zeros(),
    };
    let r = world_from_shape.rotation.to_rotation_matrix();
    r.matrix() * k * r.matrix().transpose()
}

/// `(I − n nᵀ) / r` of the distance to the point `c`.
fn point(p: &Vector3<f64>, c: &Vector3<f64>) -> Matrix3<f64> {
    let v = p - c;
    let r = v.norm();
    if r <= 0.0 {
        return Matrix3::zeros();
    }
    let n = v / r;
    (Matrix3::identity() - n * n.transpose()) / r
}

/// `e_φ e_φᵀ / ϱ` of the distance to the z axis.
fn side(p: &Vector3<f64>) -> Matrix3<f64> {
    let rho = p.xy().norm();
    if rho <= 0.0 {
        return Matrix3::zeros();
    }
    let phi = Vector3::new(-p.y / rho, p.x / rho, 0.0);
    phi * phi.transpose() / rho
}

/// The box `[−h, h]`: zero on a face (or inside), a line's on an edge, a point's at a vertex
/// (the regions of `surface::box_plane`).
fn box_curvature(p: &Vector3<f64>, h: &Vector3<f64>) -> Matrix3<f64> {
    let excess = p.abs() - h;
    let scale = 1e-12 * h.amax();
    let outside: Vec<usize> = (0..3).filter(|&i| excess[i] > scale).collect();
    let c = Vector3::from_fn(|i, _| p[i].clamp(-h[i], h[i]));
    match outside.len() {
        2 => {
            let along = (0..3).find(|i| !outside.contains(i)).unwrap_or(2);
            let mut t = Vector3::zeros();
            t[along] = 1.0;
            let v = p - c;
            let d = v.norm();
            if d <= 0.0 {
                return Matrix3::zeros();
            }
            let n = v / d;
            (Matrix3::identity() - n * n.transpose() - t * t.transpose()) / d
        }
        3 => point(p, &c),
        _ => Matrix3::zeros(),
    }
}

/// The cylinder of `radius` and half-length `h` along z: its side, its caps, its rims (the
/// regions of `obstacle::cylinder_plane`).
fn cylinder(p: &Vector3<f64>, radius: f64, h: f64) -> Matrix3<f64> {
    let rho = p.xy().norm();
    let (er, ez) = (rho - radius, p.z.abs() - h);
    let scale = 1e-12 * radius.max(h);
    if er > scale && ez > scale {
        let u = Vector3::new(p.x / rho, p.y / rho, 0.0);
        let phi = Vector3::new(-u.y, u.x, 0.0);
        let c = u * radius + Vector3::z() * (p.z.signum() * h);
        let v = p - c;
        let f = v.norm();
        let n = v / f;
        let pp = phi * phi.transpose();
        return (Matrix3::identity() - n * n.transpose() - pp) / f + pp * (n.dot(&u) / rho);
    }
    if er >= ez {
        side(p)
    } else {
        Matrix3::zeros()
    }
}

#[cfg(test)]
mod tests {
    use super::super::surface::tests::Placed;
    use super::*;

    /// `K` equals central second differences of the signed distance `n·(x − c)` of the tangent
    /// plane, in every region of every shape, the shape turned and moved.
    #[test]
    fn curvature_matches_second_differences_of_the_distance() {
        let at = Isometry3::new(Vector3::new(0.3, -0.2, 0.1), Vector3::new(0.2, -0.4, 0.3));
        let obstacle = |shape| Placed {
            world_from_shape: at,
            shape,
            hull: None,
        };
        let bx = ShapeKind::Box {
            size: Vector3::new(1.0, 0.8, 0.6),
        };
        let cyl = ShapeKind::Cylinder {
            radius: 0.3,
            length: 0.8,
        };
        let cases = [
            (
                ShapeKind::Sphere { radius: 0.4 },
                Vector3::new(0.3, 0.2, 0.5),
            ),
            (
                ShapeKind::Capsule {
                    radius: 0.1,
                    length: 0.6,
                },
                Vector3::new(0.25, 0.1, 0.1),
            ),
            (
                ShapeKind::Capsule {
                    radius: 0.1,
                    length: 0.6,
                },
                Vector3::new(0.1, 0.05, 0.45),
            ),
            (bx.clone(), Vector3::new(0.1, 0.05, 0.5)),
            (bx.clone(), Vector3::new(0.7, 0.05, 0.5)),
            (bx, Vector3::new(0.7, 0.6, 0.5)),
            (cyl.clone(), Vector3::new(0.4, 0.2, 0.1)),
            (cyl.clone(), Vector3::new(0.1, 0.05, 0.6)),
            (cyl, Vector3::new(0.4, 0.2, 0.6)),
        ];
        for (shape, local) in cases {
            let o = obstacle(shape.clone());
            let x = at.transform_point(&Point3::from(local)).coords;
            let dist = |y: &Vector3<f64>| {
                let (c, n) = o.tangent_plane(y);
                n.dot(&(y - c))
            };
            let k = curvature(&o.world_from_shape, &o.shape, &x);
            let e = 1e-4;
            for i in 0..3 {
                for j in 0..3 {
                    let (mut di, mut dj) = (Vector3::zeros(), Vector3::zeros());
                    di[i] = e;
                    dj[j] = e;
                    let fd = (dist(&(x + di + dj)) - dist(&(x + di - dj)) - dist(&(x - di + dj))
                        + dist(&(x - di - dj)))
                        / (4.0 * e * e);
                    assert!(
                        (k[(i, j)] - fd).abs() < 1e-5,
                        "{shape:?} at {local:?}: K[{i},{j}] = {} against {fd}",
                        k[(i, j)]
                    );
                }
            }
        }
    }
}
