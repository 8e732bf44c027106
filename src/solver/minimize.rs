//! Unconstrained minimization of `f(v̂) = V(u(v̂), v̂)` over the scaled independent coordinates.
//!
//! Each iteration picks a direction `d` (Newton: `−Ĥ⁻¹ ∇f` with the eigenvalues of the exact
//! reduced Hessian replaced by their magnitudes, floored; BFGS / DFP: `−B ∇f` with the inverse
//! update), caps `‖d‖∞` at `max_step`, and backtracks from `α = 1` until the Armijo condition
//! `f(v̂ + α d) ≤ f + 10⁻⁴ α ∇fᵀ d` holds. With a sparse partition that has second-pass
//! choices (contact or stop rows pivoted on their bodies, module `sparse::partition`), after a
//! step on which the corrector failed the next line search starts from the `α` that was
//! accepted instead of 1, and that start doubles after each step taken in full (a trust radius
//! for the corrector: a long rope's first steps swing its lower links far enough to leave the
//! corrector's reach, and halving from 1 every time costs two or three failed corrections per
//! iteration). Elsewhere it starts from 1 (applied to every model, this heuristic sent a far
//! start of the tractor-trailer, limits enforced, to another equilibrium). A trial point starts from the first-order prediction
//! `q + α Z d` and is brought back onto `Φ = 0` by the Newton corrector; trial energies are
//! compared through the Lagrangian `V − μᵀΦ`, which removes the first-order effect of the
//! corrector's remaining residual (otherwise `μ·Φ` can exceed the decrease a Newton step
//! promises near the minimum); if the corrector fails
//! the step is halved (paper step (f)). When no step is found, the coordinates are
//! re-partitioned once at the current point. A dense partition is also compared with a fresh
//! full pivoting after a step where the smallest-to-largest pivot ratio of `Φ_u` has fallen
//! below [`PIVOT_DRIFT`] of its value where the partition was made, and replaced if that one
//! differs: as the mechanism moves, the dependent coordinates chosen at the start lose their
//! hold (an Euler parameter near a turning point), `H = −Φ_u⁻¹ Φ_v` grows, the reduced
//! Hessian's eigenvalues spread with it and its floor swallows the physical curvatures (a
//! UR5 swinging down from horizontal stalled at ‖∇f‖ = 10⁻² for 200 iterations). a sparse partition with second-pass choices for
//! contact or stop rows (module `sparse::partition`) is recomputed after every step and
//! replaced when those choices have changed. At a stationary point with a negative reduced
//! Hessian eigenvalue (a saddle or maximum) the search leaves along its eigenvector, unless
//! `allow_unstable` is set.
//!
//! ## References
//! - J. Nocedal, S. J. Wright, *Numerical Optimization*, 2nd ed., Springer (2006), §3.1, §3.4, §6.1.
//! - R. Fletcher, M. J. D. Powell, A rapidly convergent descent method for minimization,
//!   *Computer Journal* 6 (1963) 163–168.

use super::inequality::active_set::Guard;
use super::inequality::release::Release;
use super::options::{Method, Options};
use super::partition::Partition;
use super::report::{Diagnostics, Iterate, Termination};
use super::stability::spectrum::{spectrum, Spectrum};
use super::system::{Backend, Eval, System};
use nalgebra::{DMatrix, DVector};

/// Outcome of the minimization.
pub(crate) struct Outcome {
    pub(crate) q: DVector<f64>,
    pub(crate) part: Partition,
    /// Reduced-Hessian eigenvalues and eigenvectors at `q`, when the convergence test
    /// computed them.
    pub(crate) eigen: Option<Spectrum>,
    /// The accepted iterates, when `Options::record_iterates` is set.
    pub(crate) iterates: Vec<DVector<f64>>,
    pub(crate) eval: Eval,
    pub(crate) termination: Termination,
    pub(crate) history: Vec<Iterate>,
    pub(crate) diagnostics: Diagnostics,
    /// The inactive inequalities (indices into the guard's list) that stopped the last step: `q`
    /// is on its boundary.
    pub(crate) blocked: Option<Vec<usize>>,
    /// The active inequalities (indices into the round's active list) to release: the round
    /// ended before it was stationary (module `inequality::release`).
    pub(crate) released: Vec<usize>,
}

