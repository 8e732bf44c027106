//! Inequality constraints `g(q) ≥ 0`: joint stops and contact with the grounds.
//!
//! - Joint stop on coordinate `θ` of a revolute or prismatic joint with URDF limits:
//!   `g = θ − lower ≥ 0` and `g = upper − θ ≥ 0`.
//! - Contact of point `s` (radius `ρ`) of body `i` with the ground `(o, n)`:
//!   `g = n·(r_i + A(p_i) s − o) − ρ ≥ 0`.
//!
//! An active inequality joins `Φ` as the row `g(q) = 0` (module docs of the solver's
//! `active_set`); its multiplier `λ` (`V_qᵀ = Φ_qᵀ μ`) is the stop's holding effort or the
//! contact's normal force, and must not be negative. A sticking contact adds the two tangential
//! rows `t_k·(r_i + A(p_i) c − a) = 0`: `c` the material point that touched (body frame), `a`
//! the world point where it touched, `t_1, t_2` an orthonormal basis of the ground plane; their
//! multipliers are the friction force. (A sphere held at its material point can roll, as a real
//! foot does; holding its centre would forbid rolling. The solver then moves the anchor as the
//! sphere rolls: module `solver::active_set`.)

use crate::jet::{pair_of, Pair, Scalar};
use crate::kinematics::{coordinate, Branches};
use crate::model::{BodyId, JointId, Model};
use nalgebra::{DVector, Vector3};

/// Which side of a joint's range a stop holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Bound {
    Lower,
    Upper,
}

impl Bound {
    /// `lower` or `upper`.
    pub(crate) fn name(self) -> &'static str {
        match self {
            Bound::Lower => "lower",
            Bound::Upper => "upper",
        }
    }
}

/// One inequality `g(q) ≥ 0`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Unilateral {
    /// A stop of coordinate 0 of a joint at `value`.
    Limit {
        joint: JointId,
        bound: Bound,
        value: f64,
    },
    /// Contact point `point` (index into `Model::contact_points`) against ground `ground`.
    Contact { point: usize, ground: usize },
}

/// Where a sticking contact is held: the material point of the shape that touched (body
/// frame, on the shape's surface: a sphere's centre minus its radius along the normal at first
/// touch) stays at the world point where it touched, tangentially. A sphere can still roll.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Anchor {
    /// The world point where it first touched \[m\].
    pub(crate) world: Vector3<f64>,
    /// The material point that touched, body frame \[m\].
    pub(crate) body: Vector3<f64>,
}

/// An inequality held as an equality: a stop the joint rests on, a contact that touches.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Active {
    pub(crate) row: Unilateral,
    /// Sticking contact: where it is held (tangential rows).
    pub(crate) anchor: Option<Anchor>,
}

impl Active {
    /// Number of constraint rows: 1, or 3 for a sticking contact.
    pub(crate) fn row_count(&self) -> usize {
        if self.anchor.is_some() {
            3
        } else {
            1
        }
    }
}

/// Every inequality of `model`: both stops of each revolute or prismatic joint (tree or loop)
/// with `<limit>` when `limits` is set, and every contact point against every ground.
pub(crate) fn inequalities(model: &Model, limits: bool) -> Vec<Unilateral> {
    let mut out = Vec::new();
    if limits {
        for (i, j) in model.joints.iter().enumerate() {
            if j.merged || !j.kind.has_limits() {
                continue;
            }
            if let Some([lo, hi]) = j.limits {
                out.push(Unilateral::Limit {
                    joint: JointId(i),
                    bound: Bound::Lower,
                    value: lo,
                });
                out.push(Unilateral::Limit {
                    joint: JointId(i),
                    bound: Bound::Upper,
                    value: hi,
                });
            }
        }
    }
    for point in 0..model.contact_points.len() {
        for ground in 0..model.grounds.len() + model.obstacles.len() {
            out.push(Unilateral::Contact { point, ground });
        }
    }
    out
}

/// The surface `ground` of a contact near the world point `x`, as a plane `(o, n)`: a ground
/// itself (`ground < grounds.len()`), or an obstacle's tangent plane at the point of its
/// surface closest to `x` (module `model::obstacle`).
pub(crate) fn surface(
    model: &Model,
    ground: usize,
    x: &Vector3<f64>,
) -> (Vector3<f64>, Vector3<f64>) {
    match model.grounds.get(ground) {
        Some(g) => (g.origin, g.normal),
        None => model.obstacles[ground - model.grounds.len()].tangent_plane(x),
    }
}

