//! Static equilibrium by generalized coordinate partitioning: minimize `V(q)` subject to
//! `Φ(q) = 0` (paper eq. 27).
//!
//! 1. Initial state by forward kinematics with the initial joint values; loop joints are closed
//!    by a damped Newton iteration that holds the joints given initial values where it can
//!    (module `assemble`). A floating group set on the ground by the ground start that cannot
//!    stand there topples first, as a rigid body (module `topple`).
//! 2. Partition `q = [u; v]` by full pivoting of `Φ_q` (module `partition`).
//! 3. Minimize `f(v) = V(u(v), v)` (module `minimize`; its direction, step limit and line
//!    search in folder `step`), with the corrector keeping `Φ = 0`.
//! 4. Stability from the eigenvalues of the reduced Hessian (folder `stability`); reactions
//!    from the multipliers `μ` (`V_qᵀ = Φ_qᵀ μ`, module `reactions`).
//!
//! Stops and contacts (`g(q) ≥ 0`) wrap steps 2–4 in an active-set iteration (folder
//! `inequality`; the friction verdict on their forces is folder `friction`). The evaluation
//! of the partitioned problem (corrector, reduced gradient and Hessian, dense or sparse
//! backend) is folder `system`; the large-scale linear algebra is folder `sparse`.
//!
//! ## References
//! - P. E. Nikravesh, O. K. Srinivasan, Generalized co-ordinate partitioning in static
//!   equilibrium analysis of large-scale mechanical systems, *Int. J. Numer. Meth. Eng.* 21
//!   (1985) 451–464.

mod assemble;
pub mod balance;
pub(crate) mod finite;
pub(crate) mod friction;
mod inequality;
mod load_steps;
mod minimize;
mod mode_animation;
mod options;
pub(crate) mod partition;
mod reactions;
mod report;
pub(crate) mod sparse;
mod stability;
mod step;
pub(crate) mod system;
mod topple;
pub(crate) mod tree;
mod unbounded;
pub(crate) mod valley;

pub use mode_animation::mode_animation;
pub use options::{
    ContactPolicy, Limits, LinearAlgebra, Method, Options, Progress, ProgressFn, StopSearch, Topple,
};
pub use report::{
    ActiveLimit, Contact, ContactState, Diagnostics, FrictionVerdict, Iterate, Mode, Reaction,
    Report, Sizes, Stability, Termination, Timings, Verdict,
};
pub(crate) use stability::eigen;
pub(crate) use stability::svd;
pub(crate) use stability::verdict::{
    stability_of, stability_on, stability_verdict, stability_verdict_after_round,
};
pub use topple::Toppled;

use crate::constraints::unilateral::Active;
use crate::constraints::Constraints;
use crate::error::{Error, Result};
use crate::kinematics::Branches;
use crate::model::{JointId, Model};
use crate::state::{JointValues, State};
use inequality::{active_set, distribution};
use nalgebra::DVector;
use stability::{spectrum, verdict};
use system::{Backend, System};

/// Initial guess: forward kinematics with every joint at its `mech:initial` / `--initial`
/// value (0 otherwise). Loop joints are not yet closed.
pub fn initial_state(model: &Model) -> State {
    State::initial(model)
}

/// The model's initial values by joint (missing coordinates 0), a lock's value replacing the
/// initial value of the coordinate it holds (the start is then on the lock's branch: a lock at
/// 3.2 rad is not read as 3.2 − 2π).
pub(crate) fn initial_values(model: &Model) -> JointValues {
    crate::state::initial_values(model)
}

/// Locks resolved to values: the given value, else the initial value, else 0.
pub(crate) fn lock_values(model: &Model) -> Vec<(JointId, usize, f64)> {
    model
        .locks
        .iter()
        .map(|l| {
            let init = model
                .initial
                .iter()
                .find(|i| i.joint == l.joint && i.dof == l.dof)
                .map_or(0.0, |i| i.value);
            (l.joint, l.dof, l.value.unwrap_or(init))
        })
        .collect()
}

