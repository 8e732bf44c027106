//! parry3d's signed distances to convex hulls and cylinders: independent checks of the
//! obstacles' own closest points (module `model::obstacle`).

use nalgebra::Vector3;
use parry3d_f64::math::Vector;
use parry3d_f64::shape::Cylinder;

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
