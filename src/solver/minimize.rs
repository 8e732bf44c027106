//! Unconstrained minimization of `f(v̂) = V(u(v̂), v̂)` over the scaled independent coordinates
//! (paper steps (c)–(f)), one iteration in named stages, as [`minimize`] reads:
//!
//! 1. **Record** the iterate (history, progress callback).
//! 2. **Convergence test** ([`convergence_test`]): `‖∇f‖∞ ≤ max(gradient_tolerance,
//!    10⁻¹³ Σ|V_k|)` and, unless `allow_unstable` is set, no negative eigenvalue of the reduced
//!    Hessian; at a saddle or maximum the search leaves along the eigenvector of the most
//!    negative one (along every negative one where the path keeps every row, as in stage 3);
//!    one within the Hessian's error first asks for the settling step (module `step::newton`).
//! 3. **Reduced step** ([`reduced_step`]): Newton `d = −Ĥ⁻¹ ∇f` with the exact reduced Hessian
//!    along the search path (`Ĥ + C`, module `step::path_hessian`), its eigenvalues replaced by
//!    their magnitudes, floored (dense, module `step::newton`), near a maximum or saddle at
//!    least a saddle step along every direction of negative curvature (module `step::escape`;
//!    on a small tree by Cholesky where `Ĥ + C` is positive definite, far from the rest
//!    Newton on `Ĥ` alone, module `step::path_cholesky`), or the KKT direction (sparse);
//!    BFGS / DFP `d = −B ∇f` (module `step::quasi_newton`); steepest descent when `d` is not a
//!    descent direction (an escape excepted).
//! 4. **Step cap** (module `step::step_cap`): the tangent step `δq = Z d` limited on the motion of the
//!    whole mechanism (every body's Euler parameters by `max_step`, its origin by
//!    `10 max_step ℓ`, `ℓ` the larger of the length scale and the mechanism's extent).
//! 5. **Line search and corrector** (module `step::line_search`): backtracking until Armijo
//!    holds along the search path (module `step::retraction`: tree joints turn from `θ` to
//!    `θ + α θ̇`), each trial corrected to second order where the path leaves rows open (module
//!    `step::second_order`), brought back onto `Φ = 0` by the corrector and halved when it fails
//!    (paper step (f)), from `α = 1` or, with second-pass choices in a sparse partition, the
//!    corrector's last reach ([`Search::reach`]). With a guard, a step that would violate an
//!    inactive inequality is cut where the first one reaches its boundary and the minimization
//!    stops there (`Outcome::blocked`: the caller updates the inequalities). In a curved valley
//!    trial points go to its floor first and stage 2 asks a short step along it (`valley`).
//! 6. **Accept** ([`accept_step`]): quasi-Newton update, and the unbounded test (a linear
//!    descent that goes on, module `unbounded`); with inequalities, the stall test (steps
//!    shrinking towards an obstacle's edge end the round, module `inequality::stall`).
//! 7. **Refresh the partition** ([`refresh_partition`](refresh::refresh_partition), paper step (b)): anew when `Φ_u` is
//!    ill-conditioned, when its pivots have drifted ([`PIVOT_DRIFT`]) and a fresh full
//!    pivoting differs, when a sparse partition's second-pass choices change or (sparse, tree)
//!    a fresh one differs after a failed correction. When the line search finds no step, the
//!    coordinates are re-partitioned once at the current point; a second failure ends it.
//!
//! ## References
//! - J. Nocedal, S. J. Wright, *Numerical Optimization*, 2nd ed., Springer (2006), §3.1, §3.4, §6.1.
//! - R. Fletcher, M. J. D. Powell, A rapidly convergent descent method for minimization,
//!   *Computer Journal* 6 (1963) 163–168.

use super::inequality::active_set::Guard;
use super::inequality::release::Release;
use super::inequality::release_trial::First;
use super::options::{Method, Options};
use super::partition::Partition;
use super::report::{Diagnostics, Iterate, Laps, Termination};
use super::stability::spectrum::Spectrum;
use super::stability::{at_rest::for_minimizer, inertia::ByInertia};
use super::step::direction::{direction, Direction};
use super::step::line_search::{line_search, Line, Trial};
use super::step::newton::Settle;
use super::step::path_cholesky::{self, Plan};
use super::step::quasi_newton::QuasiNewton;
use super::step::retraction::independent_change;
use super::step::step_cap::{cap_step, Step};
use super::system::{Backend, Eval, System};
use super::unbounded::LinearDescent;
use super::valley::Watch;
use nalgebra::DVector;
use refresh::{refresh_partition, repartition};

