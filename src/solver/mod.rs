//! Static equilibrium by generalized coordinate partitioning: minimize `V(q)` subject to
//! `Φ(q) = 0` (paper eq. 27).
//!
//! 1. Initial state by forward kinematics with the initial joint values; loop joints are closed
//!    by a damped Newton iteration that holds the joints given initial values where it can
//!    (module `assemble`).
//! 2. Partition `q = [u; v]` by full pivoting of `Φ_q` (module `partition`).
//! 3. Minimize `f(v) = V(u(v), v)` (module `minimize`), with the corrector keeping `Φ = 0`.
//! 4. Stability from the eigenvalues of the reduced Hessian; reactions from the multipliers
//!    `μ` (`V_qᵀ = Φ_qᵀ μ`).
//!
//! ## References
//! - P. E. Nikravesh, O. K. Srinivasan, Generalized co-ordinate partitioning in static
//!   equilibrium analysis of large-scale mechanical systems, *Int. J. Numer. Meth. Eng.* 21
//!   (1985) 451–464 (`shared/paper/`).

mod active_set;
mod assemble;
pub mod balance;
mod cone;
mod conic;
mod distribution;
mod eigen;
pub(crate) mod friction;
mod guard;
mod minimize;
mod mode_animation;
mod options;
pub(crate) mod partition;
mod reactions;
mod report;
mod rolling;
pub(crate) mod sparse;
mod spectrum;
mod stability_inertia;
pub(crate) mod system;
mod unbounded;

pub use mode_animation::mode_animation;
pub use options::{Limits, LinearAlgebra, Method, Options};
pub use report::{
    ActiveLimit, Contact, ContactState, Diagnostics, FrictionVerdict, Iterate, Reaction, Report,
    Sizes, Stability, Termination, Timings, Verdict,
};

use crate::constraints::unilateral::Active;
use crate::constraints::Constraints;
use crate::error::{Error, Result};
use crate::kinematics::Branches;
use crate::model::{JointId, Model};
use crate::state::{JointValues, State};
use nalgebra::DVector;
use system::System;

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

/// The stability verdict from the reduced-Hessian eigenvalues (ascending, at least one) and
/// eigenvectors, with the mode shapes of the smallest as joint-coordinate changes.
fn stability(
    sys: &System,
    q: &nalgebra::DVector<f64>,
    part: &partition::Partition,
    eval: &system::Eval,
    spectrum: &spectrum::Spectrum,
) -> Stability {
    let (vals, vecs) = (&spectrum.values, &spectrum.vectors);
    let tol = spectrum.tolerance();
    let negative_by_inertia = spectrum.negative_by_inertia.unwrap_or(0) > 0;
    let verdict = if vals[0] < -tol || negative_by_inertia {
        Verdict::Unstable
    } else if vals[0] <= tol {
        Verdict::Neutral
    } else {
        Verdict::Stable
    };
    let shown = vals.len().min(6);
    // The gradients of every joint coordinate, once for all modes: (joint, per coordinate the
    // (global index, derivative) pairs).
    type Gradient = Vec<(usize, f64)>;
    let gradients: Vec<(&str, Vec<Gradient>)> = if shown == 0 {
        Vec::new()
    } else {
        sys.problem
            .model
            .joints
            .iter()
            .filter(|j| !j.merged)
            .map(|j| {
                let pair = crate::jet::pair_of(&j.bodies, q, false);
                let g = (0..j.kind.scalar_coordinates())
                    .filter_map(|dof| crate::kinematics::coordinate(j, &pair, dof, 0.0))
                    .map(|s| {
                        (0..crate::jet::NL)
                            .filter_map(|i| {
                                crate::jet::global_index(&j.bodies, i).map(|g| (g, s.g[i]))
                            })
                            .collect()
                    })
                    .collect();
                (j.name.as_str(), g)
            })
            .collect()
    };
    let modes = (0..shown)
        .map(|k| {
            let dq = sys.tangent_step(part, eval, &vecs.column(k).into_owned());
            let mut mode = std::collections::BTreeMap::new();
            for (name, coords) in &gradients {
                let d: Vec<f64> = coords
                    .iter()
                    .map(|c| c.iter().map(|&(g, x)| x * dq[g]).sum())
                    .collect();
                if !d.is_empty() {
                    mode.insert(name.to_string(), d);
                }
            }
            let big = mode.values().flatten().fold(0.0f64, |a, &b| a.max(b.abs()));
            if big > 0.0 {
                mode.values_mut().flatten().for_each(|x| *x /= big);
            }
            mode
        })
        .collect();
    Stability {
        verdict,
        tolerance: tol,
        eigenvalues: vals.iter().take(shown).copied().collect(),
        modes,
    }
}