/// Relative rounding floor of the reduced gradient: the convergence test uses
/// `max(gradient_tolerance, 1e-13 · Σ|V_k|)`, `V_k` the individual energy terms. It exceeds the
/// default 1e-8 J only for models whose energy terms add up to more than 10⁵ J.
const GRADIENT_FLOOR: f64 = 1e-13;

/// A dense partition whose smallest-to-largest pivot ratio of `Φ_u` has fallen below this
/// fraction of its value where the partition was made is checked against a fresh one.
const PIVOT_DRIFT: f64 = 0.85;

/// Up to this many degrees of freedom the sparse path too steps by the exact reduced Hessian's
/// eigen-decomposition, not the shifted KKT system (whose shift cut Tiago's steps 200-fold).
const EXACT_NEWTON_DOF: usize = 64;

/// Whether two partitions choose the same dependent coordinates and rows (in any order).
fn same_split(a: &Partition, b: &Partition) -> bool {
    let sorted = |x: &[usize]| {
        let mut x = x.to_vec();
        x.sort_unstable();
        x
    };
    sorted(&a.dependent) == sorted(&b.dependent) && sorted(&a.rows) == sorted(&b.rows)
}

/// The inverse-Hessian approximation of BFGS / DFP in the current independent coordinates.
struct QuasiNewton {
    binv: DMatrix<f64>,
    /// No update yet: the first one rescales the identity (Nocedal & Wright eq. 6.20).
    fresh: bool,
}

impl QuasiNewton {
    /// The identity for BFGS / DFP; empty for Newton, which has no use for it (a dense
    /// `dof × dof` matrix would dominate time and memory on large models).
    fn new(dof: usize, method: Method) -> Self {
        let dim = if method == Method::Newton { 0 } else { dof };
        QuasiNewton {
            binv: DMatrix::identity(dim, dim),
            fresh: true,
        }
    }
}

fn quasi_newton_update(
    method: Method,
    b: &mut DMatrix<f64>,
    s: &DVector<f64>,
    y: &DVector<f64>,
    first: bool,
) {
    let ys = y.dot(s);
    if ys <= 1e-14 * s.norm() * y.norm() || ys <= 0.0 {
        return;
    }
    if first {
        let n = b.nrows();
        *b = DMatrix::identity(n, n) * (ys / y.dot(y));
    }
    match method {
        Method::Bfgs => {
            let rho = 1.0 / ys;
            let by = &*b * y;
            let yby = y.dot(&by);
            // (I − ρ s yᵀ) B (I − ρ y sᵀ) + ρ s sᵀ, expanded.
            *b += (s * s.transpose()) * (rho * rho * yby + rho)
                - (&by * s.transpose() + s * by.transpose()) * rho;
        }
        Method::Dfp => {
            let by = &*b * y;
            let yby = y.dot(&by);
            *b += s * s.transpose() / ys - &by * by.transpose() / yby;
        }
        Method::Newton => {}
    }
}

/// A fresh partition at `q`, its evaluation, and a reset quasi-Newton approximation.
fn repartition(
    sys: &mut System,
    q: &DVector<f64>,
    method: Method,
    diag: &mut Diagnostics,
) -> Option<(Partition, Eval, QuasiNewton)> {
    let part = sys.partition(q);
    diag.repartitions += 1;
    let eval = sys.evaluate(q, &part)?;
    let qn = QuasiNewton::new(part.independent.len(), method);
    Some((part, eval, qn))
}

/// The diagonal of the bounding box of the body origins.
fn extent(q: &DVector<f64>) -> f64 {
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for b in 0..q.len() / 7 {
        for k in 0..3 {
            lo[k] = lo[k].min(q[7 * b + k]);
            hi[k] = hi[k].max(q[7 * b + k]);
        }
    }
    (0..3)
        .map(|k| (hi[k] - lo[k]).max(0.0).powi(2))
        .sum::<f64>()
        .sqrt()
}