// A child module (it reads the search's state), kept beside this file.
#[path = "minimize_refresh.rs"]
mod refresh;

/// Outcome of the minimization.
pub(crate) struct Outcome {
    pub(crate) q: DVector<f64>,
    pub(crate) part: Partition,
    /// The reduced Hessian's spectrum at `q`, where the convergence test computed it.
    pub(crate) eigen: Option<Spectrum>,
    /// The inertia verdict at `q`, where the convergence test took it (`stability::at_rest`).
    pub(crate) inertia: Option<ByInertia>,
    /// The accepted iterates, when `Options::record_iterates` is set.
    pub(crate) iterates: Vec<DVector<f64>>,
    pub(crate) eval: Eval,
    pub(crate) termination: Termination,
    pub(crate) history: Vec<Iterate>,
    pub(crate) diagnostics: Diagnostics,
    /// The inactive inequalities (the guard's indices) that stopped the last step, `q` on one.
    pub(crate) blocked: Option<Vec<usize>>,
    /// The active inequalities (the round's indices) to release (module `inequality::release`).
    pub(crate) released: Vec<usize>,
    /// The end of the step tried where the last step was cut at a rolling hull's next vertex
    /// (module `inequality::roll_on`).
    pub(crate) carry: Option<DVector<f64>>,
}

/// Relative rounding floor of the reduced gradient: `max(gradient_tolerance, 1e-13 Σ|V_k|)`,
/// `V_k` the energy's terms; above the default 1e-8 J only where they add up to over 10⁵ J.
pub(crate) const GRADIENT_FLOOR: f64 = 1e-13;

/// A dense or tree partition whose smallest-to-largest pivot ratio of `Φ_u` has fallen below
/// this fraction of its value where the partition was made is checked against a fresh one: as
/// the mechanism moves, the dependent coordinates chosen at the start lose their hold (an Euler
/// parameter near a turning point), `H = −Φ_u⁻¹ Φ_v` grows, the reduced Hessian's eigenvalues
/// spread with it and its floor swallows the physical curvatures (a UR5 swinging down from
/// horizontal stalled at ‖∇f‖ = 10⁻² for 200 iterations).
const PIVOT_DRIFT: f64 = 0.85;

/// Up to this many degrees of freedom the sparse path too steps by the exact reduced Hessian's
/// eigen-decomposition, not the shifted KKT system (whose shift cut Tiago's steps 200-fold).
pub(crate) const EXACT_NEWTON_DOF: usize = 64;

/// The minimizer's state between iterations.
struct Search {
    method: Method,
    q: DVector<f64>,
    part: Partition,
    eval: Eval,
    qn: QuasiNewton,
    diag: Diagnostics,
    history: Vec<Iterate>,
    iterates: Vec<DVector<f64>>,
    iteration: usize,
    /// The step length the line search starts from with second-pass choices in a sparse
    /// partition (contact or stop rows pivoted on their bodies, module `sparse::partition`):
    /// 1, or after a step the corrector could not follow in full, the fraction that it could,
    /// doubled after each full success. A trust radius for the corrector: a long rope's first
    /// steps swing its lower links out of the corrector's reach, and halving from 1 every
    /// time costs two or three failed corrections per iteration. Elsewhere the search starts
    /// from 1 (applied to every model, this sent a far start of the tractor-trailer, limits
    /// enforced, to another equilibrium).
    reach: f64,
    /// The pivot ratio of `Φ_u` where the partition was made ([`PIVOT_DRIFT`]).
    pivot_reference: Option<f64>,
    /// The last line search failed and the partition was made afresh at `q`.
    just_repartitioned: bool,
    /// Consecutive full capped steps along which the gradient did not change.
    linear_steps: usize,
    descent: LinearDescent,
    /// Curved valleys (module `valley`).
    valley: Watch,
    /// The settling step at a curvature within the Hessian's error (module `step::newton`).
    settle: Settle,
}

/// What the convergence test found.
enum Test {
    /// Stationary, no negative curvature (unless allowed): the spectrum or inertia verdict.
    Converged(Option<Spectrum>, Option<ByInertia>),
    /// Stationary at a saddle or maximum: the eigenvector of the most negative eigenvalue.
    Saddle(DVector<f64>),
    /// Not stationary.
    Continue,
}

