//! Detecting an energy that decreases without bound along a free direction.
//!
//! A mechanism whose potential falls linearly along a motion no force resists (a floating base
//! under gravity, a constant effort on a free continuous joint) has no rest pose; the minimizer
//! would step along it forever. Along such a motion the energy has zero curvature in the
//! natural coordinate (a length, an angle) while its slope does not vanish, so the rate at
//! which the energy falls per unit of motion,
//!
//! `ρ = −∇fᵀ d / ‖S⁻¹ δq‖₂`, `δq = Z d` the step in `q`, `S⁻¹` scaling positions by `1/ℓ`,
//!
//! is the same at every point (`m g` for a falling body, `2 τ` for a turning wheel: the Euler
//! parameters move by `δθ/2`, whatever the partition). The motion is declared unbounded when
//! [`UNBOUNDED_STEPS`] consecutive accepted steps show the same `ρ > 0` to a relative
//! [`RATE_TOLERANCE`] over a travel of at least [`UNBOUNDED_TRAVEL`]; on the way to a minimum `ρ ≈ ‖∇f‖` shrinks from step to step. A spring wound far from its rest passes the first test but not the
//! second: its rate changes by `δθ / (θ − θ_ref)` a step (`10⁻⁶` only at `θ − θ_ref` ≈ 3·10⁵
//! rad with the default step cap). A zero-curvature point of a bounded energy (a pendulum
//! passing the horizontal) fails it at the next step.
//!
//! Before iterating, [`falling`] finds what needs no iteration: a group of bodies that no
//! joint, spring, lock or possible contact connects to the world (a floating base with no
//! ground under it), pulled by a net constant force `F = Σ m_b g + Σ f_load ≠ 0`. Its energy
//! falls as `−|F| s` along `s = F̂ · r` without bound, so the solve reports `unbounded` at the
//! start, naming the bodies and the force. Likewise a group that rests only on frictionless
//! grounds while the pull has a component `F·t > 0` along a direction `t` that no ground
//! opposes (`n_g·t ≥ 0` for every ground `g`): it slides along `t` without bound (a robot on a
//! frictionless slope).

use crate::jet::{global_index, pair_of};
use crate::model::{JointId, Model};
use crate::state::State;
use nalgebra::DVector;

/// The report of a mechanism that [`falling`] finds unbounded before any iteration: the
/// assembled start with its energy, gradient and stability, `termination: unbounded` and the
/// falling groups as free directions; `None` if nothing falls.
///
/// # Errors
/// As [`super::solve_round`].
pub(crate) fn fall_at_start(
    model: &Model,
    start: &State,
    locks: &[(JointId, usize, f64)],
    options: &super::Options,
) -> crate::Result<Option<(State, super::Report)>> {
    let Some(directions) = falling(model, options) else {
        return Ok(None);
    };
    let options = super::Options {
        max_iterations: 0,
        ..options.clone()
    };
    let round = super::solve_round(model, start.clone(), locks, &[], None, None, &options)?;
    let mut report = round.report;
    report.termination = super::Termination::Unbounded;
    report.diagnostics.free_directions = directions;
    Ok(Some((round.state, report)))
}

/// Consecutive accepted steps at a constant energy rate that declare the energy unbounded.
pub(crate) const UNBOUNDED_STEPS: usize = 6;

/// Distance the run must cover, in the scaled coordinates (`ℓ` for positions, about 2 rad
/// for rotations): stagnating steps at a constant slope are not a descent without bound.
pub(crate) const UNBOUNDED_TRAVEL: f64 = 1.0;

/// Relative spread of the energy rate `ρ` allowed among those steps.
pub(crate) const RATE_TOLERANCE: f64 = 1e-6;

/// The run of steps at a constant rate of energy decrease.
#[derive(Default)]
pub(crate) struct LinearDescent {
    rate: f64,
    steps: usize,
    /// `Σ ‖S⁻¹ δq‖₂` over the run.
    travel: f64,
}

impl LinearDescent {
    /// Records an accepted step: `slope = ∇fᵀ d` and `dq = Z d` for the step `d` taken,
    /// `length` the length scale `ℓ`; returns whether the descent is now declared unbounded.
    pub(crate) fn record(&mut self, slope: f64, dq: &DVector<f64>, length: f64) -> bool {
        let norm = dq
            .iter()
            .enumerate()
            .map(|(i, x)| if i % 7 < 3 { x / length } else { *x })
            .map(|x| x * x)
            .sum::<f64>()
            .sqrt();
        let rate = -slope / norm.max(f64::MIN_POSITIVE);
        let same = (rate - self.rate).abs() <= RATE_TOLERANCE * rate.abs();
        if !(rate > 0.0 && rate.is_finite()) {
            self.steps = 0;
            self.travel = 0.0;
        } else if self.steps > 0 && same {
            self.steps += 1;
            self.travel += norm;
        } else {
            self.steps = 1;
            self.travel = norm;
        }
        self.rate = rate;
        self.steps >= UNBOUNDED_STEPS && self.travel >= UNBOUNDED_TRAVEL
    }
}