/// Minimizes from `q`; with a `guard`, a step that would violate one of its inequalities is
/// cut where the first one reaches its boundary, and the minimization stops there
/// (`Outcome::blocked`).
pub(crate) fn minimize(
    sys: &mut System,
    mut q: DVector<f64>,
    mut part: Partition,
    options: &Options,
    guard: Option<&Guard>,
    release: Option<&Release>,
) -> Option<Outcome> {
    let mut diag = Diagnostics {
        load_steps: 1,
        ..Diagnostics::default()
    };
    let mut eval = sys.evaluate(&q, &part)?;
    diag.function_evaluations += 1;
    let mut history = Vec::new();
    let mut qn = QuasiNewton::new(part.independent.len(), options.method);
    let mut just_repartitioned = false;
    let mut termination = Termination::MaxIterations;
    let mut iteration = 0;
    let mut linear_steps = 0;
    let mut descent = super::unbounded::LinearDescent::default();
    let mut eigen = None;
    let mut iterates = Vec::new();
    let mut blocked = None;
    let mut released = Vec::new();
    // The step length the line search starts from: 1, or after a step the corrector could
    // not follow in full, the fraction that it could, doubled after each full success.
    let mut reach = 1.0f64;
    let mut pivot_reference = eval.factors.pivot_ratio();
    loop {
        let f = eval.merit;
        let gnorm = eval.grad_v.amax();
        // The gradient cannot be resolved below the rounding of the energy's terms.
        let gtol = options
            .gradient_tolerance
            .max(GRADIENT_FLOOR * eval.energy.magnitude);
        diag.gradient_tolerance = gtol;
        if history.last().map(|h: &Iterate| h.iteration) != Some(iteration) {
            history.push(Iterate {
                iteration,
                potential_energy: eval.energy.total,
                gradient_norm: gnorm,
                ..Iterate::default()
            });
            if options.record_iterates {
                iterates.push(q.clone());
            }
            if let Some(report) = &options.progress.0 {
                report(iteration, eval.energy.total, gnorm);
            }
        }
        // Active rows pulling hard leave before the round is stationary (`release`).
        if gnorm > gtol {
            if let Some(r) = release.and_then(|r| r.early(sys, &part, &eval)) {
                released = r;
                termination = Termination::Converged;
                break;
            }
        }
        let mut negative_curvature = None;
        let dof = part.independent.len();
        let dense_newton = options.method == Method::Newton
            && (sys.backend == Backend::Dense || dof <= EXACT_NEWTON_DOF);
        let eig =
            (dof > 0 && (dense_newton || gnorm <= gtol)).then(|| spectrum(sys, &q, &part, &eval));
        if gnorm <= gtol {
            match &eig {
                Some(e) if !options.allow_unstable => match e.lowest() {
                    Some((imin, lmin)) if lmin < -e.tolerance() => {
                        negative_curvature = Some(e.vectors.column(imin).into_owned());
                    }
                    _ => {
                        eigen = Some(e.clone());
                        termination = Termination::Converged;
                        break;
                    }
                },
                _ => {
                    eigen = eig.clone();
                    termination = Termination::Converged;
                    break;
                }
            }
        }
        if iteration >= options.max_iterations {
            break;
        }
        let g = &eval.grad_v;
        let mut d = if let Some(nc) = negative_curvature {
            diag.negative_curvature_steps += 1;
            let s = if nc.dot(g) > 0.0 { -1.0 } else { 1.0 };
            let scale = s * options.max_step / nc.amax().max(1e-300);
            nc * scale
        } else {
            match (&eig, options.method) {
                (Some(e), Method::Newton) if e.exact => {
                    let floor = 1e-8 * e.values.amax().max(1e-12);
                    let mut d = DVector::zeros(dof);
                    for i in 0..dof {
                        let v = e.vectors.column(i);
                        d -= v * (v.dot(g) / e.values[i].abs().max(floor));
                    }
                    d
                }
                (_, Method::Newton) => super::kkt_direction::kkt_direction(sys, &q, &part, &eval),
                _ => -(&qn.binv * g),
            }
        };
        if d.dot(g) > 0.0 {
            d = -g.clone();
            qn = QuasiNewton::new(dof, options.method);
        }
        // Step limit on the motion of the whole mechanism, not on v alone: every body's Euler
        // parameters change by at most `max_step` (about 2·max_step rad of rotation) and its
        // origin by at most 10·max_step lengths `ℓ`, `ℓ` the larger of the characteristic
        // length and the extent of the mechanism (the diagonal of the bounding box of the body
        // origins): in a long chain, small joint rotations move the far links by about the
        // chain's length, and a cap in link lengths would make the iteration count grow with N.
        let mut dq = sys.tangent_step(&part, &eval, &d);
        let l = sys.problem.model.length_scale.max(extent(&q));
        let (mut rot, mut pos) = (0.0f64, 0.0f64);
        for (i, x) in dq.iter().enumerate() {
            if i % 7 < 3 {
                pos = pos.max(x.abs() / l);
            } else {
                rot = rot.max(x.abs());
            }
        }
        let factor =
            (options.max_step / rot.max(1e-300)).min(10.0 * options.max_step / pos.max(1e-300));
        let capped = factor < 1.0;
        if capped {
            d *= factor;
            dq *= factor;
        }
        let slope = g.dot(&d);
        let failures_before = diag.corrector_failures;
        // Backtracking line search, from the step length the corrector last managed (with
        // second-pass choices in the partition; from 1 otherwise).
        let mut alpha = if part.second_pass.is_empty() {
            1.0
        } else {
            reach
        };
        let mut accepted = None;
        for _ in 0..40 {
            let mut qt = &q + &dq * alpha;
            if sys
                .correct_from(
                    &mut qt,
                    &part,
                    options.constraint_tolerance,
                    options.max_corrector_iterations,
                    Some(&eval.factors),
                )
                .is_err()
            {
                diag.corrector_failures += 1;
                diag.step_halvings += 1;
                alpha *= 0.5;
                continue;
            }
            if let Some(guard) = guard.filter(|g| g.violated(sys, &qt)) {
                // Cut the step where the first inequality reaches its boundary.
                if let Some((qb, k)) =
                    guard.boundary(sys, &q, &dq, alpha, Some(&qt), &part, options, &eval)
                {
                    if let Some(eb) = sys.evaluate(&qb, &part) {
                        diag.function_evaluations += 1;
                        if eb.merit <= f + roundoff_of(&eval, &eb) {
                            accepted = Some((qb, eb, 0.0));
                            blocked = Some(k);
                            break;
                        }
                    }
                }
                diag.step_halvings += 1;
                alpha *= 0.5;
                continue;
            }
            let Some(et) = sys.evaluate(&qt, &part) else {
                diag.step_halvings += 1;
                alpha *= 0.5;
                continue;
            };
            diag.function_evaluations += 1;
            let ft = et.merit;
            // Rounding error of V: relative to the size of its terms, not of their sum.
            let roundoff =
                1e-12 * eval.energy.magnitude.max(et.energy.magnitude) + f64::MIN_POSITIVE;
            let armijo = ft <= f + 1e-4 * alpha * slope;
            let flat = (ft - f).abs() <= roundoff && et.grad_v.amax() < 0.5 * gnorm;
            if ft.is_finite() && (armijo || flat) {
                accepted = Some((qt, et, alpha));
                break;
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
        match accepted {
            Some((qt, et, _)) if blocked.is_some() => {
                q = qt;
                sys.problem.cons.branches.follow(sys.problem.model, &q);
                eval = et;
                iteration += 1;
                break;
            }
            Some((qt, et, alpha)) => {
                reach = if diag.corrector_failures > failures_before {
                    alpha
                } else if alpha == reach {
                    (2.0 * reach).min(1.0)
                } else {
                    reach
                };
                let s = &d * alpha;
                let y = &et.grad_v - &eval.grad_v;
                // Full capped steps that leave the gradient unchanged: the energy falls
                // linearly along a direction of zero curvature.
                if capped && alpha == 1.0 && y.amax() <= 1e-9 * gnorm {
                    linear_steps += 1;
                } else {
                    linear_steps = 0;
                }
                quasi_newton_update(options.method, &mut qn.binv, &s, &y, qn.fresh);
                qn.fresh = false;
                let linear = descent.record(slope * alpha, &(&dq * alpha), l);
                // A linear descent toward an inequality may end on it.
                let may_be_stopped = guard.is_some_and(|g| g.approaching(sys, &q, &qt));
                q = qt;
                sys.problem.cons.branches.follow(sys.problem.model, &q);
                eval = et;
                iteration += 1;
                just_repartitioned = false;
                if (!may_be_stopped && (linear || linear_steps >= 5))
                    || eval.energy.total < -1e15
                    || (0..q.len())
                        .any(|i| i % 7 < 3 && q[i].abs() > 1e6 * sys.problem.model.length_scale)
                {
                    termination = Termination::Unbounded;
                    diag.free_directions =
                        super::unbounded::free_directions(sys.problem.model, &q, &(&dq * alpha));
                    break;
                }
                // Re-partition when Φ_u becomes ill-conditioned, or (a sparse partition with
                // second-pass choices) when the partition at `q` makes other ones. (Not on
                // any change: where a carried row ends in the final full pivoting among
                // nearly equal levers would flip from step to step.)
                let drifted = match (eval.factors.pivot_ratio(), pivot_reference) {
                    (Some(now), Some(reference)) => now < PIVOT_DRIFT * reference,
                    _ => false,
                };
                if eval.factors.ill_conditioned() {
                    (part, eval, qn) = repartition(sys, &q, options.method, &mut diag)?;
                    pivot_reference = eval.factors.pivot_ratio();
                } else if drifted {
                    // The dependent coordinates chosen at the start of this partition are
                    // losing their hold: a fresh full pivoting at `q`, adopted if it differs.
                    let fresh = sys.partition(&q);
                    if !same_split(&fresh, &part) {
                        diag.repartitions += 1;
                        eval = sys.evaluate(&q, &fresh)?;
                        part = fresh;
                        qn = QuasiNewton::new(part.independent.len(), options.method);
                    }
                    pivot_reference = eval.factors.pivot_ratio();
                } else if !part.second_pass.is_empty() {
                    let fresh = sys.partition(&q);
                    if fresh.second_pass != part.second_pass {
                        diag.repartitions += 1;
                        eval = sys.evaluate(&q, &fresh)?;
                        part = fresh;
                        qn = QuasiNewton::new(part.independent.len(), options.method);
                    }
                }
            }
            None if !just_repartitioned => {
                (part, eval, qn) = repartition(sys, &q, options.method, &mut diag)?;
                pivot_reference = eval.factors.pivot_ratio();
                just_repartitioned = true;
            }
            None => {
                termination = Termination::LineSearchFailed;
                break;
            }
        }
    }
    // A step accepted just before leaving the loop (blocked, unbounded) is recorded here.
    if history.last().map(|h: &Iterate| h.iteration) != Some(iteration) {
        history.push(Iterate {
            iteration,
            potential_energy: eval.energy.total,
            gradient_norm: eval.grad_v.amax(),
            ..Iterate::default()
        });
        if options.record_iterates {
            iterates.push(q.clone());
        }
    }
    diag.gradient_norm = eval.grad_v.amax();
    diag.constraint_residual = sys.residual(&q).amax();
    Some(Outcome {
        q,
        part,
        eigen,
        iterates,
        eval,
        termination,
        history,
        diagnostics: diag,
        blocked,
        released,
    })
}

/// Rounding error of the merit function between two evaluations: relative to the size of the
/// energy's terms, not of their sum.
fn roundoff_of(a: &Eval, b: &Eval) -> f64 {
    1e-12 * a.energy.magnitude.max(b.energy.magnitude) + f64::MIN_POSITIVE
}