/// Minimizes from `q`; with a `guard`, a step that would violate one of its inequalities is
/// cut where the first one reaches its boundary, and it stops there (`Outcome::blocked`).
pub(crate) fn minimize(
    sys: &mut System,
    q: DVector<f64>,
    part: Partition,
    options: &Options,
    guard: Option<&Guard>,
    release: Option<&Release>,
) -> Option<Outcome> {
    let mut diag = Diagnostics {
        load_steps: 1,
        ..Diagnostics::default()
    };
    let eval = sys.evaluate(&q, &part)?;
    diag.function_evaluations += 1;
    let mut s = Search {
        method: options.method,
        qn: QuasiNewton::new(part.independent.len(), options.method),
        pivot_reference: eval.factors.pivot_ratio(),
        q,
        part,
        eval,
        diag,
        history: Vec::new(),
        iterates: Vec::new(),
        iteration: 0,
        reach: 1.0,
        just_repartitioned: false,
        linear_steps: 0,
        descent: LinearDescent::default(),
        valley: Watch::default(),
        settle: Settle::default(),
    };
    let (mut termination, mut eigen, mut inertia) = (Termination::MaxIterations, None, None);
    let (mut blocked, mut released) = (None, Vec::new());
    let mut first = release.and_then(Release::first);
    let mut carry_in = release.and_then(Release::carry);
    let (mut carry_out, mut laps) = (None, Laps::default()); // laps: `timings.steps`
    loop {
        laps.lap(&mut s.diag.timings);
        // The gradient cannot be resolved below the rounding of the energy's terms.
        let gtol = options
            .gradient_tolerance
            .max(GRADIENT_FLOOR * s.eval.energy.magnitude);
        s.diag.gradient_tolerance = gtol;
        record(&mut s, options, true);
        // Active rows pulling hard leave before the round is stationary (`release`).
        if s.eval.grad_v.amax() > gtol {
            if let Some(r) = release.and_then(|r| r.early(sys, &s.part, &s.eval)) {
                released = r;
                termination = Termination::Converged;
                break;
            }
        }
        let judging = std::time::Instant::now(); // the verdict at a rest: `timings.stability`
        let mut reused = First::taken(&mut first, (&s.q, &s.part, &s.eval), gtol, &mut s.diag);
        let (eig, plan, test) = match reused.as_mut() {
            Some((e, _)) => (e.take(), None, Test::Continue),
            None => convergence_test(sys, &mut s, gtol, options),
        };
        let saddle = match test {
            Test::Converged(e, v) => {
                s.diag.timings.stability += judging.elapsed().as_secs_f64();
                (eigen, inertia) = (e, v);
                termination = Termination::Converged;
                break;
            }
            Test::Saddle(v) => Some(v),
            Test::Continue => None,
        };
        if s.iteration >= options.max_iterations {
            break;
        }
        // Rolling on from the last round's cut step (module `inequality::roll_on`).
        let rolled = carry_in.take().and_then(|t| {
            let columns = &sys.problem.scaling.columns;
            let d = independent_change(&s.part.independent, columns, &s.q, t);
            (s.iteration == 0 && s.eval.grad_v.dot(&d) < 0.0).then_some(d)
        });
        let carried = rolled.is_some();
        let (d, kkt, along_path) = match (rolled, reused) {
            (Some(d), _) => (d, false, None),
            (None, Some((_, d))) => (d, false, None),
            (None, None) => reduced_step(sys, &mut s, (eig.as_ref(), plan), saddle, guard, options),
        };
        let step = cap_step(sys, &s.part, &s.eval, &s.q, d, options);
        let slope = s.eval.grad_v.dot(&step.d);
        let failures_before = s.diag.corrector_failures;
        // From the step length the corrector last managed (with second-pass choices in the
        // partition; from 1 otherwise).
        let alpha = if s.part.second_pass.is_empty() {
            1.0
        } else {
            s.reach
        };
        // In a curved valley, from the first stalled step on (module `valley`).
        let valley = s.valley.step(eig.as_ref(), along_path.as_ref(), &s.history);
        let line = Line {
            q: &s.q,
            part: &s.part,
            eval: &s.eval,
            dq: &step.dq,
            slope,
            valley: valley.as_ref(),
            second_order: kkt,
        };
        let trial = line_search(sys, &line, alpha, guard, options, &mut s.diag);
        match trial {
            Some(t) if t.blocked.is_some() => {
                let rolls = guard.is_some_and(|g| {
                    t.blocked
                        .iter()
                        .flatten()
                        .all(|&k| !g.is_roll_limit(k) && g.rolls(k))
                });
                if rolls && t.tried > 0.0 {
                    carry_out = Some(sys.problem.retraction.point(&s.q, &step.dq, t.tried));
                }
                blocked = t.blocked;
                s.q = t.q;
                sys.problem.cons.branches.follow(sys.problem.model, &s.q);
                s.eval = t.eval;
                s.iteration += usize::from(!carried);
                break;
            }
            // A continuation that reaches no inequality is dropped (`inequality::roll_on`).
            Some(_) if carried => continue,
            Some(t) => {
                let alpha = t.alpha;
                let before = s.eval.grad_v.amax();
                if accept_step(sys, &mut s, &step, slope, t, failures_before, guard) {
                    termination = Termination::Unbounded;
                    s.diag.free_directions = super::unbounded::free_directions(
                        sys.problem.model,
                        &s.q,
                        &(&step.dq * alpha),
                    );
                    break;
                }
                // Steps shrinking towards an obstacle's edge (module `inequality::stall`).
                if let Some(r) = release.filter(|r| r.stalled(alpha, before, s.eval.grad_v.amax()))
                {
                    // The rows carried past the edge leave (`released` with a failed line
                    // search: the caller guards them by their true gap).
                    released = r.opened_at_stall(&s.q, &step.dq, &sys.problem.cons.branches);
                    termination = Termination::LineSearchFailed;
                    break;
                }
                let corrector_failed = s.diag.corrector_failures > failures_before;
                refresh_partition(sys, &mut s, corrector_failed)?;
            }
            None if !s.just_repartitioned => {
                repartition(sys, &mut s)?;
                s.just_repartitioned = true;
            }
            None => {
                termination = Termination::LineSearchFailed;
                break;
            }
        }
    }
    // The first direction of the release that started the round (`release_trial`), not taken.
    s.diag.release_trials += usize::from(first.is_some());
    // A step accepted just before leaving the loop (blocked, unbounded) is recorded here.
    record(&mut s, options, false);
    s.diag.gradient_norm = s.eval.grad_v.amax();
    s.diag.constraint_residual = sys.residual(&s.q).amax();
    Some(Outcome {
        q: s.q,
        part: s.part,
        eigen,
        inertia,
        iterates: s.iterates,
        eval: s.eval,
        termination,
        history: s.history,
        diagnostics: s.diag,
        blocked,
        released,
        carry: carry_out,
    })
}

