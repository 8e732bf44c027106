//! A rigid topple at the ground start: a floating group whose centre of mass is not over its
//! support turns over the support's edge onto the next point it lands on, until it is.
//!
//! The ground start (module `assemble`) sets each floating group (bodies that no joint holds
//! to the world) on the ground as it is. With one ground plane `n·(x − o) = 0` facing against
//! gravity `g` and sticking contacts, the group stands there if the projection along gravity
//! of its centre of mass `c = Σ m_b c_b / Σ m_b` onto the plane,
//! `c' = c − (n·(c − o) / n·ĝ) ĝ`, lies in (or on, within `ε`) the support polygon: the convex
//! hull of the touching points `s_k = x_k − ρ_k n` of its contact points (centre `x_k`, radius
//! `ρ_k`) whose gap `h_k = n·(x_k − o) − ρ_k` is at most `ε = 10⁻⁹ D` (`D` the diagonal of the
//! box around the group's contact points, at least the characteristic length). A group whose
//! `c'` is outside that polygon but inside the hull of its points within `δ = 10⁻² D` of the
//! ground is left to the solve: the joints' settling (servos deflecting, a sole not quite
//! flat) brings those points down (the corpora's standing robots need `δ` of 3.6·10⁻⁵ D (Go2)
//! to 1.7·10⁻⁴ D (iCub), Bolt 0.25 D). Otherwise it topples, joints at their start values, all
//! its bodies turned by one rotation per step, until `c'` is over the polygon of the points on
//! the ground:
//!
//! - the pivot `p` is the point of the support polygon nearest to `c'` (on an edge: that edge's
//!   line; at a corner or a single point: the point), `d̂ = (c' − p)/|c' − p|`, and the group
//!   turns about the axis `a = n × d̂` through `p + ρ_p n` (`ρ_p` the radius shared by the
//!   contact points on the pivot: 0 for mesh vertices and box corners; a sphere rolls, its
//!   centre moving by `ρ_p θ (a × n)`, on a level ground only), which lowers `c`:
//!   `dV/dθ = m |g| |c' − p| (n·ĝ) < 0`;
//! - each other contact point's gap is, with `r = x_k − p − ρ_p n` and `r⊥ = r − (a·r) a`,
//!   `h_k(θ) = ρ_p − ρ_k + n·r⊥ cos θ + n·(a × r⊥) sin θ`, and the group turns by the smallest
//!   `θ ∈ (0, π]` at which one of them reaches the ground descending (a closed form per
//!   point, `O(points)` a step), or by the angle at which `c` is lowest, `φ + π` with
//!   `u·r⊥_c cos θ + u·(a × r⊥_c) sin θ = R cos(θ − φ)` (`u = −ĝ`), if that comes first (the
//!   group then hangs from its pivot);
//! - the support is then the set of points on the ground, and the next step starts there.
//!
//! The gravity energy falls at every step (the height of `c` is `R cos(θ − φ)`, decreasing on
//! `(0, φ + π)`), and the joints' energy (springs, servos) does not change, so the start the
//! solve gets is lower than the ground start's. Groups with loads (whose energy is not that of
//! their centre of mass), with frictionless contact points (which slide rather than pivot:
//! left as they were), or on a model with several grounds or obstacles are left as they were.
//! The turn is exact as a quasi-static path only for a rigid group on sticking contacts: a
//! compliant one deflects on the way, which the solve from the toppled pose then finds. At most
//! [`MAX_STEPS`] steps; if met, the group is left where the last step put it and the report
//! says so.

use super::options::Options;
use crate::model::Model;
use nalgebra::{DVector, Vector2, Vector3, Vector4};

/// Steps of one group's topple at most.
pub(crate) const MAX_STEPS: usize = 10_000;

/// The support tolerance `ε` relative to the group's size `D` (module docs).
const SUPPORT_TOLERANCE: f64 = 1e-9;

/// The settling height `δ` relative to the group's size `D` (module docs).
const SETTLING: f64 = 1e-2;