/// Names the motion `dq` (the last step of an unbounded descent): the joints whose
/// coordinates it changes, with the sign, and the translation and rotation directions of the
/// bodies that no joint connects to the world (a floating base).
pub(crate) fn free_directions(model: &Model, q: &DVector<f64>, dq: &DVector<f64>) -> Vec<String> {
    let mut out = Vec::new();
    let mut rates = Vec::new();
    for j in model.joints.iter().filter(|j| !j.merged) {
        let pair = pair_of(&j.bodies, q, false);
        for dof in 0..j.kind.scalar_coordinates() {
            if let Some(s) = crate::kinematics::coordinate(j, &pair, dof, 0.0) {
                let d: f64 = (0..crate::jet::NL)
                    .filter_map(|i| global_index(&j.bodies, i).map(|g| s.g[i] * dq[g]))
                    .sum();
                rates.push((format!("joint `{}` coordinate {dof}", j.name), d));
            }
        }
    }
    let big = rates.iter().fold(0.0f64, |a, r| a.max(r.1.abs()));
    for (name, d) in rates {
        if big > 0.0 && d.abs() > 1e-3 * big {
            let sense = if d > 0.0 { "increasing" } else { "decreasing" };
            out.push(format!("{name} {sense}"));
        }
    }
    // Bodies joined to the world through joints (breadth-first over the joint graph).
    let n = model.bodies.len();
    let mut next: Vec<Vec<usize>> = vec![Vec::new(); n];
    let mut attached = vec![false; n];
    let mut queue = Vec::new();
    for j in model
        .joints
        .iter()
        .filter(|j| !j.merged && j.kind != crate::model::JointKind::Floating)
    {
        match (j.bodies[0], j.bodies[1]) {
            (Some(a), Some(b)) => {
                next[a.0].push(b.0);
                next[b.0].push(a.0);
            }
            (Some(a), None) | (None, Some(a)) => queue.push(a.0),
            (None, None) => {}
        }
    }
    while let Some(b) = queue.pop() {
        if !std::mem::replace(&mut attached[b], true) {
            queue.extend(next[b].iter().copied());
        }
    }
    for (b, body) in model.bodies.iter().enumerate() {
        if attached[b] {
            continue;
        }
        let t = dq.fixed_rows::<3>(7 * b);
        let tn = t.norm();
        if tn > 1e-12 {
            out.push(format!(
                "body `{}` translating along ({:.3}, {:.3}, {:.3})",
                body.name,
                shown(t[0] / tn),
                shown(t[1] / tn),
                shown(t[2] / tn)
            ));
        }
    }
    out
}

/// The groups of bodies that nothing holds while a net constant force pulls them (module
/// docs): one free direction per group, with the reason, or `None` if every group is held or
/// balanced.
///
/// A group is held if a non-floating joint, a spring, or a lock, mimic or joint spring on a
/// floating joint connects it to the world, or if it has contact points and the model has a
/// ground or an obstacle below which they might come to rest (a ground whose normal points
/// along the pull cannot hold it: the group falls away from it).
pub(crate) fn falling(model: &Model, options: &super::Options) -> Option<Vec<String>> {
    let n = model.bodies.len();
    let (mut parent, world) = groups(model);
    // Net constant force per group.
    let mut force = vec![nalgebra::Vector3::zeros(); n + 1];
    let mut members = vec![Vec::new(); n + 1];
    for (b, body) in model.bodies.iter().enumerate() {
        let r = find(&mut parent, b);
        force[r] += model.gravity * body.gravity_mass;
        members[r].push(b);
    }
    for l in &model.loads {
        let r = find(&mut parent, l.body.0);
        force[r] += l.force;
    }
    let scale = super::active_set::force_scale(model);
    let mut out = Vec::new();
    for r in 0..n {
        if r == world || members[r].is_empty() {
            continue;
        }
        let f = force[r];
        if f.norm() <= 1e-9 * scale {
            continue;
        }
        let dir = f / f.norm();
        let touches = model
            .contact_points
            .iter()
            .any(|c| find(&mut parent, c.body.0) == r);
        let support =
            !model.obstacles.is_empty() || model.grounds.iter().any(|g| g.normal.dot(&dir) < 0.0);
        if touches && support {
            // Resting on frictionless grounds only: a rigid translation along `t` with
            // `n_g·t ≥ 0` for every ground keeps every gap open and lowers the energy by
            // `F·t` per metre.
            let frictionless = model.obstacles.is_empty()
                && model
                    .contact_points
                    .iter()
                    .filter(|c| find(&mut parent, c.body.0) == r)
                    .all(|c| {
                        c.settings.friction.unwrap_or(options.friction)
                            == crate::model::Friction::None
                    });
            if let Some(t) = frictionless.then(|| slide(model, &f)).flatten() {
                if f.dot(&t) > 1e-9 * scale {
                    out.push(format!(
                        "body `{}` sliding along ({:.3}, {:.3}, {:.3}) (its contacts are frictionless and no ground stops it; gravity and loads pull it with {:.4} N along the ground)",
                        model.bodies[members[r][0]].name,
                        shown(t.x),
                        shown(t.y),
                        shown(t.z),
                        f.dot(&t)
                    ));
                }
            }
            continue;
        }
        let why = if model.grounds.is_empty() && model.obstacles.is_empty() {
            "no joint or spring holds it and there is no ground"
        } else if !touches {
            "no joint or spring holds it and it has no contact points"
        } else {
            "no joint or spring holds it and no ground is below it"
        };
        out.push(format!(
            "body `{}` translating along ({:.3}, {:.3}, {:.3}) ({why}; gravity and loads pull it with {:.4} N)",
            model.bodies[members[r][0]].name,
            shown(dir.x),
            shown(dir.y),
            shown(dir.z),
            f.norm()
        ));
    }
    (!out.is_empty()).then_some(out)
}