/// Stage 1: appends the current iterate to the history (and the recorded iterates) unless it
/// is there already; reports it to the progress callback when `report` is set.
fn record(s: &mut Search, options: &Options, report: bool) {
    if s.history.last().map(|h: &Iterate| h.iteration) == Some(s.iteration) {
        return;
    }
    let gnorm = s.eval.grad_v.amax();
    s.history.push(Iterate {
        iteration: s.iteration,
        potential_energy: s.eval.energy.total,
        gradient_norm: gnorm,
        ..Iterate::default()
    });
    if options.record_iterates {
        s.iterates.push(s.q.clone());
    }
    if report {
        if let Some(progress) = &options.progress.0 {
            progress(s.iteration, s.eval.energy.total, gnorm);
        }
    }
}

/// Stage 2: the convergence test (module docs), with the spectrum where it was needed, or on a
/// small tree away from a stationary point where the valley watch does not look the step's
/// plan instead: `Ĥ` formed, not decomposed (module `step::path_cholesky`).
fn convergence_test(
    sys: &mut System,
    s: &mut Search,
    gtol: f64,
    options: &Options,
) -> (Option<Spectrum>, Option<Plan>, Test) {
    let gnorm = s.eval.grad_v.amax();
    let dof = s.part.independent.len();
    let dense_newton = options.method == Method::Newton
        && (sys.backend == Backend::Dense || dof <= EXACT_NEWTON_DOF);
    let small = path_cholesky::small_tree(sys, dense_newton);
    let watched = s.valley.looks(&s.history);
    let at = (&s.q, &s.part, &s.eval);
    if let Some(plan) = path_cholesky::plan(sys, at, small, (gnorm, gtol), watched) {
        return (None, Some(plan), Test::Continue);
    }
    // On the Lanczos path the inertia verdict, and the spectrum only to leave a saddle
    // (module `stability::at_rest`).
    let mut verdict = None;
    let eig = (dof > 0 && (dense_newton || gnorm <= gtol))
        .then(|| {
            for_minimizer(
                sys,
                &s.q,
                &s.part,
                &s.eval,
                options.allow_unstable,
                &mut verdict,
            )
        })
        .flatten();
    if gnorm > gtol {
        return (eig, None, Test::Continue);
    }
    let rounding = GRADIENT_FLOOR * s.eval.energy.magnitude;
    let verdict = match &eig {
        Some(e) if !options.allow_unstable => match e.lowest() {
            Some((_, lmin)) if e.unresolved(lmin, gnorm, rounding) => {
                s.settle.ask(gnorm);
                return (eig, None, Test::Continue);
            }
            Some((imin, lmin)) if lmin < -e.tolerance() => {
                let v = e.vectors.column(imin).into_owned();
                return (eig, None, Test::Saddle(v));
            }
            _ if s.valley.unsettled(e, &s.eval.grad_v, rounding) => {
                return (eig, None, Test::Continue); // valley floor
            }
            _ => None,
        },
        _ => verdict,
    };
    // Converged: the spectrum moves into the test (the search stops here).
    (None, None, Test::Converged(eig, verdict))
}

