//! Joint stops and ground contact: minimize `V(q)` subject to `Φ(q) = 0` and `g(q) ≥ 0` by an
//! active-set extension of coordinate partitioning.
//!
//! The active inequalities `A` join `Φ` as rows `g_k(q) = 0`, and the equality-constrained
//! problem is solved as any other (partition, reduced Newton, corrector). Then:
//! - a step that would make an inactive `g_k` negative is cut (module `guard`) where the first
//!   one reaches `|g_k| ≤ tol`, or (projected search) holds the stops (module `bend`) and the
//!   frictionless contacts (module `hold`) it reaches on their boundaries and goes on; every
//!   inequality at its boundary there joins `A`, and the partition is recomputed;
//! - at a stationary point, the multipliers `λ_k` of the active rows (`V_qᵀ = Φ_qᵀ μ`) are the
//!   stops' efforts and the contacts' normal forces; those below `−force_tolerance · F` (`F`
//!   the weight and loads of the mechanism) leave `A`: all of them the first time, later only
//!   the most negative (or those the step moves off together, module `release_trial`); a
//!   round also ends before it is stationary when a multiplier pulls
//!   hard relative to the reduced gradient (module `release`); a round whose line search
//!   fails releases its pulling rows likewise, and where none pulls, the contacts that no
//!   longer hold a floating body (module `let_go`);
//! - it stops when every `λ_k ≥ −force_tolerance · F` and every `g_k ≥ −tol`
//!   (complementarity `g_k λ_k = 0` holds by construction: active rows have `g = 0`, inactive
//!   ones `λ = 0`), or after `max_iterations` changes of `A` after the start (reported as
//!   cycling).
//! - a sticking sphere that has rolled at a stationary point is re-anchored where it touches
//!   and the round solved again (module `rolling`); where no rest exists this way (a ball on a
//!   sloping plane rolls down) it gives up after `MAX_ROLLS` re-anchorings (`unbounded`).
//!
//! Gaps are compared dimensionless: lengths divided by the characteristic length `L`, angles
//! as they are; `tol = gap_tolerance`. Redundant active rows (a box flat on the ground has four
//! supporting vertices for three degrees of freedom) are handled by the partition, which gives
//! them no multiplier; the force distribution reported is then the least-norm one over the
//! stops and contacts (module `distribution`: a box flat on four vertices gets `m g / 4` on
//! each). Stability is judged on the tangent space of the active rows that carry a force and the
//! critical cone of those that do not (module `cone`).
//!
//! ## References
//! - J. Nocedal, S. J. Wright, *Numerical Optimization*, 2nd ed., Springer (2006), §16.5
//!   (active-set methods), §15.4 (handling inequalities in reduced-gradient methods).

pub(crate) use super::guard::Guard;
use crate::constraints::unilateral::{self, Active, Unilateral};
use crate::kinematics::Branches;
use crate::model::Model;
use crate::solver::options::Options;
use crate::solver::system::Backend;
use nalgebra::{DVector, Vector3};

/// `g` divided by the characteristic length for a gap in m: its row's `D g`, as in the
/// constraint residual (module `system::residual`).
pub(crate) fn dimensionless(model: &Model, u: &Unilateral, g: f64) -> f64 {
    if unilateral::length_power(model, u) == 1 {
        g / model.length_scale
    } else {
        g
    }
}

/// Every inequality of the model under `options`.
pub(crate) fn inequalities(model: &Model, options: &Options) -> Vec<Unilateral> {
    unilateral::inequalities(model, options.contact().enforces_limits())
}