/// Closes the constraints from `q` without the initial-value holds (see module `assemble`),
/// with joint angles read on (and moved along) `branches`.
pub(crate) fn assemble_only(
    model: &Model,
    q: nalgebra::DVector<f64>,
    branches: &mut Branches,
    locks: &[(JointId, usize, f64)],
) -> Result<nalgebra::DVector<f64>> {
    assemble::project(model, q, branches, locks, &[], &Options::default())
}

/// Finds the stable static equilibrium of `model` from its initial guess (a floating
/// mechanism with grounds and no base pose given starts with its lowest contact point on the
/// grounds, module `assemble`, and topples first if it cannot stand there: [`Options::topple`],
/// [`Report::toppled`]).
///
/// # Errors
/// [`Error::Assembly`] if the loops cannot be closed from the initial guess,
/// [`Error::Inconsistent`] for contradictory redundant constraints,
/// [`Error::ForceTableOutOfRange`] if the energy cannot be evaluated at the start,
/// [`Error::SingularPartition`] if the partition fails there, [`Error::ConstantEnergy`] if the
/// mechanism can move but nothing stores energy, [`Error::TooManyDegreesOfFreedom`] for BFGS /
/// DFP on a large model. Not converging is not an error: see
/// [`Report::termination`].
///
/// # Example
/// ```
/// let loaded = restpose::urdf::load_file("robots/pendulum.urdf", &Default::default()).unwrap();
/// let (state, report) = restpose::solve(&loaded.model, &Default::default()).unwrap();
/// assert!(report.converged());
/// assert!((report.energy.total + 18.686957).abs() < 1e-6);
/// # let _ = state;
/// ```
pub fn solve(model: &Model, options: &Options) -> Result<(State, Report)> {
    let start = assemble::grounded_start(model, initial_state(model));
    solve_started(model, start, options, assemble::ground_start(model))
}

/// Like [`solve`], from a given (not necessarily assembled) state.
///
/// # Errors
/// As [`solve`].
pub fn solve_from(model: &Model, start: State, options: &Options) -> Result<(State, Report)> {
    solve_started(model, start, options, false)
}

/// [`solve_from`]; a ground start (`grounded`) first topples the floating groups that cannot
/// stand on it (module `topple`).
fn solve_started(
    model: &Model,
    start: State,
    options: &Options,
    grounded: bool,
) -> Result<(State, Report)> {
    let started = std::time::Instant::now();
    let locks = lock_values(model);
    let mut branches = start.branches;
    let mut q = assemble::assemble(model, start.q, &mut branches, &locks, options)?;
    let toppled = if grounded {
        topple::topple(model, &mut q, options)
    } else {
        Vec::new()
    };
    if !toppled.is_empty() {
        branches.follow(model, &q);
    }
    let q = State { q, branches };
    let assembly = started.elapsed().as_secs_f64();
    let (state, mut report) =
        if let Some(fall) = unbounded::fall_at_start(model, &q, &locks, options)? {
            fall
        } else {
            load_steps::solve(model, q, &locks, options)?
        };
    // Everything after the assembly that is not the final stability is iterations (load
    // stages and a direct attempt before a ramp included).
    report.toppled = toppled;
    let t = &mut report.diagnostics.timings;
    t.assembly = assembly;
    t.iterations = (started.elapsed().as_secs_f64() - assembly - t.stability).max(0.0);
    Ok((state, report))
}

/// BFGS / DFP store a dense `dof × dof` inverse-Hessian approximation: refused above this.
const QUASI_NEWTON_DOF_LIMIT: usize = 2000;

/// Minimizes from an assembled `q`: partition, minimize, stability, reactions.
pub(crate) fn solve_assembled(
    model: &Model,
    start: State,
    locks: &[(JointId, usize, f64)],
    options: &Options,
) -> Result<(State, Report)> {
    if !active_set::inequalities(model, options).is_empty() {
        return active_set::solve(model, start, locks, options);
    }
    let round = solve_round(model, start, locks, &[], None, None, options)?;
    Ok((round.state, round.report))
}

