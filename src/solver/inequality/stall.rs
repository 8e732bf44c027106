//! A round that stalls at the edge of an obstacle: steps that shrink geometrically while the
//! reduced gradient does not fall.
//!
//! The gap of a contact on an obstacle, `g(x) = dist(x, obstacle)`, has a kink where the nearest
//! feature changes (a box's edge). A body sliding along a face towards such an edge, its point
//! held on the face by the active row `g = 0`, cannot follow the face past the edge: the
//! corrector fails on every trial step beyond it, and the line search accepts only the part of
//! the step that stays on this side, so the iterates approach the edge point `q*` with steps
//!
//! `α_{j+1} ≤ ½ α_j`,
//!
//! while `‖∇f‖` stays where it was (`q*` is not stationary: the body is pulled on over the
//! edge). The remaining decrease is then bounded by the last step's, and the round would only
//! end at the line search's rounding floor, 20–40 iterations later (or at `max_iterations`,
//! the steps accepted on the energy's rounding noise). After [`STALLED_STEPS`] such steps
//! with `‖∇f‖` above [`GRADIENT_KEPT`] of its value at the first, the round ends as a failed
//! line search. The rows that hold the body back there are those whose point the step the
//! round wants to take, `q ⊕ δq` (the tangent step, uncorrected), carries past the edge:
//! their gap opens by a first-order part of the point's displacement `s`,
//!
//! `g_k(q ⊕ δq) > OPENING · s_k`,
//!
//! where a point sliding on a face keeps `g_k = 0` to first order. Those rows leave (as pulling
//! rows do, module `release`) and are guarded by their true gap in the next round, not by the
//! face's plane extended past the edge (module `let_go`). If no row opens, the active-set
//! iteration treats the round as a failed line search (module `active_set`): the rows that
//! pull there leave, or the contacts hanging on the edge let go, and a body with nothing left
//! to hold it falls, which the minimizer's constant-rate test reports as `unbounded`.
//!
//! Only rounds with an active contact on an obstacle are watched: grounds are planes and stops
//! are smooth, so nothing else has such a kink, and a Newton iteration converging to a
//! stationary point reduces `‖∇f‖` with its steps.

use crate::constraints::unilateral::{self, Active, Unilateral};
use crate::kinematics::Branches;
use crate::model::Model;
use nalgebra::DVector;
use std::cell::Cell;

/// Consecutive geometrically shrinking steps that end a round.
pub(crate) const STALLED_STEPS: usize = 3;

/// The fraction of the reduced gradient at the start of the run that it must keep.
pub(crate) const GRADIENT_KEPT: f64 = 0.9;

/// The least opening, as a fraction of the point's displacement along the step, of a row
/// carried past an edge.
pub(crate) const OPENING: f64 = 0.25;

/// The stall test of one round (module docs).
pub(crate) struct Stall {
    /// Some active contact rests on an obstacle.
    watched: bool,
    /// The round's active inequalities.
    active: Vec<Unilateral>,
    /// The last accepted step length, the run of shrinking steps, and `‖∇f‖∞` before its
    /// first step.
    last: Cell<Option<f64>>,
    run: Cell<usize>,
    gradient: Cell<f64>,
}

impl Stall {
    /// The test for a round whose active list is `active`.
    pub(crate) fn new(model: &Model, active: &[Active]) -> Self {
        let watched = active.iter().any(|a| match a.row {
            Unilateral::Contact { ground, .. } => ground >= model.grounds.len(),
            Unilateral::Limit { .. } => false,
        });
        Stall {
            watched,
            active: active.iter().map(|a| a.row).collect(),
            last: Cell::new(None),
            run: Cell::new(0),
            gradient: Cell::new(0.0),
        }
    }

    /// Records an accepted step of length `alpha` from a point whose reduced gradient was
    /// `before` to one where it is `after` (‖·‖∞); returns whether the round has stalled.
    pub(crate) fn record(&self, alpha: f64, before: f64, after: f64) -> bool {
        if !self.watched {
            return false;
        }
        let shrinking = self.last.get().is_some_and(|l| alpha <= 0.5 * l) && alpha > 0.0;
        self.last.set(Some(alpha));
        if !shrinking {
            self.run.set(0);
            self.gradient.set(before);
            return false;
        }
        if self.run.get() == 0 {
            self.gradient.set(before);
        }
        self.run.set(self.run.get() + 1);
        if after < GRADIENT_KEPT * self.gradient.get() {
            self.run.set(0);
            return false;
        }
        self.run.get() >= STALLED_STEPS
    }

    /// The active contacts on obstacles (indices into the round's active list) that the
    /// tangent step `dq` from `q` carries past an edge (module docs).
    pub(crate) fn opened(
        &self,
        model: &Model,
        q: &DVector<f64>,
        dq: &DVector<f64>,
        branches: &Branches,
    ) -> Vec<usize> {
        let mut moved = q + dq;
        for b in 0..model.bodies.len() {
            let mut e = moved.fixed_rows_mut::<4>(7 * b + 3);
            let n = e.norm();
            if n > 0.0 {
                e /= n;
            }
        }
        let mut out = Vec::new();
        for (i, u) in self.active.iter().enumerate() {
            let Unilateral::Contact { point, ground } = *u else {
                continue;
            };
            if ground < model.grounds.len() {
                continue;
            }
            let s = (unilateral::point_world(model, point, &moved)
                - unilateral::point_world(model, point, q))
            .norm();
            let g = unilateral::gap(model, u, &moved, branches);
            if g.is_some_and(|g| s > 0.0 && g > OPENING * s) {
                out.push(i);
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn watched() -> Stall {
        Stall {
            watched: true,
            active: Vec::new(),
            last: Cell::new(None),
            run: Cell::new(0),
            gradient: Cell::new(0.0),
        }
    }

    #[test]
    fn halving_steps_at_a_constant_gradient_stall() {
        let s = watched();
        let mut alpha = 0.0625;
        let mut stalled = Vec::new();
        for _ in 0..5 {
            stalled.push(s.record(alpha, 5.7, 5.7));
            alpha *= 0.5;
        }
        // The first step starts the comparison; three shrinking steps after it stall.
        assert_eq!(stalled, [false, false, false, true, true]);
    }

    #[test]
    fn newton_convergence_and_steady_steps_do_not() {
        // Quadratic convergence: the steps shrink, and so does the gradient.
        let s = watched();
        let mut g = 1.0;
        for k in 0..8 {
            let next = g * g * 0.1;
            assert!(!s.record(0.5f64.powi(k), g, next));
            g = next;
        }
        // A slide along a face: full steps.
        let s = watched();
        for _ in 0..10 {
            assert!(!s.record(1.0, 5.0, 5.0));
        }
        // Not watched (no obstacle contact): never.
        let s = Stall {
            watched: false,
            ..watched()
        };
        let mut alpha = 1.0;
        for _ in 0..10 {
            assert!(!s.record(alpha, 5.0, 5.0));
            alpha *= 0.25;
        }
    }
}
