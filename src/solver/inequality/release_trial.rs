//! Several stops leaving at once, decided by the step (the primal active-set rule: a row
//! leaves the working set only if the step moves off it).
//!
//! The multiplier `μ_k` of an active row says how the energy falls when row `k` is relaxed
//! *with every other active row held*. When several rows pull together (module `release`),
//! releasing them all can turn one straight back: with the others free, the Newton step `d`
//! of the next round drives its gap down, `ġ_k = ∇g_k · Z d < 0`, and the guard cuts that
//! step at `α = 0` (an iteration that does not move the point) before the row rejoins.
//! Example-robot-data's classical simple humanoid ended its round 10 releasing four arm stops
//! that all pulled with the others held; round 11's first step pushed the right shoulder roll
//! back into its stop (docs/method.md, "Meeting several stops in one step").
//!
//! So before several rows leave together, where at least one of them is a joint stop, the
//! step is computed with them released (the reduced direction of the next round's first
//! iteration, capped: `trial`), and every candidate stop whose gap that step closes beyond
//! the tolerance at its full length,
//!
//! `g_k + ġ_k < −tol`,
//!
//! stays held; the step is computed again with the remaining candidates, at most
//! [`PASSES`] times, until none is pushed back. When every candidate is pushed back, the
//! trial says nothing about which to keep, and all leave as before. A single candidate leaves
//! as before, without a trial (but see "One stop leaving early" below). A stop kept this way
//! does not leave before the next round is stationary (it is not eligible for the early release
//! of module `release` in that round).
//! No trial is computed where the next round would take no step: once the candidates are
//! released, other rows pull hard and leave at its start (module `release`'s early test on
//! the trial's multipliers); the release after it decides (only the evaluation is made).
//!
//! The round after a consistent trial starts with the stops released on the concave side of
//! their fall; there the escape from negative curvature is taken at every iterate (the guard's
//! `falling`, module `step::newton`), in the trials as well.
//!
//! Each trial is one reduced direction (one evaluation, one eigen-decomposition or KKT
//! solve). Where the last one is consistent it is the next round's first direction: that round
//! starts at the same point with the same rows, and its first iteration takes it ([`First`],
//! module `minimize`) instead of computing it again. Every other trial, and a consistent one
//! the next round does not take (it ends before its first step, or starts elsewhere), is work
//! no iteration counts: `Diagnostics::release_trials` (each trial's evaluation is counted in
//! `function_evaluations`).
//!
//! **Rows released before** (they leave only at a stationary point, module `release`) that
//! pull together there leave together where the step with all of them released moves off
//! every one (a consistent trial); otherwise the one pulling hardest leaves alone, as in the
//! classic method. icub-models' iCubGenova03 released its right wrist pitch and shoulder pitch
//! in two converged rounds, then its wrist pitch and prosupination in two more.
//!
//! **One stop leaving early.** A single stop that pulls hard before its round is stationary
//! is tried as well: where the step with it released pushes it straight back (`g + ġ < −tol`),
//! it stays held (and is not eligible for the early release in the next round); where the step
//! moves off it, it leaves as before and the trial is not used (counted in
//! `release_trials`): taking its direction and the fall from the concave side (above) moved
//! the classical simple humanoid from 30 to 32 iterations. icub-models' iCubDarmstadt01 released
//! its left shoulder roll early and the next step met it again after 2.7·10⁻⁸ rad, one
//! iteration of its 36.
//!
//! ## References
//! - J. Nocedal, S. J. Wright, *Numerical Optimization*, 2nd ed., Springer (2006), §16.5
//!   (a constraint leaves the working set when the step computed without it moves off it).

use crate::constraints::unilateral::{self, Active, Unilateral};
use crate::constraints::Constraints;
use crate::model::{JointId, Model};
use crate::solver::options::{Method, Options};
use crate::solver::partition::Partition;
use crate::solver::stability::spectrum::Spectrum;
use crate::solver::system::{Backend, System};
use crate::State;
use nalgebra::{DMatrix, DVector};

/// Trials at most per release (each one reduced direction).
pub(crate) const PASSES: usize = 3;

/// The step length along which the stops' rates are read (their angles are linear along the
/// path, module `step::retraction`).
const PROBE: f64 = 1e-3;

/// The first direction of the next round, where the last trial was consistent (no candidate
/// pushed back): that round starts with the same rows at the same point, so its first
/// iteration takes this direction instead of computing it again (module `minimize`).
pub(crate) struct First {
    q: DVector<f64>,
    independent: Vec<usize>,
    eig: Option<Spectrum>,
    d: DVector<f64>,
    escaped: bool,
}