/// One equality-constrained solve of the active-set iteration (module `active_set`).
pub(crate) struct Round {
    pub(crate) state: State,
    pub(crate) report: Report,
    /// The inactive inequalities (indices into the guard's list) that stopped the last step.
    pub(crate) blocked: Option<Vec<usize>>,
    /// The active inequalities (indices into the active list) that leave before the round
    /// was stationary (module `inequality::release`).
    pub(crate) released: Vec<usize>,
    /// The end of the step tried where the last step was cut at a rolling hull's next vertex
    /// (module `inequality::roll_on`).
    pub(crate) carry: Option<nalgebra::DVector<f64>>,
    /// Multipliers of the rows of each active inequality.
    pub(crate) multipliers: Vec<(Active, Vec<f64>)>,
    /// `required_mu` and slipping, where module `friction` chose the distribution.
    pub(crate) chosen: Option<(Option<f64>, bool)>,
}

/// Minimizes from an assembled `q` with the active inequalities `active` as rows, stopping
/// where a step meets an inequality of `guard`.
pub(crate) fn solve_round(
    model: &Model,
    start: State,
    locks: &[(JointId, usize, f64)],
    active: &[Active],
    guard: Option<&active_set::Guard>,
    release: Option<&inequality::release::Release>,
    options: &Options,
) -> Result<Round> {
    let q = start.q;
    let cons = Constraints::new(model, locks)
        .with_active(model, active)
        .on_branches(start.branches.clone());
    let mut sys = System::new(model, cons, Backend::of_round(model, options));
    let part = sys.partition(&q);
    let dof0 = part.independent.len();
    if options.method != Method::Newton && dof0 > QUASI_NEWTON_DOF_LIMIT {
        return Err(Error::TooManyDegreesOfFreedom {
            method: serde_json::to_value(options.method)
                .ok()
                .and_then(|v| v.as_str().map(str::to_owned))
                .unwrap_or_default(),
            dof: dof0,
            limit: QUASI_NEWTON_DOF_LIMIT,
            gigabytes: (dof0 * dof0 * 8) as f64 / 1e9,
        });
    }
    if dof0 > 0 && !crate::forces::has_energy(model) {
        return Err(Error::ConstantEnergy {
            file: model.source_file(),
            robot: model.name.clone(),
            dof: dof0,
        });
    }
    let rank = part.rows.len();
    let Some(out) = minimize::minimize(&mut sys, q.clone(), part, options, guard, release) else {
        return Err(
            crate::forces::undefined_term(model, &start.branches, &q).unwrap_or(
                Error::SingularPartition {
                    at: "the assembled initial guess".into(),
                    rows: rank,
                },
            ),
        );
    };
    let iteration = out.history.last().map_or(0, |h| h.iteration);
    if !out.eval.energy.total.is_finite() {
        return Err(Error::NonFiniteEnergy {
            at: format!("iteration {iteration} of the solve"),
            term: crate::forces::finite::non_finite_term(model, &sys.problem.cons.branches, &out.q),
        });
    }
    if let Some(i) = out.q.iter().position(|x| !x.is_finite()) {
        return Err(Error::NonFinite {
            what: format!("coordinate {}", model.coordinate_name(i)),
            iteration,
        });
    }
    let state = State {
        q: out.q.clone(),
        branches: sys.problem.cons.branches.clone(),
    };
    let dof = out.part.independent.len();
    let mut diagnostics = out.diagnostics;
    diagnostics.linear_algebra = sys.backend.name().into();
    let stability_started = std::time::Instant::now();
    let mut mu = DVector::zeros(sys.problem.cons.len());
    for (k, &row) in out.part.rows.iter().enumerate() {
        mu[row] = out.eval.mu[k];
    }
    let mut chosen = None;
    // The distribution among redundant stops and contacts, at a rest pose only: a round
    // stopped by an inequality (blocked) or before it was stationary (released) is not one,
    // and the active-set iteration goes on from it (as for the stability verdict below).
    if !active.is_empty()
        && !out.part.redundant.is_empty()
        && out.released.is_empty()
        && out.blocked.is_none()
    {
        chosen = distribution::spread(
            model,
            &sys.problem.cons,
            &out.q,
            &out.part,
            &out.eval.factors,
            &mut mu,
            options,
        );
    }
    let multipliers = active_set::active_multipliers(&sys.problem.cons, &mu);
    // A round stopped by an inequality is not a rest pose: the active-set iteration goes on
    // from it (and judges stability itself if it ends there).
    // Where the minimizer judged by the KKT inertia (many degrees of freedom), that verdict,
    // unless eigenvalues are asked for (module `stability::at_rest`): then the spectrum, with
    // that verdict's `λ_max` (the same estimate at the same point).
    let stability = (dof > 0 && out.blocked.is_none() && out.released.is_empty()).then(|| {
        if let (Some(judged), false) = (out.inertia, options.eigenvalues) {
            diagnostics.eigenvalues_by = "inertia".into();
            return Some(Stability {
                verdict: judged.verdict,
                tolerance: judged.tolerance,
                eigenvalues: Vec::new(),
                modes: Vec::new(),
            });
        }
        let largest = out.inertia.map(|judged| judged.largest);
        let eig = out.eigen.clone().unwrap_or_else(|| {
            spectrum::spectrum_knowing(&mut sys, &out.q, &out.part, &out.eval, largest)
        });
        diagnostics.eigenvalues_by = if eig.exact { "exact" } else { "lanczos" }.into();
        // A converged round whose verdict the active set will not use (every active row a
        // stop, more than `MAX_WEAK` of them touching without a force:
        // `Release::needs_verdict`) labels how its spectrum was taken and forms no verdict.
        let needed = out.termination != Termination::Converged
            || release.is_none_or(|r| r.needs_verdict(&multipliers));
        needed.then(|| verdict::from_spectrum(&sys, &out.q, &out.part, &out.eval, &eig))
    });
    let stability = stability.flatten();
    let reactions = reactions::reactions(&sys, &out.q, &mu);
    let blocked = out.blocked;
    let released = out.released;
    let carry = out.carry;
    // After the minimizer's verdict at the rest (`minimize::convergence_test`).
    diagnostics.timings.stability += stability_started.elapsed().as_secs_f64();
    let mut history = out.history;
    for h in &mut history {
        h.load_step = 1;
        h.round = 1;
    }
    let report = Report {
        termination: out.termination,
        iterations: history.last().map_or(0, |h| h.iteration),
        energy: out.eval.energy,
        dof,
        history,
        independent_coordinates: out
            .part
            .independent
            .iter()
            .map(|&i| model.coordinate_name(i))
            .collect(),
        redundant_constraints: out
            .part
            .redundant
            .iter()
            .map(|&r| sys.problem.cons.row_name(model, r))
            .collect(),
        stability,
        reactions,
        diagnostics,
        sizes: Sizes {
            bodies: model.bodies.len(),
            coordinates: model.coordinate_count(),
            constraint_rows: sys.problem.cons.len(),
        },
        iterates: {
            let mut branches = start.branches;
            out.iterates
                .into_iter()
                .map(|q| {
                    branches.follow(model, &q);
                    State {
                        q,
                        branches: branches.clone(),
                    }
                })
                .collect()
        },
        contacts: Vec::new(),
        active_limits: Vec::new(),
        active_set_changes: 0,
        friction: None,
        balance: None,
        toppled: Vec::new(),
    };
    Ok(Round {
        state,
        report,
        blocked,
        released,
        carry,
        multipliers,
        chosen,
    })
}