/// Name of the surface `ground`: the ground's, or the obstacle's link.
pub(crate) fn surface_name(model: &Model, ground: usize) -> &str {
    match model.grounds.get(ground) {
        Some(g) => &g.name,
        None => &model.obstacles[ground - model.grounds.len()].link,
    }
}

/// The bodies a row of `u` depends on.
pub(crate) fn bodies(model: &Model, u: &Unilateral) -> [Option<BodyId>; 2] {
    match *u {
        Unilateral::Limit { joint, .. } => model.joints[joint.0].bodies,
        Unilateral::Contact { point, .. } => [Some(model.contact_points[point].body), None],
    }
}

/// Power of length in the unit of `g` (0 for an angle).
pub(crate) fn length_power(model: &Model, u: &Unilateral) -> i32 {
    match *u {
        Unilateral::Limit { joint, .. } => i32::from(!model.joints[joint.0].kind.is_angle(0)),
        Unilateral::Contact { .. } => 1,
    }
}

/// Name of the inequality: `joint.lower_limit`, `link.contact[k]@ground`.
pub(crate) fn name(model: &Model, u: &Unilateral) -> String {
    match *u {
        Unilateral::Limit { joint, bound, .. } => {
            format!("{}.{}_limit", model.joints[joint.0].name, bound.name())
        }
        Unilateral::Contact { point, ground } => format!(
            "{}.contact[{point}]@{}",
            model.contact_points[point].link,
            surface_name(model, ground)
        ),
    }
}

/// An orthonormal basis `t_1, t_2` of the plane with unit normal `n`.
pub(crate) fn tangents(n: &Vector3<f64>) -> [Vector3<f64>; 2] {
    let helper = if n.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let t1 = n.cross(&helper).normalize();
    [t1, n.cross(&t1)]
}

/// World position of a contact point at `q` (value only).
pub(crate) fn point_world(model: &Model, point: usize, q: &DVector<f64>) -> Vector3<f64> {
    let c = &model.contact_points[point];
    let i = 7 * c.body.0;
    let r = Vector3::new(q[i], q[i + 1], q[i + 2]);
    let p = nalgebra::Vector4::new(q[i + 3], q[i + 4], q[i + 5], q[i + 6]);
    r + crate::math::rotation(&p) * c.point
}

/// The rows of `a` as jets over the pair of `bodies(model, &a.row)`: `g`, then the two
/// tangential rows of a sticking contact. `None` where a joint coordinate is undefined.
pub(crate) fn rows(
    model: &Model,
    a: &Active,
    pair: &Pair,
    branches: &Branches,
) -> Option<Vec<Scalar>> {
    let mut out = Vec::with_capacity(a.row_count());
    rows_into(model, a, pair, branches, &mut out).map(|()| out)
}

/// [`rows`] into the buffer `out` (cleared first; no allocation once it has room for 3).
pub(crate) fn rows_into(
    model: &Model,
    a: &Active,
    pair: &Pair,
    branches: &Branches,
    out: &mut Vec<Scalar>,
) -> Option<()> {
    out.clear();
    match a.row {
        Unilateral::Limit {
            joint,
            bound,
            value,
        } => {
            let j = &model.joints[joint.0];
            let theta = coordinate(j, pair, 0, branches.get(joint, 0))?;
            out.push(match bound {
                Bound::Lower => theta.minus(value),
                Bound::Upper => theta.minus(value).scale(-1.0),
            });
            Some(())
        }
        Unilateral::Contact { point, ground } => {
            let c = &model.contact_points[point];
            let at = pair.r[0] + crate::math::rotation(&pair.p[0]) * c.point;
            let (origin, normal) = surface(model, ground, &at);
            let x = pair.point(0, &c.point);
            let n = pair.vector(1, &normal);
            let mut gap = pair
                .dot(&x.sub(&pair.point(1, &origin)), &n)
                .minus(c.radius);
            // An obstacle's curvature: `(∂x/∂q)ᵀ K (∂x/∂q)` (module `model::curvature`).
            if let (Some(h), Some(o)) = (
                gap.h.as_mut(),
                ground
                    .checked_sub(model.grounds.len())
                    .and_then(|k| model.obstacles.get(k)),
            ) {
                let k = o.curvature(&at);
                if k != nalgebra::Matrix3::zeros() {
                    **h += x.j.transpose() * k * x.j;
                }
            }
            out.push(gap);
            if let Some(anchor) = a.anchor {
                let d = pair
                    .point(0, &anchor.body)
                    .sub(&pair.point(1, &anchor.world));
                for t in tangents(&normal) {
                    out.push(pair.dot(&d, &pair.vector(1, &t)));
                }
            }
            Some(())
        }
    }
}

