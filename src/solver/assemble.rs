//! Closing the loops: damped Newton on `Φ(q) = 0` from the forward-kinematics guess.
//!
//! Each iteration partitions `Φ_q` afresh and solves `Φ_u δu = −Φ` (the minimal change of the
//! dependent coordinates), halving the step until `‖Φ‖∞` decreases. Joints with an initial
//! value are held by temporary lock rows, so that the loop closes around them (choosing the
//! assembly branch); if that fails, the assembly is retried without them.
//!
//! The projection at the start of each active-set round (`project`) closes the new rows to the
//! constraint tolerance over the partition's independent rows, the redundant ones to
//! `REDUNDANT_FLOOR`. Sticking contacts whose tangential rows are nearly dependent (Vision 60
//! of pybullet_data started flat, its legs on the ground: a pivot of `Φ_u` at `10⁻⁸` of the
//! largest) can hold a row as redundant to `4.5·10⁻⁹` and then, when a contact joins, count it
//! independent: the damped Newton step through that pivot cannot close it. The error then says
//! so and names the remedies (start standing, or frictionless contacts) rather than the base's
//! start pose.

use super::options::Options;
use super::system::residual::REDUNDANT_FLOOR;
use super::system::{Backend, System};
use crate::constraints::unilateral::Active;
use crate::constraints::Constraints;
use crate::error::{Error, Result};
use crate::kinematics::Branches;
use crate::model::{JointId, Model};
use nalgebra::DVector;

/// Why the damped Newton iteration stopped short.
enum Failure {
    /// No decrease after this many iterations.
    Stuck(usize),
    /// The independent rows hold, the redundant row `row` does not: no configuration
    /// satisfies all rows.
    Inconsistent(usize),
}

fn newton(
    sys: &mut System,
    mut q: DVector<f64>,
    tol: f64,
) -> std::result::Result<DVector<f64>, Failure> {
    const MAX: usize = 100;
    for it in 0..MAX {
        let phi = sys.residual(&q).clone();
        if sys.dimensionless_residual() <= tol {
            return Ok(q);
        }
        let part = sys.partition(&q);
        let rows_residual =
            |sys: &System, phi: &DVector<f64>| sys.problem.scaling.residual_over(phi, &part.rows);
        let res = rows_residual(sys, &phi);
        // The redundant rows hold only to rounding once the independent ones do: accepted at
        // the corrector's floor (a contact made active within the gap tolerance is one).
        if res <= tol && sys.dimensionless_residual() <= tol.max(REDUNDANT_FLOOR) {
            return Ok(q);
        }
        if res <= tol {
            // The redundant rows hold only to rounding of the independent ones, or to the
            // gaps below the tolerance at which touching contacts were taken as active:
            // accepted at the floor, as the corrector does.
            if sys.dimensionless_residual() <= tol.max(REDUNDANT_FLOOR) {
                return Ok(q);
            }
            let worst = part
                .redundant
                .iter()
                .copied()
                .max_by(|&a, &b| {
                    let scaling = &sys.problem.scaling;
                    scaling
                        .row_residual(&phi, a)
                        .total_cmp(&scaling.row_residual(&phi, b))
                })
                .unwrap_or_else(|| phi.iamax());
            return Err(Failure::Inconsistent(worst));
        }
        let Some(du) = sys.dependent_step(&q, &part) else {
            return Err(Failure::Stuck(it));
        };
        let mut alpha = 1.0;
        let mut improved = false;
        while alpha >= 1e-4 {
            let mut qt = q.clone();
            for (k, &c) in part.dependent.iter().enumerate() {
                qt[c] += alpha * du[k];
            }
            let trial = sys.residual(&qt).clone();
            if rows_residual(sys, &trial) < res {
                q = qt;
                sys.problem.cons.branches.follow(sys.problem.model, &q);
                improved = true;
                break;
            }
            alpha *= 0.5;
        }
        if !improved {
            return Err(Failure::Stuck(it));
        }
    }
    Err(Failure::Stuck(MAX))
}

/// The start of a floating mechanism placed on the grounds: with grounds, contact points and
/// no base position given (`mech:base`, `--base-xyz`; `--base-rpy` alone gives only the
/// orientation), every group of bodies that no joint holds to the world is translated against
/// gravity (along +z without gravity), as it is (upright when the base starts at the
/// identity, turned as `--base-rpy` says), until its lowest contact point touches the grounds
/// that face that way: `t = max_{c,g} −g_gap(c) / (n_g·û)`. It then settles from there.
pub(crate) fn grounded_start(model: &Model, mut start: crate::State) -> crate::State {
    if !ground_start(model) {
        return start;
    }
    let up = if model.gravity.norm() > 0.0 {
        -model.gravity.normalize()
    } else {
        nalgebra::Vector3::z()
    };
    let (root, world) = super::unbounded::groups(model);
    let mut lift = vec![f64::NEG_INFINITY; model.bodies.len() + 1];
    for (k, c) in model.contact_points.iter().enumerate() {
        let r = root[c.body.0];
        if r == world {
            continue;
        }
        let x = crate::constraints::unilateral::point_world(model, k, &start.q);
        for g in model.grounds.iter().filter(|g| g.normal.dot(&up) > 1e-9) {
            let gap = g.normal.dot(&(x - g.origin)) - c.radius;
            lift[r] = lift[r].max(-gap / g.normal.dot(&up));
        }
    }
    for b in 0..model.bodies.len() {
        let t = lift[root[b]];
        if t.is_finite() {
            for k in 0..3 {
                start.q[7 * b + k] += t * up[k];
            }
        }
    }
    start
}

