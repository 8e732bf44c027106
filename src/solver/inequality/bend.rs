//! The projected (bent) search path of the joint stops, `Options::stop_search =
//! StopSearch::Projected` (the default; `StopSearch::Cut` cuts the step at the first stop,
//! module `guard`): along
//! the retraction (module `step::retraction`) a tree joint's coordinate moves linearly, `θ(α) = θ + α θ̇`, so an inactive
//! stop `g(θ) ≥ 0` is reached at `α_k = −g(θ)/ġ` (`ġ < 0`). The trial point at `α` holds each
//! such joint at its stop beyond `α_k`,
//!
//! `θ_j(α) = θ_j + min(α, α_k) θ̇_j`,
//!
//! the projection of the path onto the stop interval, and its children move on: a step that
//! reaches several stops takes them all at once, and every stop within the tolerance of its
//! boundary at the accepted point joins the active set for the next round (the release rule
//! decides later whether it leaves). The descent test is Armijo's along the bent path,
//! `f(t) ≤ f + 10⁻⁴ ∇fᵀ Δv̂` with `Δv̂` the change of the scaled independent coordinates
//! actually taken (Bertsekas' projected Armijo rule).
//!
//! Where the bend does not hold (a joint on a loop, a mimic or contact row that the corrector
//! moves it off its stop again), the stop is not at its boundary after the correction: a
//! violation falls to the guard's cut (module `guard`), as without the bend.
//!
//! The rest of Bertsekas' projected Newton method is restpose's as it is: the stops held are
//! the active rows whose multipliers push (module `release` lets the pulling ones leave
//! before a round is stationary), the Newton step is the reduced one with those rows held
//! (with the valley and escape steps of modules `valley` and `step::escape`), and the step is
//! limited per joint (module `step::step_cap`). Why it is the default, measured against the
//! quasi-static release: docs/method.md, "Meeting several stops in one step".
//!
//! ## References
//! - D. P. Bertsekas, "Projected Newton methods for optimization problems with simple
//!   constraints", *SIAM J. Control Optim.* 20 (1982) 221–246.
//! - J. J. Moré, G. Toraldo, "Algorithms for bound constrained quadratic programming problems",
//!   *Numer. Math.* 55 (1989) 377–400.

use super::active_set::{dimensionless, Guard};
use crate::constraints::unilateral::{self, Unilateral};
use crate::kinematics::Branches;
use crate::model::{JointId, Model};
use crate::solver::step::retraction::angular_velocity;
use crate::solver::system::System;
use nalgebra::{DVector, Vector3};

/// An inactive stop the path reaches: the guard's index `k`, the body its joint moves, `α_k`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Stop {
    pub(crate) k: usize,
    pub(crate) body: usize,
    pub(crate) alpha: f64,
}

/// Step along which the joint rates are read (the coordinates are linear along the path).
const PROBE: f64 = 1e-3;

impl Guard<'_> {
    /// The inactive stops of tree joints that the path from `q` along `dq` closes before the
    /// step length `alpha_max`, with the step length at which each is reached. Stops within
    /// the tolerance at the start (rows just released) are left to the guard.
    ///
    /// Each joint's angle is read once for its two stops, and a stop the path cannot reach
    /// before `alpha_max` ([`Reading::unreachable`]) costs no probe: the line search only
    /// ever bends at stops with `α_k < α ≤ alpha_max`, so the list is the full one's without
    /// entries it would never read (`alpha_max = ∞`: the full list).
    pub(crate) fn stops(
        &self,
        sys: &System,
        q: &DVector<f64>,
        dq: &DVector<f64>,
        alpha_max: f64,
    ) -> Vec<Stop> {
        self.stops_from(sys, q, dq, alpha_max, false)
    }

    /// [`Guard::stops`], and where `at_boundary`, the stops within the tolerance at `q` that
    /// the path closes, held from `α = 0`.
    pub(crate) fn stops_from(
        &self,
        sys: &System,
        q: &DVector<f64>,
        dq: &DVector<f64>,
        alpha_max: f64,
        at_boundary: bool,
    ) -> Vec<Stop> {
        let model = sys.problem.model;
        let branches = &sys.problem.cons.branches;
        let ret = &sys.problem.retraction;
        let mut probe = None;
        let mut out = Vec::new();
        let mut last: Option<(JointId, Option<Reading>)> = None;
        // Every body's angular velocity along `dq` (a parent's is read by each child joint).
        let mut omega = None;
        for (k, u) in self.inactive.iter().enumerate() {
            let Unilateral::Limit {
                joint,
                bound,
                value,
            } = *u
            else {
                continue;
            };
            let Some(body) = ret.body_of(joint.0) else {
                continue;
            };
            let reading = match last {
                Some((j, r)) if j == joint => r,
                _ => Reading::at(model, joint, q, branches, || {
                    omega
                        .get_or_insert_with(|| angular_velocities(q, dq))
                        .as_slice()
                }),
            };
            last = Some((joint, reading));
            // (Where the angle is undefined the gap is infinite and the probe reads none.)
            let Some(reading) = reading else {
                continue;
            };
            let g0 = unilateral::limit_gap(reading.theta, bound, value);
            let touching = dimensionless(model, u, g0) <= self.tol;
            if touching && !at_boundary {
                continue;
            }
            if !touching && reading.unreachable(g0, value, alpha_max) {
                continue;
            }
            let qp = probe.get_or_insert_with(|| ret.point(q, dq, PROBE));
            let Some(t1) = unilateral::limit_angle(model, joint, qp, branches) else {
                continue;
            };
            let rate = (unilateral::limit_gap(t1, bound, value) - g0) / PROBE;
            if rate < 0.0 && g0 > 0.0 && !touching {
                out.push(Stop {
                    k,
                    body,
                    alpha: -g0 / rate,
                });
            } else if rate < 0.0 && touching {
                out.push(Stop {
                    k,
                    body,
                    alpha: 0.0,
                });
            }
        }
        out
    }

    /// The stops of `caps` at their boundary (within the tolerance) at the trial point `qt`.
    pub(crate) fn reached(&self, sys: &System, caps: &[Stop], qt: &DVector<f64>) -> Vec<usize> {
        let branches = &sys.problem.cons.branches;
        caps.iter()
            .filter(|s| self.gap(s.k, qt, branches).abs() <= self.tol)
            .map(|s| s.k)
            .collect()
    }
}