/// A floating group that could not stand on its ground start and toppled (module
/// `solver::topple`).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Toppled {
    /// The group's first body (the floating base's link).
    pub body: String,
    /// Turns over a support edge or point, each ending where a point lands.
    pub steps: usize,
    /// Angle of the group's net rotation from the ground start to the toppled pose \[rad\].
    pub angle: f64,
    /// Links whose contact points touched the ground at the start, in model order.
    pub support_before: Vec<String>,
    /// Links whose contact points touch the ground after the topple, in model order.
    pub support_after: Vec<String>,
    /// Distance of the centre of mass's projection along gravity outside the start support
    /// polygon \[m\].
    pub com_outside: f64,
    /// Gravity energy the topple released, `V(start) − V(toppled)` \[J\].
    pub energy_released: f64,
    /// Why the topple stopped before the centre of mass was over the support, if it did.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stopped: Option<String>,
}

impl Toppled {
    /// The summary's line: what could not stand, how far it turned, onto what.
    pub fn describe(&self) -> String {
        format!(
            "toppled at the start: `{}` cannot stand on {} (centre of mass {:.6} m outside); \
             turned {:.6} rad in {} steps onto {}, {:.6} J lower{}",
            self.body,
            self.support_before.join(", "),
            self.com_outside,
            self.angle,
            self.steps,
            self.support_after.join(", "),
            self.energy_released,
            self.stopped
                .as_ref()
                .map_or(String::new(), |s| format!(" ({s})"))
        )
    }
}

/// One group's topple: the report and the gravity energy after each step (the first entry
/// the start's).
pub(crate) struct Path {
    pub(crate) toppled: Toppled,
    #[cfg_attr(
        not(test),
        expect(dead_code, reason = "the unit tests check the descent")
    )]
    pub(crate) energies: Vec<f64>,
}

/// Topples every floating group of a ground start that cannot stand (module docs) in `q`.
pub(crate) fn topple(model: &Model, q: &mut DVector<f64>, options: &Options) -> Vec<Toppled> {
    paths(model, q, options)
        .into_iter()
        .map(|p| p.toppled)
        .collect()
}

/// [`topple`], with the energies of each step.
pub(crate) fn paths(model: &Model, q: &mut DVector<f64>, options: &Options) -> Vec<Path> {
    let mut out = Vec::new();
    if options.topple == super::options::Topple::Off
        || model.grounds.len() != 1
        || !model.obstacles.is_empty()
        || model.gravity.norm() == 0.0
    {
        return out;
    }
    let ground = &model.grounds[0];
    let down = model.gravity.normalize();
    if ground.normal.dot(&down) >= -1e-9 {
        return out;
    }
    let (root, world) = super::unbounded::groups(model);
    let policy = options.contact();
    let mut roots: Vec<usize> = (0..model.bodies.len())
        .map(|b| root[b])
        .filter(|&r| r != world)
        .collect();
    roots.sort_unstable();
    roots.dedup();
    for r in roots {
        let bodies: Vec<usize> = (0..model.bodies.len()).filter(|&b| root[b] == r).collect();
        let points: Vec<usize> = (0..model.contact_points.len())
            .filter(|&k| root[model.contact_points[k].body.0] == r)
            .collect();
        let loaded = model.loads.iter().any(|l| root[l.body.0] == r);
        let sliding = points
            .iter()
            .any(|&k| !policy.sticks(&model.contact_points[k].settings));
        let mass: f64 = bodies.iter().map(|&b| model.bodies[b].gravity_mass).sum();
        if points.is_empty() || loaded || sliding || mass <= 0.0 {
            continue;
        }
        let group = Group {
            model,
            bodies,
            points,
            normal: ground.normal,
            origin: ground.origin,
            down,
            mass,
        };
        if let Some(path) = group.topple(q) {
            out.push(path);
        }
    }
    out
}

/// A floating group on the ground.
struct Group<'m> {
    model: &'m Model,
    bodies: Vec<usize>,
    points: Vec<usize>,
    /// The ground's normal `n` and a point `o` of it.
    normal: Vector3<f64>,
    origin: Vector3<f64>,
    /// `ĝ`.
    down: Vector3<f64>,
    /// Mass subject to gravity \[kg\].
    mass: f64,
}