/// The values of the rows of `a` (as [`rows`] lists them) into `out`, bit for bit the jets'
/// values of [`rows`] (the same operations on the same numbers) without their derivatives or
/// an allocation: the corrector's chord steps and the guard's boundary search evaluate `Φ`
/// alone at every trial point. Returns the number of rows, `None` where [`rows`] has none.
pub(crate) fn values(
    model: &Model,
    a: &Active,
    pair: &Pair,
    branches: &Branches,
    out: &mut [f64; 3],
) -> Option<usize> {
    use crate::math::rotation;
    match a.row {
        Unilateral::Limit {
            joint,
            bound,
            value,
        } => {
            let j = &model.joints[joint.0];
            let theta = crate::kinematics::coordinate_value(j, pair, 0, branches.get(joint, 0))?;
            out[0] = match bound {
                Bound::Lower => theta - value,
                // `Scalar::scale(-1.0)`: the product by −1 is the negation, exactly.
                Bound::Upper => -(theta - value),
            };
            Some(1)
        }
        Unilateral::Contact { point, ground } => {
            let c = &model.contact_points[point];
            // `Pair::point`, `Pair::vector`, `Vec3Jet::sub`, `Pair::dot`, `Scalar::minus`.
            let a0 = rotation(&pair.p[0]);
            let a1 = rotation(&pair.p[1]);
            let x = pair.r[0] + a0 * c.point;
            let (origin, normal) = surface(model, ground, &x);
            let n = a1 * normal;
            out[0] = (x - (pair.r[1] + a1 * origin)).dot(&n) - c.radius;
            let Some(anchor) = a.anchor else {
                return Some(1);
            };
            let d = (pair.r[0] + a0 * anchor.body) - (pair.r[1] + a1 * anchor.world);
            for (k, t) in tangents(&normal).iter().enumerate() {
                out[1 + k] = d.dot(&(a1 * t));
            }
            Some(3)
        }
    }
}

/// The coordinate a stop of `joint` bounds (its first), read on its branch; `None` if the
/// joint has none.
pub(crate) fn limit_angle(
    model: &Model,
    joint: JointId,
    q: &DVector<f64>,
    branches: &Branches,
) -> Option<f64> {
    let j = &model.joints[joint.0];
    let pair = pair_of(&j.bodies, q, false);
    // The value alone (bit for bit the jet's value, without its 14 derivatives): the guard
    // reads every idle stop's angle at every trial point of the line search.
    crate::kinematics::coordinate_value(j, &pair, 0, branches.get(joint, 0))
}

/// The gap of a stop at `value` on the `bound` side, the coordinate at `theta`.
pub(crate) fn limit_gap(theta: f64, bound: Bound, value: f64) -> f64 {
    match bound {
        Bound::Lower => theta - value,
        Bound::Upper => value - theta,
    }
}

/// `g(q)` (value only); `None` where a joint coordinate is undefined.
pub(crate) fn gap(
    model: &Model,
    u: &Unilateral,
    q: &DVector<f64>,
    branches: &Branches,
) -> Option<f64> {
    // Values only: no jets, no allocation (called for every inactive inequality at every
    // trial point of the line search).
    match *u {
        Unilateral::Limit {
            joint,
            bound,
            value,
        } => Some(limit_gap(
            limit_angle(model, joint, q, branches)?,
            bound,
            value,
        )),
        Unilateral::Contact { point, ground } => {
            let x = point_world(model, point, q);
            let (origin, normal) = surface(model, ground, &x);
            Some(normal.dot(&(x - origin)) - model.contact_points[point].radius)
        }
    }
}

#[cfg(test)]
#[path = "unilateral_tests.rs"]
mod tests;
