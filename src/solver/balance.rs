//! Balance diagnostics of a free mechanism standing on its contacts: the support polygon, the
//! centre of mass and the static stability margin.
//!
//! With `ĝ` the direction of gravity and `P = I − ĝ ĝᵀ` the projection along it onto the
//! plane through the mean `o` of the loaded contact points, the support polygon is the convex
//! hull of `o + P (p_i − o)` over the contacts that push (normal force above `10⁻⁹` of the
//! weight), the centre of mass `c = Σ m_b c_b / Σ m_b` (the mass subject to gravity) projects
//! to `o + P (c − o)`, and the stability margin is the signed distance from that projection to
//! the polygon's boundary: positive inside, negative outside (a single point or a segment has
//! no inside: minus the distance to it). Only a mechanism without a joint to the world (a
//! floating base) gets one: elsewhere the world holds it too.

use super::report::Contact;
use crate::model::{JointKind, Model};
use crate::state::State;
use nalgebra::{Vector2, Vector3};

/// The support polygon, centre of mass and stability margin (module docs).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Balance {
    /// Centre of the mass subject to gravity, world frame \[m\].
    pub centre_of_mass: [f64; 3],
    /// Its projection along gravity onto the support plane \[m\].
    pub com_projection: [f64; 3],
    /// Corners of the support polygon (convex hull of the loaded contact points projected
    /// along gravity), counter-clockwise seen against gravity \[m\].
    pub support_polygon: Vec<[f64; 3]>,
    /// Signed distance from the projection of the centre of mass to the polygon's boundary,
    /// positive inside \[m\].
    pub stability_margin: f64,
}

/// Whether no joint holds a body to the world other than a floating one.
fn floats(model: &Model) -> bool {
    !model.bodies.is_empty()
        && model.joints.iter().all(|j| {
            j.kind == JointKind::Floating || (j.bodies[0].is_some() && j.bodies[1].is_some())
        })
}

impl Balance {
    /// The diagnostics of a free mechanism at `state` on `contacts` (`None` for one held by
    /// the world, without gravity, or without a loaded contact).
    pub fn of(model: &Model, state: &State, contacts: &[Contact]) -> Option<Balance> {
        if !floats(model) || model.gravity.norm() == 0.0 {
            return None;
        }
        let down = model.gravity.normalize();
        let total: f64 = model.bodies.iter().map(|b| b.gravity_mass).sum();
        if total <= 0.0 {
            return None;
        }
        let weight = total * model.gravity.norm();
        let loaded: Vec<Vector3<f64>> = contacts
            .iter()
            .filter(|c| c.normal_force > 1e-9 * weight)
            .map(|c| Vector3::from(c.point_world))
            .collect();
        if loaded.is_empty() {
            return None;
        }
        let mut com = Vector3::zeros();
        for (i, b) in model.bodies.iter().enumerate() {
            let pose = state.body_pose(crate::model::BodyId(i));
            com += (pose * nalgebra::Point3::from(b.gravity_com)).coords * b.gravity_mass;
        }
        com /= total;
        let origin = loaded.iter().sum::<Vector3<f64>>() / loaded.len() as f64;
        // A right-handed basis (e1, e2) of the plane, seen against gravity (e1 × e2 = −ĝ).
        let e1 = if down.x.abs() < 0.9 {
            Vector3::x().cross(&down).normalize()
        } else {
            Vector3::y().cross(&down).normalize()
        };
        let e2 = down.cross(&e1);
        let flat = |p: &Vector3<f64>| Vector2::new((p - origin).dot(&e1), (p - origin).dot(&e2));
        let lift = |p: &Vector2<f64>| origin + e1 * p.x + e2 * p.y;
        let hull = convex_hull(loaded.iter().map(flat).collect());
        let c2 = flat(&com);
        Some(Balance {
            centre_of_mass: com.into(),
            com_projection: lift(&c2).into(),
            support_polygon: hull.iter().map(|p| lift(p).into()).collect(),
            stability_margin: signed_distance(&hull, &c2),
        })
    }
}