/// Stability verdict at a state that is feasible and balanced (`None` with no degree of
/// freedom or where the energy is undefined).
/// `eigenvalues` as in [`stability_of`].
pub(crate) fn stability_at(model: &Model, state: &State, eigenvalues: bool) -> Option<Stability> {
    stability_on(model, state, &[], eigenvalues)
}

pub(crate) use cone::stability_touching;

/// [`stability_at`] on the tangent space of the equality rows and the inequalities `active`
/// (the stops and contacts that carry a force); `eigenvalues` as in [`stability_of`].
pub(crate) fn stability_on(
    model: &Model,
    state: &State,
    active: &[Active],
    eigenvalues: bool,
) -> Option<Stability> {
    let q = &state.q;
    let sys_cons = Constraints::new(model, &lock_values(model))
        .with_active(model, active)
        .on_branches(state.branches.clone());
    let mut sys = System::new(model, sys_cons);
    let part = sys.partition(q);
    if part.independent.is_empty() {
        return None;
    }
    let eval = sys.evaluate(q, &part)?;
    stability_of(&mut sys, q, &part, &eval, eigenvalues)
}

/// [`stability_at`] with the system of the model's rows already partitioned and evaluated at
/// `q` (what `verify` has made for its balance check); `None` with no degree of freedom.
///
/// Where the eigenvalues would come from Lanczos (sparse path, more than
/// `spectrum::EXACT_UP_TO` degrees of freedom) and `eigenvalues` is false, the verdict comes
/// from the inertia of the shifted KKT matrix alone (module `stability_inertia`), without
/// eigenvalues or mode shapes; Lanczos only if that inertia cannot be trusted.
pub(crate) fn stability_of(
    sys: &mut System,
    q: &nalgebra::DVector<f64>,
    part: &partition::Partition,
    eval: &system::Eval,
    eigenvalues: bool,
) -> Option<Stability> {
    if part.independent.is_empty() {
        return None;
    }
    let lanczos =
        sys.backend == system::Backend::Sparse && part.independent.len() > spectrum::EXACT_UP_TO;
    if lanczos && !eigenvalues {
        if let Some((verdict, tolerance)) = stability_inertia::inertia_verdict(sys, q, part, eval) {
            return Some(Stability {
                verdict,
                tolerance,
                eigenvalues: Vec::new(),
                modes: Vec::new(),
            });
        }
    }
    let eig = spectrum::spectrum(sys, q, part, eval);
    Some(stability(sys, q, part, eval, &eig))
}

/// Finds the stable static equilibrium of `model` from its initial guess.
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
    let start = initial_state(model);
    solve_from(model, start, options)
}

/// Like [`solve`], from a given (not necessarily assembled) state.
///
/// # Errors
/// As [`solve`].
pub fn solve_from(model: &Model, start: State, options: &Options) -> Result<(State, Report)> {
    let started = std::time::Instant::now();
    let locks = lock_values(model);
    let mut branches = start.branches;
    let q = assemble::assemble(model, start.q, &mut branches, &locks, options)?;
    let q = State { q, branches };
    let assembly = started.elapsed().as_secs_f64();
    let (state, mut report) = match options.load_steps {
        0 => {
            let direct = solve_assembled(model, q.clone(), &locks, options)?;
            if direct.1.converged() || direct.1.termination == Termination::Unbounded {
                direct
            } else {
                let ramped = ramp(model, q, AUTOMATIC_LOAD_STEPS, &locks, options)?;
                if ramped.1.converged() {
                    ramped
                } else {
                    direct
                }
            }
        }
        1 => solve_assembled(model, q, &locks, options)?,
        n => ramp(model, q, n, &locks, options)?,
    };
    // Everything after the assembly that is not the final stability is iterations (load
    // stages and a direct attempt before a ramp included).
    let t = &mut report.diagnostics.timings;
    t.assembly = assembly;
    t.iterations = (started.elapsed().as_secs_f64() - assembly - t.stability).max(0.0);
    Ok((state, report))
}