/// Every body's world angular velocity along the tangent `dq` at `q`.
fn angular_velocities(q: &DVector<f64>, dq: &DVector<f64>) -> Vec<Vector3<f64>> {
    (0..q.len() / 7)
        .map(|b| angular_velocity(q, dq, b))
        .collect()
}

/// A limited joint's coordinate at the start of a step, as the stop search reads it.
#[derive(Clone, Copy, Debug)]
struct Reading {
    /// The coordinate, bit for bit [`unilateral::limit_angle`].
    theta: f64,
    /// The branch it is read on.
    reference: f64,
    /// For an angle read as `atan2(y₀·x₁, x₀·x₁)`: `R = |ω_r| / (ρ − PROBE |ω_r|)`, `ρ` of
    /// [`crate::kinematics::angle_value_and_spread`] (`None` where `x₁` lies near the axis:
    /// `ρ < 0.1`, or the probe could bring it there).
    rate: Option<f64>,
}

impl Reading {
    /// The coordinate of `joint` at `q` (`None` where it is undefined), and for an angle
    /// the bound of its rate along the tangent whose body angular velocities `omega` gives
    /// ([`Reading::unreachable`]).
    fn at<'w>(
        model: &Model,
        joint: JointId,
        q: &DVector<f64>,
        branches: &Branches,
        omega: impl FnOnce() -> &'w [Vector3<f64>],
    ) -> Option<Self> {
        let j = &model.joints[joint.0];
        let reference = branches.get(joint, 0);
        let pair = crate::jet::pair_of(&j.bodies, q, false);
        if let (Some(child), Some((theta, rho))) = (
            j.bodies[1],
            crate::kinematics::angle_value_and_spread(j, &pair, reference),
        ) {
            let omega = omega();
            let wa = j.bodies[0].map_or_else(Vector3::zeros, |a| omega[a.0]);
            let w = (omega[child.0] - wa).norm();
            let room = rho - PROBE * w;
            return Some(Reading {
                theta,
                reference,
                rate: (room >= 0.5 * rho && rho >= 0.1).then(|| w / room),
            });
        }
        Some(Reading {
            theta: unilateral::limit_angle(model, joint, q, branches)?,
            reference,
            rate: None,
        })
    }

    /// Whether a stop at `value` whose gap is `g0 > 0` at the start is certainly reached, if
    /// at all, at no `α_k` below `alpha_max` (so the probe may be skipped).
    ///
    /// Along the retraction the child's `x₁` turns relative to the parent's frame by the
    /// rotation `R(α ω_r)`, `ω_r = ω_b − ω_a` (module `step::retraction`; the parent's own
    /// motion turns both frames alike), so the angle `atan2(y₀·x₁, x₀·x₁)` changes at a rate of
    /// at most `|ω_r| / ρ(α)` with `ρ(α) ≥ ρ(0) − α |ω_r|`: over the probe `[0, PROBE]` the
    /// probe's difference quotient is at most `R = |ω_r| / (ρ(0) − PROBE |ω_r|)` in magnitude
    /// (plus its rounding), and `α_k = g0 / |rate| ≥ g0 / R`. Not where the probe could cross
    /// the branch cut at `θ_b ± π` (its difference quotient would then be `±2π / PROBE`), nor
    /// where `x₁` lies near the joint axis.
    fn unreachable(&self, g0: f64, value: f64, alpha_max: f64) -> bool {
        let Some(rate) = self.rate else {
            return false;
        };
        let centre = if self.reference.is_finite() {
            self.reference
        } else {
            0.0
        };
        // The rounding of the probe's difference quotient (two readings on the branch and
        // two gaps), far above its few units in the last place.
        let size = self.theta.abs() + centre.abs() + value.abs() + 8.0;
        let rate = rate * (1.0 + 1e-6) + 1e3 * f64::EPSILON * size / PROBE;
        let turn = (self.theta - centre).abs() + PROBE * rate;
        g0 > 0.0 && turn < 3.0 && g0 >= alpha_max * rate
    }
}

#[cfg(test)]
#[path = "bend_tests.rs"]
mod tests;