/// The convex hull of `points`, counter-clockwise, without collinear points (Andrew's
/// monotone chain); one or two points for a degenerate set.
pub(crate) fn convex_hull(mut points: Vec<Vector2<f64>>) -> Vec<Vector2<f64>> {
    points.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    let scale = points
        .iter()
        .map(|p| p.amax())
        .fold(0.0, f64::max)
        .max(1e-300);
    points.dedup_by(|a, b| (*a - *b).amax() <= 1e-12 * scale);
    if points.len() < 3 {
        return points;
    }
    let cross = |o: &Vector2<f64>, a: &Vector2<f64>, b: &Vector2<f64>| (a - o).perp(&(b - o));
    let tol = 1e-12 * scale * scale;
    let mut hull: Vec<Vector2<f64>> = Vec::with_capacity(2 * points.len());
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &Vector2<f64>>> = if pass == 0 {
            Box::new(points.iter())
        } else {
            Box::new(points.iter().rev())
        };
        for p in iter {
            while hull.len() >= start + 2
                && cross(&hull[hull.len() - 2], &hull[hull.len() - 1], p) <= tol
            {
                hull.pop();
            }
            hull.push(*p);
        }
        hull.pop();
    }
    if hull.len() < 3 {
        // Collinear: the segment's ends.
        return vec![points[0], points[points.len() - 1]];
    }
    hull
}

/// Signed distance from `p` to the boundary of the convex polygon `hull` (counter-clockwise):
/// positive inside; minus the distance to a point or segment.
pub(crate) fn signed_distance(hull: &[Vector2<f64>], p: &Vector2<f64>) -> f64 {
    let to_segment = |a: &Vector2<f64>, b: &Vector2<f64>| {
        let d = b - a;
        let t = if d.norm_squared() > 0.0 {
            ((p - a).dot(&d) / d.norm_squared()).clamp(0.0, 1.0)
        } else {
            0.0
        };
        (a + d * t - p).norm()
    };
    match hull.len() {
        0 => f64::NEG_INFINITY,
        1 => -(hull[0] - p).norm(),
        2 => -to_segment(&hull[0], &hull[1]),
        n => {
            let edges = (0..n).map(|i| (hull[i], hull[(i + 1) % n]));
            let distance = edges
                .clone()
                .map(|(a, b)| to_segment(&a, &b))
                .fold(f64::INFINITY, f64::min);
            let inside = edges
                .into_iter()
                .all(|(a, b)| (b - a).perp(&(p - a)) >= 0.0);
            if inside {
                distance
            } else {
                -distance
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit square with a point inside, on an edge and outside (distances by hand), and
    /// interior and collinear points dropped from the hull.
    #[test]
    fn square_margins() {
        let pts: Vec<Vector2<f64>> = [
            (0.0, 0.0),
            (1.0, 0.0),
            (1.0, 1.0),
            (0.0, 1.0),
            (0.5, 0.5),
            (0.5, 0.0),
        ]
        .iter()
        .map(|&(x, y)| Vector2::new(x, y))
        .collect();
        let hull = convex_hull(pts);
        assert_eq!(hull.len(), 4, "{hull:?}");
        assert!((signed_distance(&hull, &Vector2::new(0.3, 0.5)) - 0.3).abs() < 1e-15);
        assert!(signed_distance(&hull, &Vector2::new(1.0, 0.5)).abs() < 1e-15);
        assert!((signed_distance(&hull, &Vector2::new(2.0, 2.0)) + 2f64.sqrt()).abs() < 1e-15);
        let seg = convex_hull(vec![
            Vector2::new(0.0, 0.0),
            Vector2::new(1.0, 0.0),
            Vector2::new(2.0, 0.0),
        ]);
        assert_eq!(seg.len(), 2);
        assert!((signed_distance(&seg, &Vector2::new(1.0, 0.5)) + 0.5).abs() < 1e-15);
    }
}