/// `u` made active at `q`: a sticking contact is anchored at the point's projection on the
/// ground.
pub(crate) fn activate(
    model: &Model,
    options: &Options,
    u: Unilateral,
    q: &DVector<f64>,
) -> Active {
    let anchor = match u {
        Unilateral::Contact { point, ground } => {
            let c = &model.contact_points[point];
            options.contact().sticks(&c.settings).then(|| {
                let x = unilateral::point_world(model, point, q);
                let (_, normal) = unilateral::surface(model, ground, &x);
                let g = unilateral::gap(model, &u, q, &Branches::default()).unwrap_or(0.0);
                let i = 7 * c.body.0;
                let p = nalgebra::Vector4::new(q[i + 3], q[i + 4], q[i + 5], q[i + 6]);
                let a = crate::math::rotation(&p);
                unilateral::Anchor {
                    world: x - normal * (g + c.radius),
                    body: c.point - a.transpose() * normal * c.radius,
                }
            })
        }
        Unilateral::Limit { .. } => None,
    };
    Active { row: u, anchor }
}

/// Force scale `F` of the mechanism \[N\]: its weight plus the dead loads, and the joint
/// efforts divided by the characteristic length (at least 1e-12).
pub(crate) fn force_scale(model: &Model) -> f64 {
    let weight: f64 =
        model.bodies.iter().map(|b| b.gravity_mass).sum::<f64>() * model.gravity.norm();
    let loads: f64 = model.loads.iter().map(|l| l.force.norm()).sum();
    let efforts: f64 =
        model.efforts.iter().map(|e| e.value.abs()).sum::<f64>() / model.length_scale;
    (weight + loads + efforts).max(1e-12)
}

/// Multipliers of the rows of each active inequality (`g` first, then the tangential rows),
/// from the multipliers `full` of every row of `cons`.
pub(crate) fn active_multipliers(
    cons: &crate::constraints::Constraints,
    full: &DVector<f64>,
) -> Vec<(Active, Vec<f64>)> {
    cons.blocks
        .iter()
        .filter_map(|b| match &b.kind {
            crate::constraints::BlockKind::Unilateral(a) => {
                Some((*a, (0..a.row_count()).map(|k| full[b.first + k]).collect()))
            }
            _ => None,
        })
        .collect()
}

/// The multiplier of an active row's inequality, a stop's torque divided by the
/// characteristic length so that it compares with forces.
pub(crate) fn scaled_force(model: &Model, a: &Active, m: &[f64]) -> f64 {
    match a.row {
        Unilateral::Limit { joint, .. } if model.joints[joint.0].kind.is_angle(0) => {
            m[0] / model.length_scale
        }
        _ => m[0],
    }
}

/// The active rows that carry a force above `threshold` (strongly active) and those that do
/// not (weakly active), with the multipliers' scaling of [`scaled_force`].
pub(crate) fn split(
    model: &Model,
    multipliers: &[(Active, Vec<f64>)],
    threshold: f64,
) -> (Vec<Active>, Vec<Active>) {
    let mut strong = Vec::new();
    let mut weak = Vec::new();
    for (a, m) in multipliers {
        if scaled_force(model, a, m) > threshold {
            strong.push(*a);
        } else {
            weak.push(*a);
        }
    }
    (strong, weak)
}

/// The world point where a contact touches: the point minus its radius along the normal.
pub(crate) fn touch_point(model: &Model, a: &Active, q: &DVector<f64>) -> Option<Vector3<f64>> {
    match a.row {
        Unilateral::Contact { point, ground } => {
            let x = unilateral::point_world(model, point, q);
            let (_, normal) = unilateral::surface(model, ground, &x);
            Some(x - normal * model.contact_points[point].radius)
        }
        Unilateral::Limit { .. } => None,
    }
}