/// The unit direction `t` maximizing `f·t` subject to `n_g·t ≥ 0` for every ground (a cone
/// in 3-D: its best direction is `f` itself, `f` projected on one ground plane, or the line
/// where two planes meet), if one with `f·t > 0` exists.
fn slide(model: &Model, f: &nalgebra::Vector3<f64>) -> Option<nalgebra::Vector3<f64>> {
    let normals: Vec<_> = model.grounds.iter().map(|g| g.normal).collect();
    let mut candidates = vec![*f];
    for n in &normals {
        candidates.push(f - n * n.dot(f));
    }
    for (i, a) in normals.iter().enumerate() {
        for b in &normals[i + 1..] {
            let l = a.cross(b);
            candidates.push(l * l.dot(f).signum());
        }
    }
    candidates
        .into_iter()
        .filter(|t| t.norm() > 1e-12 * f.norm())
        .map(|t| t.normalize())
        .filter(|t| normals.iter().all(|n| n.dot(t) >= -1e-12))
        .max_by(|a, b| a.dot(f).total_cmp(&b.dot(f)))
        .filter(|t| t.dot(f) > 0.0)
}

/// Union-find root of `i` in `p`.
fn find(p: &mut [usize], mut i: usize) -> usize {
    while p[i] != i {
        p[i] = p[p[i]];
        i = p[i];
    }
    i
}

/// The groups of bodies joined by joints and springs (union-find parents over the bodies,
/// index `bodies.len()` the world), with the world's root. A floating joint joins nothing
/// unless a lock, mimic or joint spring acts on it.
pub(crate) fn groups(model: &Model) -> (Vec<usize>, usize) {
    let n = model.bodies.len();
    let mut parent: Vec<usize> = (0..=n).collect();
    let join =
        |p: &mut Vec<usize>, a: Option<crate::model::BodyId>, b: Option<crate::model::BodyId>| {
            let (a, b) = (a.map_or(n, |x| x.0), b.map_or(n, |x| x.0));
            let (ra, rb) = (find(p, a), find(p, b));
            p[ra] = rb;
        };
    let held_joint = |id: usize| {
        model.locks.iter().any(|l| l.joint.0 == id)
            || model.joint_springs.iter().any(|s| s.joint.0 == id)
            || model
                .mimics
                .iter()
                .any(|m| m.joint.0 == id || m.reference.0 == id)
    };
    for (id, j) in model.joints.iter().enumerate().filter(|(_, j)| !j.merged) {
        if j.kind != crate::model::JointKind::Floating || held_joint(id) {
            join(&mut parent, j.bodies[0], j.bodies[1]);
        }
    }
    for s in &model.springs {
        join(&mut parent, s.ends[0].body, s.ends[1].body);
    }
    for b in 0..=n {
        parent[b] = find(&mut parent, b);
    }
    let world = find(&mut parent, n);
    (parent, world)
}

/// `x` rounded to the 3 decimals shown, without a sign on zero (no "-0.000").
fn shown(x: f64) -> f64 {
    (x * 1000.0).round() / 1000.0 + 0.0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_constant_rate_is_declared_after_the_set_number_of_steps() {
        let dq = DVector::from_vec(vec![0.0, 0.0, -0.3, 0.0, 0.0, 0.0, 0.0]);
        let tiny = &dq * 1e-9;
        let mut run = LinearDescent::default();
        for k in 1..UNBOUNDED_STEPS {
            assert!(!run.record(-5.886, &dq, 1.0), "step {k}");
        }
        assert!(run.record(-5.886, &dq, 1.0));
        // A rate that falls off (a spring nearing its rest) never is.
        let mut run = LinearDescent::default();
        for k in 0..50 {
            assert!(!run.record(-5.886 * (1.0 - 1e-4 * k as f64), &dq, 1.0));
        }
        // Nor are stagnating tiny steps.
        let mut run = LinearDescent::default();
        for _ in 0..50 {
            assert!(!run.record(-5.886e-9, &tiny, 1.0));
        }
        // Nor is an ascent.
        let mut run = LinearDescent::default();
        for _ in 0..50 {
            assert!(!run.record(5.886, &dq, 1.0));
        }
    }
}