/// Whether the start is a ground start: grounds and contact points, and no base position
/// given.
pub(crate) fn ground_start(model: &Model) -> bool {
    let placed = model.base_pose.is_some() && !model.base_on_ground;
    !placed && !model.grounds.is_empty() && !model.contact_points.is_empty()
}

/// Assembles `q` (closes loops, applies locks and normalizes) or explains why it cannot.
pub(crate) fn assemble(
    model: &Model,
    q: DVector<f64>,
    branches: &mut Branches,
    locks: &[(JointId, usize, f64)],
    options: &Options,
) -> Result<DVector<f64>> {
    let tol = options.constraint_tolerance;
    let mut held: Vec<(JointId, usize, f64)> = locks.to_vec();
    for i in &model.initial {
        let scalar = i.dof < model.joints[i.joint.0].kind.scalar_coordinates();
        if scalar && !held.iter().any(|l| l.0 == i.joint && l.1 == i.dof) {
            held.push((i.joint, i.dof, i.value));
        }
    }
    if held.len() > locks.len() {
        let cons = Constraints::new(model, &held).on_branches(branches.clone());
        let mut sys = System::new(model, cons, Backend::of(model, options));
        if let Ok(qa) = newton(&mut sys, q.clone(), tol) {
            let cons =
                Constraints::new(model, locks).on_branches(sys.problem.cons.branches.clone());
            let mut fin = System::new(model, cons, Backend::of(model, options));
            fin.residual(&qa);
            if fin.dimensionless_residual() <= tol.max(REDUNDANT_FLOOR) {
                *branches = fin.problem.cons.branches;
                return Ok(qa);
            }
        }
    }
    project(model, q, branches, locks, &[], options)
}

/// Damped Newton onto `Φ = 0` with the given locks and active inequalities only.
pub(crate) fn project(
    model: &Model,
    q: DVector<f64>,
    branches: &mut Branches,
    locks: &[(JointId, usize, f64)],
    active: &[Active],
    options: &Options,
) -> Result<DVector<f64>> {
    let tol = options.constraint_tolerance;
    let cons = Constraints::new(model, locks)
        .with_active(model, active)
        .on_branches(branches.clone());
    let mut sys = System::new(model, cons, Backend::of(model, options));
    let q0 = q.clone();
    match newton(&mut sys, q, tol) {
        Ok(qa) => {
            *branches = sys.problem.cons.branches;
            Ok(qa)
        }
        Err(Failure::Inconsistent(row)) => {
            let residual = sys.phi()[row].abs();
            let loops: Vec<String> = model
                .joints
                .iter()
                .filter(|j| !j.tree)
                .map(|j| format!("`{}`", j.name))
                .collect();
            // The redundant row is the partition's choice; the joint that does not close is
            // the one violated at the start.
            let start = worst_joint_row(&mut sys, &q0);
            Err(Error::Inconsistent {
                site: model
                    .row_site(&sys.problem.cons.row_name(model, start))
                    .or_else(|| model.row_site(&sys.problem.cons.row_name(model, row)))
                    .map(Box::new),
                row: sys.problem.cons.row_name(model, row),
                residual,
                loops: if loops.is_empty() {
                    "none".into()
                } else {
                    loops.join(", ")
                },
            })
        }
        Err(Failure::Stuck(iterations)) => {
            let worst = worst_joint_row(&mut sys, &q0);
            let row = sys.problem.cons.row_name(model, worst);
            // The blocks are in row order: the row is the last block starting at or before it.
            let block = sys
                .problem
                .cons
                .blocks
                .iter()
                .rev()
                .find(|b| b.first <= worst);
            let unilateral = block
                .is_some_and(|b| matches!(b.kind, crate::constraints::BlockKind::Unilateral(_)));
            // A sticking contact's tangential row off by no more than the redundant rows'
            // floor: rows nearly dependent on others (module docs).
            let tangential = block.is_some_and(|b| {
                matches!(b.kind, crate::constraints::BlockKind::Unilateral(a) if a.anchor.is_some())
                    && worst > b.first
            });
            let scaled = sys.problem.scaling.row_residual(sys.phi(), worst);
            let remedy = if tangential && scaled <= REDUNDANT_FLOOR {
                format!(
                    "the sticking contacts' tangential rows are nearly dependent here (several \
                     points of the same links touch the ground and stick, as a leg lying on it), \
                     and a residual of {scaled:.1e} of the characteristic length cannot be closed through them: start the \
                     robot standing above the ground (no `mech:initial` folding its legs onto \
                     it; with servos, their reference pose as the start), or let the contacts \
                     slide (`friction=\"none\"`)"
                )
            } else if unilateral {
                "a contact or stop starts too far inside its bound to be pushed out together with \
                 the joints: start the floating base above the ground (`mech:base`), or the \
                 joints inside their limits (`mech:initial`)"
                    .into()
            } else {
                "check the loop geometry or give `mech:initial` values near an assembled pose"
                    .into()
            };
            Err(Error::Assembly {
                site: model.row_site(&row).map(Box::new),
                residual: sys.phi()[worst].abs(),
                row,
                iterations,
                remedy,
            })
        }
    }
}

/// The most violated row at `q0` (scaled), a joint row rather than a normalization row, which
/// only reflects how Newton steps distorted the Euler parameters; leaves `Φ(q0)` in `sys`.
fn worst_joint_row(sys: &mut System, q0: &DVector<f64>) -> usize {
    let phi = sys.residual(q0).clone();
    (0..phi.len())
        .filter(|&r| !sys.problem.cons.is_normalization(r))
        .max_by(|&a, &b| {
            (phi[a] * sys.problem.scaling.rows[a])
                .abs()
                .total_cmp(&(phi[b] * sys.problem.scaling.rows[b]).abs())
        })
        .unwrap_or_else(|| phi.iamax())
}