/// The active-set iteration from an assembled state (module docs).
///
/// # Errors
/// As [`crate::solve`]; [`crate::Error::Assembly`] if the initially violated inequalities
/// cannot be met together with the joints.
pub(crate) fn solve(
    model: &Model,
    start: crate::State,
    locks: &[(crate::model::JointId, usize, f64)],
    options: &Options,
) -> crate::Result<(crate::State, crate::solver::Report)> {
    let all = inequalities(model, options);
    let tol = options.gap_tolerance;
    let threshold = options.force_tolerance * force_scale(model);
    let mut state = start;
    // Inequalities violated or touching at the start are active from the start (a sticking
    // contact that touches at the start is held where it is).
    let mut active: Vec<Active> = Vec::new();
    for u in all.iter().filter(|u| {
        unilateral::gap(model, u, &state.q, &state.branches)
            .is_some_and(|g| dimensionless(model, u, g) <= tol)
    }) {
        let a = super::patch::activate(model, options, &active, *u, &state.q);
        active.push(a);
    }
    // The inequalities active from the start count as changes in the report, not towards the
    // cycling guard (a rope lying on the ground starts with hundreds).
    let mut changes = active.len();
    let initial = changes;
    let mut rolls = 0;
    let mut touched = Vec::new();
    super::rolling::record_touches(model, &active, &state.q, &mut touched);
    let mut iterations = 0;
    let mut counters = crate::solver::Diagnostics::default();
    let (mut history, mut iterates) = (Vec::new(), Vec::new());
    let mut rounds = 0;
    // The inequalities released once already (they leave again only alone, at a stationary
    // point: module `release`).
    let mut released_before: Vec<Unilateral> = Vec::new();
    // The contacts that let go of a floating body in the last round (module `let_go`).
    let mut let_go: Vec<Unilateral> = Vec::new();
    // The inequalities the last step met (module `guard`: some may be false hits).
    let mut hits: Vec<Unilateral> = Vec::new();
    // A row that leaves again alone and comes straight back (module `release`).
    let mut returns = super::release::Returns::default();
    // The sticking contacts that came back that way and slide from then on (module `slide`).
    let mut slid = super::slide::Slid::default();
    // Stops that the step kept held at the last release (module `release_trial`): not
    // eligible to leave early in the next round; and that round's first direction.
    let mut next = super::release_trial::Next::default();
    // The end of a step cut at a rolling hull's next vertex, passed across the hand-over to
    // the round after it (module `roll_on`).
    let mut roll_on = super::roll_on::RollOn::default();
    let mut carry = None;
    // Converged points left along the critical cone's direction of negative curvature.
    let mut cone_leaves = 0;
    loop {
        let mut branches = state.branches.clone();
        let q = super::guard::project_past_false_hits(
            model,
            state.q,
            &mut branches,
            locks,
            &mut active,
            &std::mem::take(&mut hits),
            options,
            tol,
        )?;
        let inactive: Vec<Unilateral> = all
            .iter()
            .filter(|u| !active.iter().any(|a| a.row == **u))
            .copied()
            .collect();
        let prior = std::mem::take(&mut next);
        let mut guard = Guard::new(model, options, inactive, &active, tol, &q)
            .with_true_gaps(&std::mem::take(&mut let_go))
            .holding(&active, locks, options)
            .rolling_on(&active);
        guard.falling = prior.falling;
        // `max_iterations` bounds the iterations of all rounds together.
        let budget = Options {
            max_iterations: options.max_iterations.saturating_sub(iterations),
            ..options.clone()
        };
        let not_early = [released_before.as_slice(), &prior.kept].concat();
        let release = super::release::Release::new(model, &active, &not_early, threshold)
            .holding_patch_neighbours(&active)
            .starting_with(prior.first)
            .carrying(carry.take())
            .cycling(changes - initial >= options.max_iterations);
        let round = crate::solver::solve_round(
            model,
            crate::State { q, branches },
            locks,
            &active,
            Some(&guard),
            Some(&release),
            &budget,
        )?;
        iterations += round.report.iterations;
        counters.add_counts(&round.report.diagnostics);
        state = round.state;
        let mut report = round.report;
        rounds += 1;
        report.history.iter_mut().for_each(|h| h.round = rounds);
        crate::solver::report::append_history(
            &mut history,
            &mut iterates,
            std::mem::take(&mut report.history),
            std::mem::take(&mut report.iterates),
        );
        let energy = history.last().map_or(0.0, |h| h.potential_energy);
        carry = roll_on.after_round(
            report.iterations,
            round.blocked.is_some(),
            !round.released.is_empty(),
            round.carry,
        );
        let met: Vec<Unilateral> = round
            .blocked
            .iter()
            .flatten()
            .filter(|&&k| !guard.is_roll_limit(k))
            .map(|&k| guard.inactive[k])
            .collect();
        let returned =
            !met.is_empty() && returns.met(&met, energy, force_scale(model) * model.length_scale);
        let slides = slid.now(returned, &mut returns);
        let cycling = changes - initial >= options.max_iterations || (returned && !slides);
        if !round.released.is_empty() && !cycling {
            // Rows pulling hard before the round was stationary (module `release`), or rows
            // carried past an obstacle's edge by a stalled round (module `stall`: its line
            // search is reported failed), guarded by their true gap next.
            if report.termination == crate::solver::Termination::LineSearchFailed {
                let_go = round.released.iter().map(|&i| active[i].row).collect();
            }
            let gone = super::release_trial::decide_early(
                (model, options, locks),
                &state,
                (&active, &all),
                (&released_before, threshold),
                round.released.clone(),
            )
            .counted(&mut counters, &mut next);
            changes += super::release::leave(
                (model, options, &state.q),
                &gone,
                &mut active,
                &mut released_before,
                &mut touched,
            );
            continue;
        }
        let mut rolled_too_far = false;
        if let (Some(hit), false) = (&round.blocked, cycling) {
            // A sphere that reached its roll limit is re-anchored where it touches now.
            if hit.iter().any(|&k| guard.is_roll_limit(k)) {
                super::rolling::reanchor(model, options, &mut active, &touched, &state.q);
                rolls += 1;
            }
            for &k in hit.iter().filter(|&&k| !guard.is_roll_limit(k)) {
                let a =
                    super::patch::activate(model, options, &active, guard.inactive[k], &state.q);
                active.push(slid.joining(a));
                hits.push(guard.inactive[k]);
                changes += 1;
            }
            super::rolling::record_touches(model, &active, &state.q, &mut touched);
            if rolls <= super::rolling::MAX_ROLLS {
                continue;
            }
            report.termination = crate::solver::Termination::Unbounded;
            rolled_too_far = true;
        }
        // A round whose line search failed while active rows pull (a box sliding over the
        // edge of a finite ramp, its contacts at the edge pulling it back) is not a rest
        // either: those rows leave as at a stationary point, and the next round goes on.
        let failed = report.termination == crate::solver::Termination::LineSearchFailed;
        let stuck = failed
            && !super::release::all_to_release(model, &round.multipliers, threshold).is_empty();
        // Or while its contacts no longer hold a floating body (module `let_go`).
        let hanging = if failed && !stuck && !cycling && !rolled_too_far {
            super::let_go::opened(model, &active, &state)
        } else {
            Vec::new()
        };
        let_go = hanging.iter().map(|&i| active[i].row).collect();
        if !hanging.is_empty() {
            changes += super::release::leave(
                (model, options, &state.q),
                &hanging,
                &mut active,
                &mut released_before,
                &mut touched,
            );
            continue;
        }
        if (report.converged() || stuck) && !cycling && !rolled_too_far {
            let mut gone = super::release::all_to_release(model, &round.multipliers, threshold);
            // Several at once only among rows never released before (module `release`).
            let fresh: Vec<usize> = gone
                .iter()
                .copied()
                .filter(|&i| !released_before.contains(&active[i].row))
                .collect();
            let ctx = (model, options, locks);
            let early = (released_before.as_slice(), threshold);
            if fresh.is_empty() {
                // Rows released before leave together only where the step with all of them
                // released moves off every one (module `release_trial`); else the one
                // pulling hardest leaves alone.
                let decided = (gone.len() >= 2).then(|| {
                    super::release_trial::decide(ctx, &state, (&active, &all), early, gone.clone())
                });
                match decided {
                    Some(d) if d.consistent() => gone = d.counted(&mut counters, &mut next),
                    Some(d) => {
                        d.counted(&mut counters, &mut super::release_trial::Next::default());
                        gone.truncate(1);
                    }
                    None => gone.truncate(1),
                }
                if let [i] = gone[..] {
                    returns.left(active[i].row, energy);
                }
            } else {
                gone = super::release_trial::decide(ctx, &state, (&active, &all), early, fresh)
                    .counted(&mut counters, &mut next);
            }
            if !gone.is_empty() {
                gone.sort_unstable();
                changes += super::release::leave(
                    (model, options, &state.q),
                    &gone,
                    &mut active,
                    &mut released_before,
                    &mut touched,
                );
                continue;
            }
            // Not after a slide (module `slide`).
            if !slid.any()
                && super::rolling::reanchor(model, options, &mut active, &touched, &state.q)
            {
                rolls += 1;
                if rolls <= super::rolling::MAX_ROLLS {
                    continue;
                }
                report.termination = crate::solver::Termination::Unbounded;
            }
        }
        if cycling {
            report.termination = crate::solver::Termination::ActiveSetCycling;
        }
        let mut judging = 0.0;
        // A round stopped at an inequality or a roll limit, or before it was stationary, has
        // no verdict of its own.
        if (cycling || rolled_too_far) && (round.blocked.is_some() || !round.released.is_empty()) {
            let judged = std::time::Instant::now();
            report.stability = crate::solver::stability_on(
                model,
                &state,
                &active,
                Backend::of(model, options),
                options.eigenvalues,
            );
            judging = judged.elapsed().as_secs_f64();
        }
        report.iterations = iterations;
        (report.history, report.iterates) = (history, iterates);
        let own = report.diagnostics.clone();
        report.diagnostics = counters;
        report.diagnostics.gradient_norm = own.gradient_norm;
        report.diagnostics.gradient_tolerance = own.gradient_tolerance;
        report.diagnostics.constraint_residual = own.constraint_residual;
        report.diagnostics.linear_algebra = own.linear_algebra;
        report.diagnostics.eigenvalues_by = own.eigenvalues_by;
        report.diagnostics.free_directions = own.free_directions;
        report.diagnostics.load_steps = 1;
        report.active_set_changes = changes;
        let sticking =
            super::describe::describe(model, options, &state, &round.multipliers, &mut report);
        report.friction = crate::solver::friction::verdict(&sticking, round.chosen);
        crate::solver::friction::settle_states(&mut report.contacts, report.friction.as_ref());
        report.balance = crate::solver::balance::Balance::of(model, &state, &report.contacts);
        // Judged with every active row held; where some touch without a force, on the
        // critical cone instead (module `cone`).
        let judged = std::time::Instant::now();
        let (strong, weak) = split(model, &round.multipliers, threshold);
        if report.converged() && !weak.is_empty() {
            // The round held all of them as rows: its verdict's eigenvalues are reported.
            report.stability = crate::solver::stability_verdict_after_round(
                model,
                &state,
                (&strong, &weak),
                Backend::of(model, options),
                options.eigenvalues,
                report.stability.take(),
            );
        }
        // Stops and contacts carrying a force that leave no feasible motion: a strict
        // minimum (`stability_on`).
        if report.converged() && report.stability.is_none() && !strong.is_empty() {
            report.stability = crate::solver::stability_on(
                model,
                &state,
                &strong,
                Backend::of(model, options),
                options.eigenvalues,
            );
        }
        report.diagnostics.timings.stability += judging + judged.elapsed().as_secs_f64();
        // A converged point that the critical cone judges unstable is left, the weak rows its
        // direction opens released, and the search goes on (module `stability::leave`).
        if crate::solver::stability::leave::should_leave(&report, options, &weak, cone_leaves) {
            let backend = Backend::of(model, options);
            let left = crate::solver::stability::leave::leave(
                model, &state, &strong, &weak, backend, options,
            );
            if let Some((q, opened)) = left {
                cone_leaves += 1;
                state.q = q;
                active.retain(|a| !opened.contains(a));
                changes += opened.len();
                history = std::mem::take(&mut report.history);
                iterates = std::mem::take(&mut report.iterates);
                counters = std::mem::take(&mut report.diagnostics);
                continue;
            }
        }
        return Ok((state, report));
    }
}
