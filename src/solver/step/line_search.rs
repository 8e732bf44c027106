//! The backtracking line search of the minimizer along a reduced step `d` (tangent step
//! `δq = Z d`), the paper's step (d)–(f).
//!
//! A trial point starts from the point `α` along `δq` on the search path (module
//! `retraction`: the bodies moved rigidly along the spanning tree, which turns every tree
//! joint from `θ` to `θ + α θ̇`; the paper's path is the straight line `q + α δq`) and is brought
//! back onto `Φ = 0` by the Newton corrector (paper step (e.1)), which closes what the path
//! leaves open (loops, contacts), after the second-order correction of the trial point where the
//! step came from the KKT factors (module `second_order`: those rows closed in all
//! coordinates, to `O(α³)`); if the corrector fails, the step is halved (step (f)). A corrected point is accepted when the Armijo condition
//! `f(v̂ + α d) ≤ f + 10⁻⁴ α ∇fᵀ d` holds, or when `f` is flat to rounding and the gradient
//! has halved; otherwise `α` shrinks by safeguarded quadratic interpolation (to between
//! 0.1 and 0.5 of itself). Trial energies are compared through the Lagrangian `V − μᵀΦ`
//! (`Eval::merit`), which removes the first-order effect of the corrector's remaining
//! residual. With a guard, a trial point that violates an inactive inequality is replaced by
//! the point where the first one reaches its boundary, accepted if it does not raise `f`
//! beyond rounding; with the projected search, first by its projection onto the frictionless
//! contacts it pushes into a ground (module `inequality::hold`), accepted by Armijo's test on
//! the change actually made. A trial point brought to a valley's floor (module `valley`) is
//! judged likewise where that correction held stops, which then join with the trial point's.
//!
//! ## References
//! - J. Nocedal, S. J. Wright, *Numerical Optimization*, 2nd ed., Springer (2006), §3.1, §3.5.

use crate::solver::inequality::active_set::Guard;
use crate::solver::inequality::bend::Stop;
use crate::solver::options::{Options, StopSearch};
use crate::solver::partition::Partition;
use crate::solver::report::Diagnostics;
use crate::solver::step::retraction::independent_change;
use crate::solver::step::second_order::corrected_point;
use crate::solver::system::{Eval, System};
use nalgebra::DVector;

/// Trial step lengths before the search gives up.
const MAX_TRIALS: usize = 40;

/// The search line: the point `q`, its evaluation, the tangent step `δq` and the slope
/// `∇fᵀ d` of the merit along it.
pub(crate) struct Line<'a> {
    pub(crate) q: &'a DVector<f64>,
    pub(crate) part: &'a Partition,
    pub(crate) eval: &'a Eval,
    pub(crate) dq: &'a DVector<f64>,
    pub(crate) slope: f64,
    /// Where the iteration crawls along a curved valley, the trial points are brought back
    /// to its floor before they are judged (module `valley`).
    pub(crate) valley: Option<&'a crate::solver::valley::Valley>,
    /// The KKT factors of the step's direction at `q`, with a positive definite reduced
    /// Hessian, are in `sys`: trial points get the second-order correction (module
    /// `second_order`).
    pub(crate) second_order: bool,
}

/// A point the line search accepted.
pub(crate) struct Trial {
    pub(crate) q: DVector<f64>,
    pub(crate) eval: Eval,
    /// The step length taken (0 for a step cut at an inequality's boundary).
    pub(crate) alpha: f64,
    /// The inactive inequalities (indices into the guard's list) whose boundary cut the step.
    pub(crate) blocked: Option<Vec<usize>>,
    /// The step length tried when the point was found (for a cut step, the one that crossed).
    pub(crate) tried: f64,
}

