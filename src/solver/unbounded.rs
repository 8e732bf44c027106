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

use crate::jet::{global_index, pair_of};
use crate::model::Model;
use nalgebra::DVector;

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
