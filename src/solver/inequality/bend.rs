//! The projected (bent) search path of the joint stops: along the retraction (module
//! `retraction`) a tree joint's coordinate moves linearly, `θ(α) = θ + α θ̇`, so an inactive
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
//! ## References
//! - D. P. Bertsekas, "Projected Newton methods for optimization problems with simple
//!   constraints", *SIAM J. Control Optim.* 20 (1982) 221–246.
//! - J. J. Moré, G. Toraldo, "Algorithms for bound constrained quadratic programming problems",
//!   *Numer. Math.* 55 (1989) 377–400.

use super::active_set::Guard;
use crate::constraints::unilateral::{self, Unilateral};
use crate::solver::system::System;
use nalgebra::DVector;

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
    /// The inactive stops of tree joints that the path from `q` along `dq` closes, with the
    /// step length at which each is reached. Stops within the tolerance at the start (rows
    /// just released) are left to the guard.
    pub(crate) fn stops(&self, sys: &System, q: &DVector<f64>, dq: &DVector<f64>) -> Vec<Stop> {
        let model = sys.problem.model;
        let branches = &sys.problem.cons.branches;
        let ret = &sys.problem.retraction;
        let mut probe = None;
        let mut out = Vec::new();
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
            if self.gap(k, q, branches) <= self.tol {
                continue;
            }
            let qp = probe.get_or_insert_with(|| ret.point(q, dq, PROBE));
            let (Some(t0), Some(t1)) = (
                unilateral::limit_angle(model, joint, q, branches),
                unilateral::limit_angle(model, joint, qp, branches),
            ) else {
                continue;
            };
            let g0 = unilateral::limit_gap(t0, bound, value);
            let rate = (unilateral::limit_gap(t1, bound, value) - g0) / PROBE;
            if rate < 0.0 && g0 > 0.0 {
                out.push(Stop {
                    k,
                    body,
                    alpha: -g0 / rate,
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

pub(crate) fn held_trial(
    sys: &mut System,
    line: &crate::solver::step::line_search::Line,
    alpha: f64,
    guard: &Guard,
    options: &crate::solver::options::Options,
    diag: &mut crate::solver::report::Diagnostics,
    at_cut: f64,
) -> Option<crate::solver::step::line_search::Trial> {
    let window: f64 = std::env::var("RP_WINDOW").ok()?.parse().ok()?;
    let (q, part, eval, dq) = (line.q, line.part, line.eval, line.dq);
    let stops = guard.stops(sys, q, dq);
    let first = stops
        .iter()
        .map(|s| s.alpha)
        .filter(|&a| a < alpha)
        .fold(f64::INFINITY, f64::min);
    if !first.is_finite() {
        return None;
    }
    let reach = alpha.min(first * (1.0 + window));
    let caps: Vec<Stop> = stops.iter().filter(|s| s.alpha <= reach).copied().collect();
    let bodies: Vec<(usize, f64)> = caps.iter().map(|s| (s.body, s.alpha)).collect();
    let mut qt = if std::env::var("RP_JUMP").is_ok() {
        sys.problem.retraction.point_with(q, dq, |b| {
            bodies.iter().find(|c| c.0 == b).map_or(first, |c| c.1)
        })
    } else {
        sys.problem.retraction.bent_point(q, dq, reach, &bodies)
    };
    if sys
        .correct_from(
            &mut qt,
            part,
            options.constraint_tolerance,
            options.max_corrector_iterations,
            Some(&eval.factors),
        )
        .is_err()
        || guard.violated(sys, &qt)
    {
        return None;
    }
    let et = sys.evaluate(&qt, part)?;
    diag.function_evaluations += 1;
    let columns = &sys.problem.scaling.columns;
    let descent = eval
        .grad_v
        .dot(&crate::solver::step::retraction::independent_change(
            &part.independent,
            columns,
            q,
            &qt,
        ));
    if !(descent < 0.0 && et.merit <= eval.merit + 1e-4 * descent && et.merit <= at_cut) {
        return None;
    }
    let reached = guard.reached(sys, &caps, &qt);
    if reached.is_empty() {
        return None;
    }
    Some(crate::solver::step::line_search::Trial {
        q: qt,
        eval: et,
        alpha: 0.0,
        blocked: Some(reached),
    })
}