/// Stage 3: the reduced step `d` (module docs, module `step::direction`); steepest descent
/// (and a reset quasi-Newton matrix) when not downhill; whether `sys` keeps its KKT factors;
/// and the spectrum of the Hessian along the path where the step was taken with it.
fn reduced_step(
    sys: &mut System,
    s: &mut Search,
    (eig, plan): (Option<&Spectrum>, Option<Plan>),
    negative_curvature: Option<DVector<f64>>,
    guard: Option<&Guard>,
    options: &Options,
) -> (DVector<f64>, bool, Option<Spectrum>) {
    let dof = s.part.independent.len();
    let settle = s.settle.take(s.eval.grad_v.amax());
    let g = &s.eval.grad_v;
    let Direction {
        d,
        escaped,
        kkt,
        along_path,
    } = direction(
        sys,
        (&s.q, &s.part, &s.eval),
        (eig, plan),
        negative_curvature.as_ref(),
        settle,
        &s.qn.binv,
        guard,
        options,
    );
    s.diag.negative_curvature_steps += usize::from(escaped || negative_curvature.is_some());
    if d.dot(g) > 0.0 && !escaped {
        s.qn = QuasiNewton::new(dof, options.method);
        return (-g.clone(), kkt, along_path);
    }
    (d, kkt, along_path)
}

/// Stage 6: moves to the accepted trial point: the line search's next start, the quasi-Newton
/// update, the joint branches followed; returns whether the descent is unbounded (a linear
/// descent that is not heading for an inequality, a vanishing energy, a body far away).
fn accept_step(
    sys: &mut System,
    s: &mut Search,
    step: &Step,
    slope: f64,
    t: Trial,
    failures_before: usize,
    guard: Option<&Guard>,
) -> bool {
    let alpha = t.alpha;
    s.reach = if s.diag.corrector_failures > failures_before {
        alpha
    } else if alpha == s.reach {
        (2.0 * s.reach).min(1.0)
    } else {
        s.reach
    };
    let gnorm = s.eval.grad_v.amax();
    let columns = &sys.problem.scaling.columns;
    let ds = independent_change(&s.part.independent, columns, &s.q, &t.q);
    let y = &t.eval.grad_v - &s.eval.grad_v;
    // Full capped steps that leave the gradient unchanged: the energy falls linearly along a
    // direction of zero curvature.
    if step.capped && alpha == 1.0 && y.amax() <= 1e-9 * gnorm {
        s.linear_steps += 1;
    } else {
        s.linear_steps = 0;
    }
    s.qn.update(s.method, &ds, &y);
    let linear = s
        .descent
        .record(slope * alpha, &(&step.dq * alpha), step.length);
    // A linear descent toward an inequality may end on it.
    let may_be_stopped = guard.is_some_and(|g| g.approaching(sys, &s.q, &t.q));
    s.q = t.q;
    sys.problem.cons.branches.follow(sys.problem.model, &s.q);
    s.eval = t.eval;
    s.iteration += 1;
    s.just_repartitioned = false;
    let q = &s.q;
    (!may_be_stopped && (linear || s.linear_steps >= 5))
        || s.eval.energy.total < -1e15
        || (0..q.len()).any(|i| i % 7 < 3 && q[i].abs() > 1e6 * sys.problem.model.length_scale)
}