/// Backtracks along `line` from the step length `alpha` (module docs); `None` when no step
/// length was accepted within [`MAX_TRIALS`] trials.
pub(crate) fn line_search(
    sys: &mut System,
    line: &Line,
    mut alpha: f64,
    guard: Option<&Guard>,
    options: &Options,
    diag: &mut Diagnostics,
) -> Option<Trial> {
    let (q, part, eval, dq, slope) = (line.q, line.part, line.eval, line.dq, line.slope);
    let f = eval.merit;
    let gnorm = eval.grad_v.amax();
    // The inactive stops the path reaches, and where (module `inequality::bend`).
    let stops = match (guard, options.stop_search) {
        (Some(g), StopSearch::Projected) => g.stops(sys, q, dq, alpha),
        _ => Vec::new(),
    };
    for _ in 0..MAX_TRIALS {
        let caps: Vec<Stop> = stops.iter().filter(|s| s.alpha < alpha).copied().collect();
        // `Φ` of the trial point, where the second-order correction has just evaluated it.
        let mut phi_in_scratch = false;
        let mut qt = if caps.is_empty() {
            let qt = sys.problem.retraction.point(q, dq, alpha);
            let tolerance = options.constraint_tolerance;
            if line.second_order {
                let got = corrected_point(sys, part, (q, dq, alpha), &qt, tolerance);
                phi_in_scratch = got.phi_in_scratch;
                got.point.unwrap_or(qt)
            } else {
                qt
            }
        } else {
            let bodies: Vec<(usize, f64)> = caps.iter().map(|s| (s.body, s.alpha)).collect();
            sys.problem.retraction.bent_point(q, dq, alpha, &bodies)
        };
        if sys
            .correct_evaluated(
                &mut qt,
                part,
                (
                    options.constraint_tolerance,
                    options.max_corrector_iterations,
                ),
                Some(&eval.factors),
                phi_in_scratch,
            )
            .is_err()
        {
            diag.corrector_failures += 1;
            diag.step_halvings += 1;
            alpha *= 0.5;
            continue;
        }
        if let Some(guard) = guard.filter(|g| g.violated(sys, &qt)) {
            // Frictionless contacts held on their grounds (module `inequality::hold`).
            if let Some((qh, k)) = guard.hold(sys, &qt, options) {
                if let Some(eh) = sys.evaluate(&qh, part) {
                    diag.function_evaluations += 1;
                    let columns = &sys.problem.scaling.columns;
                    let descent =
                        eval.grad_v
                            .dot(&independent_change(&part.independent, columns, q, &qh));
                    if descent < 0.0 && eh.merit <= f + 1e-4 * descent {
                        return Some(Trial {
                            q: qh,
                            eval: eh,
                            alpha,
                            blocked: Some(k),
                            tried: alpha,
                        });
                    }
                }
            }
            // Cut the step where the first inequality reaches its boundary.
            if let Some((qb, k)) = guard.boundary(sys, q, dq, alpha, Some(&qt), part, options, eval)
            {
                // Sticking contacts touching just after the first, met together (module
                // `inequality::together`).
                let cut = (&qb, k.as_slice());
                if let Some((q2, k2)) = guard.together(sys, q, dq, cut, alpha, part, options, eval)
                {
                    if let Some(e2) = sys.evaluate(&q2, part) {
                        diag.function_evaluations += 1;
                        if e2.merit <= f + roundoff_of(eval, &e2) {
                            return Some(Trial {
                                q: q2,
                                eval: e2,
                                alpha: 0.0,
                                blocked: Some(k2),
                                tried: alpha,
                            });
                        }
                    }
                }
                if let Some(eb) = sys.evaluate(&qb, part) {
                    diag.function_evaluations += 1;
                    if eb.merit <= f + roundoff_of(eval, &eb) {
                        return Some(Trial {
                            q: qb,
                            eval: eb,
                            alpha: 0.0,
                            blocked: Some(k),
                            tried: alpha,
                        });
                    }
                }
            }
            diag.step_halvings += 1;
            alpha *= 0.5;
            continue;
        }
        let Some(et) = sys.evaluate(&qt, part) else {
            diag.step_halvings += 1;
            alpha *= 0.5;
            continue;
        };
        diag.function_evaluations += 1;
        let mut held = Vec::new();
        let (qt, et) = match line.valley {
            Some(v) => v.correct(sys, part, (options, guard), diag, (qt, et), &mut held),
            None => (qt, et),
        };
        let ft = et.merit;
        // Rounding error of V: relative to the size of its terms, not of their sum.
        let roundoff = 1e-12 * eval.energy.magnitude.max(et.energy.magnitude) + f64::MIN_POSITIVE;
        // Along a bent path: Armijo on the change actually taken (the projected Armijo rule).
        let armijo = if caps.is_empty() && held.is_empty() {
            ft <= f + 1e-4 * alpha * slope
        } else {
            let columns = &sys.problem.scaling.columns;
            let descent = eval
                .grad_v
                .dot(&independent_change(&part.independent, columns, q, &qt));
            descent < 0.0 && ft <= f + 1e-4 * descent
        };
        // (In a curved valley, flat with the gradient along the floor smaller: module
        // `valley`.)
        let flat = (ft - f).abs() <= roundoff
            && (et.grad_v.amax() < 0.5 * gnorm
                || line
                    .valley
                    .is_some_and(|v| v.closer(&eval.grad_v, &et.grad_v)));
        if ft.is_finite() && (armijo || flat) {
            let all: Vec<Stop> = caps.iter().chain(&held).copied().collect();
            let mut reached = guard.map_or_else(Vec::new, |g| g.reached(sys, &all, &qt));
            reached.sort_unstable();
            reached.dedup();
            return Some(Trial {
                q: qt,
                eval: et,
                alpha,
                blocked: (!reached.is_empty()).then_some(reached),
                tried: alpha,
            });
        }
        // Quadratic interpolation of f along d, safeguarded.
        let denom = 2.0 * (ft - f - slope * alpha);
        let next = if denom > 0.0 {
            -slope * alpha * alpha / denom
        } else {
            0.5 * alpha
        };
        alpha = next.clamp(0.1 * alpha, 0.5 * alpha);
        diag.step_halvings += 1;
    }
    None
}

/// Rounding error of the merit function between two evaluations: relative to the size of the
/// energy's terms, not of their sum.
fn roundoff_of(a: &Eval, b: &Eval) -> f64 {
    1e-12 * a.energy.magnitude.max(b.energy.magnitude) + f64::MIN_POSITIVE
}
