//! Load stepping around the direct solve: gravity, loads and efforts scaled by `k / n`,
//! `k = 1 … n`, each stage starting from the previous rest pose. `Options::max_iterations`
//! bounds all stages together: with automatic stepping (`load_steps = 0`) the direct attempt
//! gets half of it, and a ramp after a failed direct attempt what the attempt left.

use super::report::append_history;
use super::{solve_assembled, Diagnostics, Options, Report, Termination};
use crate::error::Result;
use crate::model::{JointId, Model};
use crate::state::State;

/// The solve from an assembled `q` under `options.load_steps` (module docs).
///
/// # Errors
/// As [`crate::solve`].
pub(crate) fn solve(
    model: &Model,
    q: State,
    locks: &[(JointId, usize, f64)],
    options: &Options,
) -> Result<(State, Report)> {
    match options.load_steps {
        0 => {
            let half = Options {
                max_iterations: options.max_iterations - options.max_iterations / 2,
                ..options.clone()
            };
            let direct = solve_assembled(model, q.clone(), locks, &half)?;
            let left = options.max_iterations.saturating_sub(direct.1.iterations);
            if direct.1.converged() || direct.1.termination == Termination::Unbounded || left == 0 {
                return Ok(direct);
            }
            let budget = Options {
                max_iterations: left,
                ..options.clone()
            };
            let mut ramped = ramp(model, q, AUTOMATIC_LOAD_STEPS, locks, &budget)?;
            if ramped.1.converged() {
                // The history shows the abandoned direct attempt first (load step 0).
                let (mut history, mut iterates) = (direct.1.history, direct.1.iterates);
                for h in &mut history {
                    h.load_step = 0;
                }
                let r = &mut ramped.1;
                r.iterations += direct.1.iterations;
                r.diagnostics.add_counts(&direct.1.diagnostics);
                append_history(
                    &mut history,
                    &mut iterates,
                    std::mem::take(&mut r.history),
                    std::mem::take(&mut r.iterates),
                );
                (r.history, r.iterates) = (history, iterates);
                Ok(ramped)
            } else {
                Ok(direct)
            }
        }
        1 => solve_assembled(model, q, locks, options),
        n => ramp(model, q, n, locks, options),
    }
}

/// Load steps tried when a direct solve does not converge (`Options::load_steps = 0`).
const AUTOMATIC_LOAD_STEPS: usize = 8;

/// Load stepping: solves with gravity, loads and efforts scaled by `k / n`, `k = 1 … n`, each
/// stage starting from the previous rest pose.
fn ramp(
    model: &Model,
    mut q: State,
    n: usize,
    locks: &[(JointId, usize, f64)],
    options: &Options,
) -> Result<(State, Report)> {
    let mut iterations = 0;
    let mut counters = Diagnostics::default();
    let (mut history, mut iterates) = (Vec::new(), Vec::new());
    for k in 1..n {
        let stage = model.with_load_factor(k as f64 / n as f64);
        let budget = Options {
            max_iterations: options.max_iterations.saturating_sub(iterations),
            ..options.clone()
        };
        let (s, mut r) = solve_assembled(&stage, q, locks, &budget)?;
        q = s;
        r.history.iter_mut().for_each(|h| h.load_step = k);
        if !r.converged() {
            // A stage that did not come to rest ends the ramp (out of iterations, or no rest).
            r.iterations += iterations;
            r.diagnostics.add_counts(&counters);
            r.diagnostics.load_steps = n;
            append_history(
                &mut history,
                &mut iterates,
                std::mem::take(&mut r.history),
                std::mem::take(&mut r.iterates),
            );
            (r.history, r.iterates) = (history, iterates);
            return Ok((q, r));
        }
        iterations += r.iterations;
        counters.add_counts(&r.diagnostics);
        append_history(&mut history, &mut iterates, r.history, r.iterates);
    }
    let budget = Options {
        max_iterations: options.max_iterations.saturating_sub(iterations),
        ..options.clone()
    };
    let (s, mut r) = solve_assembled(model, q, locks, &budget)?;
    r.iterations += iterations;
    r.diagnostics.add_counts(&counters);
    r.diagnostics.load_steps = n;
    r.history.iter_mut().for_each(|h| h.load_step = n);
    append_history(
        &mut history,
        &mut iterates,
        std::mem::take(&mut r.history),
        std::mem::take(&mut r.iterates),
    );
    (r.history, r.iterates) = (history, iterates);
    Ok((s, r))
}