/// The spectrum and the direction.
pub(crate) type Taken = (Option<Spectrum>, DVector<f64>);

impl First {
    /// The round's first direction `first` (taken out), where the round is at `q` with the
    /// independent coordinates of `part` and not stationary (`‖∇f‖∞ > gtol`), its escape
    /// counted in `diag.negative_curvature_steps`; else `None`, and the trial is counted in
    /// `diag.release_trials` as work no iteration took.
    pub(crate) fn taken(
        first: &mut Option<&First>,
        (q, part, eval): (&DVector<f64>, &Partition, &crate::solver::system::Eval),
        gtol: f64,
        diag: &mut crate::solver::Diagnostics,
    ) -> Option<Taken> {
        let f = first.take()?;
        let fits = eval.grad_v.amax() > gtol && f.q == *q && f.independent == part.independent;
        diag.release_trials += usize::from(!fits);
        diag.negative_curvature_steps += usize::from(fits && f.escaped);
        fits.then(|| (f.eig.clone(), f.d.clone()))
    }
}

/// What the release keeps for the next round.
#[derive(Default)]
pub(crate) struct Next {
    /// The candidates kept held because the step pushed them back.
    pub(crate) kept: Vec<Unilateral>,
    /// The last trial's direction, if consistent.
    pub(crate) first: Option<First>,
    /// Whether the last trial was consistent (the stops released fall: module docs).
    pub(crate) falling: bool,
}

/// The decision of one release.
pub(crate) struct Decided {
    /// The candidates (ascending positions in `active`) that leave.
    gone: Vec<usize>,
    next: Next,
    /// Reduced directions computed to decide.
    trials: usize,
    /// Evaluations made to decide.
    evaluations: usize,
}

/// The candidates `gone` (positions in `active`) that may leave together at `state` (module
/// docs). `all` are the model's inequalities.
pub(crate) fn decide(
    ctx: (&Model, &Options, &[(JointId, usize, f64)]),
    state: &State,
    rows: (&[Active], &[Unilateral]),
    early: (&[Unilateral], f64),
    gone: Vec<usize>,
) -> Decided {
    decide_with(ctx, state, rows, early, gone, false)
}

/// [`decide`] for the rows that pull hard before a round is stationary (module `release`):
/// a single candidate stop is tried as well, and stays held where the step pushes it back
/// (module docs, "One stop leaving early").
pub(crate) fn decide_early(
    ctx: (&Model, &Options, &[(JointId, usize, f64)]),
    state: &State,
    rows: (&[Active], &[Unilateral]),
    early: (&[Unilateral], f64),
    gone: Vec<usize>,
) -> Decided {
    decide_with(ctx, state, rows, early, gone, true)
}

fn decide_with(
    (model, options, locks): (&Model, &Options, &[(JointId, usize, f64)]),
    state: &State,
    (active, all): (&[Active], &[Unilateral]),
    early: (&[Unilateral], f64),
    mut gone: Vec<usize>,
    single: bool,
) -> Decided {
    gone.sort_unstable();
    let mut next = Next::default();
    let (mut trials, mut evaluations) = (0, 0);
    let limit = |i: &usize| matches!(active[*i].row, Unilateral::Limit { .. });
    let alone = single && gone.len() == 1;
    while (gone.len() >= 2 || alone) && gone.iter().any(limit) && trials < PASSES {
        let ctx = (model, options, locks);
        let trial = pushed_back(ctx, state, (active, all), early, &gone, &mut evaluations);
        let Some((pushed, first)) = trial else {
            break;
        };
        trials += 1;
        if pushed.is_empty() {
            // A single stop that the step moves off leaves as before: its trial is work no
            // iteration takes.
            if !alone {
                (next.first, next.falling) = (first, true);
            }
            break;
        }
        if pushed.len() == gone.len() {
            if alone {
                next.kept.extend(pushed.iter().map(|&i| active[i].row));
                gone.clear();
            }
            break;
        }
        next.kept.extend(pushed.iter().map(|&i| active[i].row));
        gone.retain(|i| !pushed.contains(i));
    }
    Decided {
        gone,
        next,
        trials,
        evaluations,
    }
}

impl Decided {
    /// Whether the last trial was consistent (no candidate that leaves is pushed back by the
    /// step) and is the next round's first direction.
    pub(crate) fn consistent(&self) -> bool {
        self.next.falling
    }

    /// The candidates that leave; the trials counted in `counters` (their evaluations
    /// in `function_evaluations`; the consistent last one when the next round takes it, module `minimize`),
    /// what the next round needs in `next`.
    pub(crate) fn counted(
        self,
        counters: &mut crate::solver::Diagnostics,
        next: &mut Next,
    ) -> Vec<usize> {
        counters.release_trials += self.trials - usize::from(self.next.first.is_some());
        counters.function_evaluations += self.evaluations;
        *next = self.next;
        self.gone
    }
}