/// BFGS / DFP store a dense `dof × dof` inverse-Hessian approximation: refused above this.
const QUASI_NEWTON_DOF_LIMIT: usize = 2000;

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
    for k in 1..n {
        let stage = model.with_load_factor(k as f64 / n as f64);
        let (s, r) = solve_assembled(&stage, q, locks, options)?;
        q = s;
        iterations += r.iterations;
        counters.add_counts(&r.diagnostics);
    }
    let (s, mut r) = solve_assembled(model, q, locks, options)?;
    r.iterations += iterations;
    r.diagnostics.add_counts(&counters);
    r.diagnostics.load_steps = n;
    Ok((s, r))
}

/// Minimizes from an assembled `q`: partition, minimize, stability, reactions.
fn solve_assembled(
    model: &Model,
    start: State,
    locks: &[(JointId, usize, f64)],
    options: &Options,
) -> Result<(State, Report)> {
    if !active_set::inequalities(model, options).is_empty() {
        return active_set::solve(model, start, locks, options);
    }
    let round = solve_round(model, start, locks, &[], None, options)?;
    Ok((round.state, round.report))
}

/// One equality-constrained solve of the active-set iteration (module `active_set`).
pub(crate) struct Round {
    pub(crate) state: State,
    pub(crate) report: Report,
    /// The inactive inequalities (indices into the guard's list) that stopped the last step.
    pub(crate) blocked: Option<Vec<usize>>,
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
    options: &Options,
) -> Result<Round> {
    let q = start.q;
    let cons = Constraints::new(model, locks)
        .with_active(model, active)
        .on_branches(start.branches.clone());
    let mut sys = System::with_options(model, cons, options);
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
            robot: model.name.clone(),
            dof: dof0,
        });
    }
    let rank = part.rows.len();
    let Some(out) = minimize::minimize(&mut sys, q.clone(), part, options, guard) else {
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
        return Err(Error::NonFinite {
            what: "potential energy".into(),
            iteration,
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
    // A round stopped by an inequality is not a rest pose: the active-set iteration goes on
    // from it (and judges stability itself if it ends there).
    let stability = (dof > 0 && out.blocked.is_none()).then(|| {
        let eig = out
            .eigen
            .clone()
            .unwrap_or_else(|| spectrum::spectrum(&mut sys, &out.q, &out.part, &out.eval));
        diagnostics.eigenvalues_by = if eig.exact { "exact" } else { "lanczos" }.into();
        stability(&sys, &out.q, &out.part, &out.eval, &eig)
    });
    let mut mu = DVector::zeros(sys.problem.cons.len());
    for (k, &row) in out.part.rows.iter().enumerate() {
        mu[row] = out.eval.mu[k];
    }
    let mut chosen = None;
    if !active.is_empty() && !out.part.redundant.is_empty() {
        chosen = distribution::spread(model, &sys.problem.cons, &out.q, &mut mu, options);
    }
    let reactions = reactions::reactions(&sys, &out.q, &mu);
    let multipliers = active_set::active_multipliers(&sys.problem.cons, &mu);
    let blocked = out.blocked;
    diagnostics.timings.stability = stability_started.elapsed().as_secs_f64();
    let report = Report {
        termination: out.termination,
        iterations: out.history.last().map_or(0, |h| h.iteration),
        energy: out.eval.energy,
        dof,
        history: out.history,
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
            .map(|&r| sys.problem.cons.row_name(r).to_string())
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
    };
    Ok(Round {
        state,
        report,
        blocked,
        multipliers,
        chosen,
    })
}