impl Group<'_> {
    /// The centre of the mass subject to gravity.
    fn com(&self, q: &DVector<f64>) -> Vector3<f64> {
        let mut c = Vector3::zeros();
        for &b in &self.bodies {
            let body = &self.model.bodies[b];
            let (r, p) = pose(q, b);
            c += (r + crate::math::rotation(&p) * body.gravity_com) * body.gravity_mass;
        }
        c / self.mass
    }

    /// Gravity energy `−m g·c` \[J\].
    fn energy(&self, q: &DVector<f64>) -> f64 {
        -self.mass * self.model.gravity.dot(&self.com(q))
    }

    /// The centres of the contact points and their gaps.
    fn gaps(&self, q: &DVector<f64>) -> Vec<(Vector3<f64>, f64)> {
        let mut body = usize::MAX;
        let (mut r, mut rotation) = (Vector3::zeros(), nalgebra::Matrix3::identity());
        self.points
            .iter()
            .map(|&k| {
                let c = &self.model.contact_points[k];
                if c.body.0 != body {
                    body = c.body.0;
                    let (position, p) = pose(q, body);
                    (r, rotation) = (position, crate::math::rotation(&p));
                }
                let x = r + rotation * c.point;
                (x, self.normal.dot(&(x - self.origin)) - c.radius)
            })
            .collect()
    }

    /// Links of the points `chosen` (indices into `self.points`), in model order.
    fn links(&self, chosen: &[usize]) -> Vec<String> {
        let mut names: Vec<&str> = Vec::new();
        for link in self.model.links.iter() {
            if chosen
                .iter()
                .any(|&i| self.model.contact_points[self.points[i]].link == link.name)
                && !names.contains(&link.name.as_str())
            {
                names.push(&link.name);
            }
        }
        names.into_iter().map(str::to_owned).collect()
    }

    /// Topples the group in `q` (module docs); `None` if it stands or is not on the ground.
    fn topple(&self, q: &mut DVector<f64>) -> Option<Path> {
        let n = self.normal;
        let saved = q.clone();
        let start = self.gaps(q);
        let (lo, hi) = start.iter().fold(
            (
                Vector3::repeat(f64::INFINITY),
                Vector3::repeat(f64::NEG_INFINITY),
            ),
            |(lo, hi), (x, _)| (lo.inf(x), hi.sup(x)),
        );
        let size = (hi - lo).norm().max(self.model.length_scale);
        let eps = SUPPORT_TOLERANCE * size;
        let lowest = start.iter().map(|s| s.1).fold(f64::INFINITY, f64::min);
        if lowest.abs() > eps {
            return None;
        }
        // A right-handed basis of the plane.
        let e1 = if n.x.abs() < 0.9 {
            Vector3::x().cross(&n).normalize()
        } else {
            Vector3::y().cross(&n).normalize()
        };
        let e2 = n.cross(&e1);
        let flat =
            |x: &Vector3<f64>| Vector2::new((x - self.origin).dot(&e1), (x - self.origin).dot(&e2));
        let lift = |p: &Vector2<f64>| self.origin + e1 * p.x + e2 * p.y;
        let p0 = pose(q, self.bodies[0]).1;
        let mut energies = vec![self.energy(q)];
        let mut before = None;
        let mut outside = 0.0;
        let mut stopped = None;
        let mut steps = 0;
        loop {
            let gaps = self.gaps(q);
            let support: Vec<usize> = (0..gaps.len()).filter(|&i| gaps[i].1 <= eps).collect();
            let touching: Vec<Vector2<f64>> = support
                .iter()
                .map(|&i| flat(&(gaps[i].0 - n * self.model.contact_points[self.points[i]].radius)))
                .collect();
            let c = self.com(q);
            let projection = c - self.down * (n.dot(&(c - self.origin)) / n.dot(&self.down));
            let c2 = flat(&projection);
            let hull = super::balance::convex_hull(touching);
            let margin = super::balance::signed_distance(&hull, &c2);
            if before.is_none() {
                // The hull of the points within `δ` of the ground: the support the solve's
                // settling can reach.
                let near: Vec<Vector2<f64>> = (0..gaps.len())
                    .filter(|&i| gaps[i].1 <= SETTLING * size)
                    .map(|i| {
                        flat(&(gaps[i].0 - n * self.model.contact_points[self.points[i]].radius))
                    })
                    .collect();
                let hull = super::balance::convex_hull(near);
                if super::balance::signed_distance(&hull, &c2) >= -eps {
                    return None;
                }
                before = Some(self.links(&support));
                outside = -margin;
            }
            if margin >= -eps {
                break;
            }
            if steps == MAX_STEPS {
                stopped = Some(format!(
                    "stopped after {MAX_STEPS} steps with the centre of mass {:.6} m outside its support",
                    -margin
                ));
                break;
            }
            let p = lift(&nearest(&hull, &c2));
            let d = (lift(&c2) - p).normalize();
            let a = n.cross(&d);
            // The pivot: support points on the axis through `p` along `a`.
            let on_axis = |x: &Vector3<f64>| {
                let r = x - p;
                (r - a * a.dot(&r)).norm() <= eps
            };
            let radius = |i: usize| self.model.contact_points[self.points[i]].radius;
            let pivot: Vec<usize> = support
                .iter()
                .copied()
                .filter(|&i| on_axis(&(gaps[i].0 - n * radius(i))))
                .collect();
            let rho = pivot.first().map_or(0.0, |&i| radius(i));
            if pivot.iter().any(|&i| (radius(i) - rho).abs() > eps) {
                stopped = Some(format!(
                    "the pivot joins contact spheres of different radii ({:.6} m and {:.6} m): \
                     the group cannot roll on them as one",
                    rho,
                    pivot.iter().map(|&i| radius(i)).fold(rho, f64::max)
                ));
                break;
            }
            if rho > 0.0 && n.dot(&self.down) > -1.0 + 1e-12 {
                stopped = Some(format!(
                    "the pivot is a contact sphere (radius {rho:.6} m) on a ground that is not \
                     level: rolling it would move the centre of mass along the slope too"
                ));
                break;
            }
            let centre = p + n * rho;
            // The angle at which the centre of mass is lowest.
            let (ac, bc) = components(&(c - centre), &a, &-self.down);
            let mut angle = (bc.atan2(ac) + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU);
            for (i, (x, _)) in gaps.iter().enumerate() {
                if pivot.contains(&i) {
                    continue;
                }
                let (ak, bk) = components(&(x - centre), &a, &n);
                if let Some(t) = landing(rho - radius(i), ak, bk) {
                    angle = angle.min(t);
                }
            }
            if !(angle > 0.0 && angle.is_finite()) {
                stopped = Some(format!(
                    "no turn about the pivot at [{:.6}, {:.6}, {:.6}] lowers the centre of mass",
                    p.x, p.y, p.z
                ));
                break;
            }
            self.turn(q, &a, &centre, angle, a.cross(&n) * (rho * angle));
            steps += 1;
            energies.push(self.energy(q));
        }
        // A group whose numbers overflow on the way (a mass or a coordinate near the largest
        // float) is left as placed: the topple never hands the solve a non-finite start.
        let finite = |i: &usize| (7 * i..7 * i + 7).all(|k| q[k].is_finite());
        let numbers = energies.iter().chain([&outside]);
        if !(self.bodies.iter().all(finite) && numbers.into_iter().all(|e| e.is_finite())) {
            *q = saved;
            return None;
        }
        let after = {
            let gaps = self.gaps(q);
            let support: Vec<usize> = (0..gaps.len()).filter(|&i| gaps[i].1 <= eps).collect();
            self.links(&support)
        };
        // The net rotation: the first body's orientation now relative to its start.
        let p1 = pose(q, self.bodies[0]).1;
        let relative = crate::math::compose(&p1, &Vector4::new(p0[0], -p0[1], -p0[2], -p0[3]));
        let half = Vector3::new(relative[1], relative[2], relative[3]).norm();
        let angle = 2.0 * half.atan2(relative[0].abs());
        Some(Path {
            toppled: Toppled {
                body: self.model.bodies[self.bodies[0]].name.clone(),
                steps,
                angle,
                support_before: before.unwrap_or_default(),
                support_after: after,
                com_outside: outside,
                energy_released: energies[0] - energies[energies.len() - 1],
                stopped,
            },
            energies,
        })
    }

    /// Turns the group by `angle` about the axis `a` through `centre`, then moves it by `shift`.
    fn turn(
        &self,
        q: &mut DVector<f64>,
        a: &Vector3<f64>,
        centre: &Vector3<f64>,
        angle: f64,
        shift: Vector3<f64>,
    ) {
        let (s, c) = (0.5 * angle).sin_cos();
        let turn = Vector4::new(c, a.x * s, a.y * s, a.z * s);
        let rotation = crate::math::rotation(&turn);
        for &b in &self.bodies {
            let (r, p) = pose(q, b);
            let r = centre + rotation * (r - centre) + shift;
            let p = crate::math::compose(&turn, &p);
            let i = 7 * b;
            for k in 0..3 {
                q[i + k] = r[k];
            }
            for k in 0..4 {
                q[i + 3 + k] = p[k];
            }
        }
    }
}