/// The candidate stops among `gone` that the next round's first step, with all of `gone`
/// released, pushes back beyond the tolerance, and that step; `None` where it cannot be
/// computed, or where that round takes no step: other rows pull hard once `gone` are
/// released and leave at its start (module `release`; `early`: the rows released before
/// and the complementarity tolerance), and the release after it decides.
fn pushed_back(
    (model, options, locks): (&Model, &Options, &[(JointId, usize, f64)]),
    state: &State,
    (active, all): (&[Active], &[Unilateral]),
    (released_before, threshold): (&[Unilateral], f64),
    gone: &[usize],
    evaluations: &mut usize,
) -> Option<(Vec<usize>, Option<First>)> {
    let held: Vec<Active> = (0..active.len())
        .filter(|i| !gone.contains(i))
        .map(|i| active[i])
        .collect();
    // The next round's start (module `active_set`: projected onto its rows).
    let mut branches = state.branches.clone();
    let q = crate::solver::assemble::project(
        model,
        state.q.clone(),
        &mut branches,
        locks,
        &held,
        options,
    )
    .ok()?;
    let q = &q;
    let cons = Constraints::new(model, locks)
        .with_active(model, &held)
        .on_branches(branches);
    let mut sys = System::new(model, cons, Backend::of_round(model, options));
    let part = sys.partition(q);
    let eval = sys.evaluate(q, &part)?;
    *evaluations += 1;
    let dof = part.independent.len();
    let before: Vec<Unilateral> = (released_before.iter().copied())
        .chain(gone.iter().map(|&i| active[i].row))
        .collect();
    let gtol = options
        .gradient_tolerance
        .max(crate::solver::minimize::GRADIENT_FLOOR * eval.energy.magnitude);
    let at_start = super::release::Release::new(model, &held, &before, threshold)
        .holding_patch_neighbours(&held);
    if dof == 0 || (eval.grad_v.amax() > gtol && at_start.early(&sys, &part, &eval).is_some()) {
        return None;
    }
    let inactive: Vec<Unilateral> = all
        .iter()
        .filter(|u| !held.iter().any(|a| a.row == **u))
        .copied()
        .collect();
    let tol = options.gap_tolerance;
    let mut guard = super::guard::Guard::new(model, options, inactive, &held, tol, q)
        .holding(&held, locks, options);
    guard.falling = true;
    // The next round's first direction (module `minimize`, stages 2–4).
    let dense_newton = options.method == Method::Newton
        && (sys.backend == Backend::Dense || dof <= crate::solver::minimize::EXACT_NEWTON_DOF);
    let mut verdict = None;
    let eig = dense_newton
        .then(|| {
            crate::solver::stability::at_rest::for_minimizer(
                &mut sys,
                q,
                &part,
                &eval,
                options.allow_unstable,
                &mut verdict,
            )
        })
        .flatten();
    let binv = DMatrix::identity(dof, dof);
    let crate::solver::step::direction::Direction {
        mut d,
        escaped,
        kkt,
        ..
    } = crate::solver::step::direction::direction(
        &mut sys,
        (q, &part, &eval),
        (eig.as_ref(), None),
        None,
        None,
        &binv,
        Some(&guard),
        options,
    );
    if d.dot(&eval.grad_v) > 0.0 && !escaped {
        d = -eval.grad_v.clone();
    }
    let step = crate::solver::step::step_cap::cap_step(&sys, &part, &eval, q, d.clone(), options);
    let probe = sys.problem.retraction.point(q, &step.dq, PROBE);
    let branches = &sys.problem.cons.branches;
    let pushed = gone
        .iter()
        .copied()
        .filter(|&i| {
            let Unilateral::Limit {
                joint,
                bound,
                value,
            } = active[i].row
            else {
                return false;
            };
            let angle = |x: &DVector<f64>| unilateral::limit_angle(model, joint, x, branches);
            let (Some(t0), Some(t1)) = (angle(q), angle(&probe)) else {
                return false;
            };
            let g0 = unilateral::limit_gap(t0, bound, value);
            let rate = (unilateral::limit_gap(t1, bound, value) - g0) / PROBE;
            g0 + rate < -tol
        })
        .collect();
    // Reused only where the direction needs nothing the trial's system keeps (the KKT
    // factors of the second-order correction).
    let first = (!kkt).then(|| First {
        q: q.clone(),
        independent: part.independent.clone(),
        eig,
        d,
        escaped,
    });
    Some((pushed, first))
}
