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