/// Position and Euler parameters of body `b` in `q`.
fn pose(q: &DVector<f64>, b: usize) -> (Vector3<f64>, Vector4<f64>) {
    let i = 7 * b;
    (
        Vector3::new(q[i], q[i + 1], q[i + 2]),
        Vector4::new(q[i + 3], q[i + 4], q[i + 5], q[i + 6]),
    )
}

/// `(u·r⊥, u·(a × r⊥))`: the height along `u` of the point `r` (from a point of the axis `a`)
/// turned by `θ` about `a` is `u·r∥ + u·r⊥ cos θ + u·(a × r⊥) sin θ`.
fn components(r: &Vector3<f64>, a: &Vector3<f64>, u: &Vector3<f64>) -> (f64, f64) {
    let perp = r - a * a.dot(r);
    (u.dot(&perp), u.dot(&a.cross(&perp)))
}

/// The smallest `θ ∈ (0, π]` at which `h(θ) = h0 + A cos θ + B sin θ` reaches 0 descending
/// (`h′(θ) < 0`), if any.
fn landing(h0: f64, a: f64, b: f64) -> Option<f64> {
    let r = a.hypot(b);
    if r == 0.0 || h0.abs() > r {
        return None;
    }
    let phi = b.atan2(a);
    let spread = (-h0 / r).clamp(-1.0, 1.0).acos();
    [phi + spread, phi - spread]
        .into_iter()
        .map(|t| t.rem_euclid(std::f64::consts::TAU))
        .filter(|&t| t > 0.0 && t <= std::f64::consts::PI && -a * t.sin() + b * t.cos() < 0.0)
        .min_by(f64::total_cmp)
}

/// The point of the convex polygon `hull` (counter-clockwise; one or two points for a
/// degenerate one) nearest to `p`, a point outside it.
fn nearest(hull: &[Vector2<f64>], p: &Vector2<f64>) -> Vector2<f64> {
    let on_segment = |a: &Vector2<f64>, b: &Vector2<f64>| {
        let d = b - a;
        let t = if d.norm_squared() > 0.0 {
            ((p - a).dot(&d) / d.norm_squared()).clamp(0.0, 1.0)
        } else {
            0.0
        };
        a + d * t
    };
    match hull.len() {
        0 => *p,
        1 => hull[0],
        n => (0..n)
            .map(|i| on_segment(&hull[i], &hull[(i + 1) % n]))
            .min_by(|x, y| (x - p).norm_squared().total_cmp(&(y - p).norm_squared()))
            .unwrap_or(*p),
    }
}

#[cfg(test)]
#[path = "topple_tests.rs"]
mod tests;
