//! [`super::verify`] on the dense or the sparse path: the balance of the model's rows, the
//! forces that hold the pose (module `held`), the report of the stops and contacts (module
//! `unilateral`) and the stability verdict.

use super::{
    closures, held, reduced, unilateral, Imbalance, Tolerances, Unilaterals, Verification,
};
use crate::error::Result;
use crate::jet::pair_of;
use crate::model::{JointId, Model};
use crate::solver::system::{Backend, Scaling};
use crate::state::State;

/// The scalar coordinates of the tree joints: `(joint, dof, value)` (values alone: bit for
/// bit those of the coordinates' jets).
pub(super) fn tree_coordinates(model: &Model, state: &State) -> Vec<(JointId, usize, f64)> {
    let mut coords = Vec::new();
    for (i, j) in model.joints.iter().enumerate() {
        if !j.tree || j.merged {
            continue;
        }
        let pair = pair_of(&j.bodies, &state.q, false);
        for dof in 0..j.kind.scalar_coordinates() {
            if let Some(s) = crate::kinematics::coordinate_value(
                j,
                &pair,
                dof,
                state.branches.get(JointId(i), dof),
            ) {
                coords.push((JointId(i), dof, s));
            }
        }
    }
    coords
}

/// [`super::verify`] on the dense (`backend` [`Backend::Dense`]) or the sparse path (the
/// solver's sparse partition, factored by `backend`: [`Backend::Sparse`] or, where the
/// partition fits a tree, [`Backend::Tree`]).
///
/// On the sparse path the stability verdict reuses the partition and evaluation of the
/// balance check and is computed before the forces (kept only when the pose passes), on the
/// same thread: the balance check's memory then serves the forces' locked system, which
/// starts from the balance check's evaluated rows (module `model_rows`). `eigenvalues`: the lowest
/// eigenvalues also where only Lanczos finds them ([`super::Eigenvalues::Always`]).
pub(super) fn verify_on(
    model: &Model,
    state: &State,
    tol: &Tolerances,
    uni: &Unilaterals,
    backend: Backend,
    eigenvalues: super::Eigenvalues,
) -> Result<Verification> {
    let sparse = backend != Backend::Dense;
    let skip = eigenvalues == super::Eigenvalues::Skip;
    let eigenvalues = eigenvalues == super::Eigenvalues::Always;
    // The forces on both paths from the sparse partition (module `held`): one computation,
    // so the dense and the sparse path report the same numbers (a pose balanced to the
    // solver's gradient tolerance leaves the forces determined to about that, and partitions
    // differ in where they put the rest). The tree factors of that partition where the
    // balance check uses them (the same numbers to rounding; module `solver::tree`).
    let forces_backend = if backend == Backend::Tree {
        Backend::Tree
    } else {
        Backend::Sparse
    };
    // Every check passes the finiteness guard first: on the sparse path with the rows of the
    // balance check's system (evaluated once for both, module `reduced`).
    let reduced = if sparse || skip {
        let locks = crate::solver::lock_values(model);
        // Without the verdict (`analyze`'s self-check) no partition of the model's rows, on
        // either path: its only other use is the projected gradient (the dense path's
        // null-space basis), which the pass does not read. The rows are then those of the
        // forces' system (its backend), which takes them (module `model_rows`).
        let backend = if sparse { backend } else { forces_backend };
        Some(reduced::reduced(model, state, &locks, backend, !skip)?)
    } else {
        crate::solver::finite::guard(model, state, "the given pose")?;
        None
    };
    let mut contact = unilateral::UnilateralCheck::default();
    let list = unilateral::touching(model, state, uni, tol.gap, &mut contact);
    let coords = tree_coordinates(model, state);
    let values = coords.as_slice();
    let (phi, scaled, energy, projected_gradient, force_scale, closure, held, stability) =
        if let Some(r) = reduced {
            let closure = closures(model, &r.sys.problem.cons, &r.phi, tol.constraint);
            let scaled = r.sys.problem.scaling.residual(&r.phi);
            let reduced::Reduced {
                phi,
                energy,
                reduced_gradient,
                force_scale,
                mut sys,
                solved,
                potential,
                ..
            } = r;
            let assembled = scaled <= tol.constraint;
            let tau = tol.force + tol.relative * force_scale;
            // Without a stop or contact touching, the forces' first solve is this system's
            // (`held::free_of`), and the verdict is judged on this partition; unpartitioned
            // (no verdict asked), the forces come from the locked solve alone.
            let free = match &solved {
                Some((part, eval)) if list.is_empty() => {
                    held::Free::Given(held::free_of(&sys, part, eval))
                }
                None => held::Free::Skip {
                    joint_space: sparse,
                },
                Some(_) => held::Free::Solve,
            };
            // The verdict first, on this thread; then the balance check's memory (its
            // factors, the KKT matrix and factors of the verdict) goes back before the forces'
            // locked system is built, which reuses it (the two systems alive at once, on two
            // threads, were most of `verify`'s fresh pages: each costs a page fault). The
            // model's rows go to the locked system (module `model_rows`).
            // The verdict takes the evaluation (its factors are freed before the KKT matrix
            // is built, which reuses their memory).
            let stability = match solved {
                Some((part, eval)) if assembled && list.is_empty() && !skip => {
                    crate::solver::stability_of(&mut sys, &state.q, &part, eval, eigenvalues)
                }
                _ => None,
            };
            sys.work.kkt = None;
            let given = held::ModelRows::take(&mut sys, &state.q, values.len(), potential);
            drop(sys);
            let held = held::held(
                model,
                state,
                &list,
                values,
                forces_backend,
                tau,
                free,
                given,
            )?;
            // The verdict of a pose that fails is not reported.
            let stability = stability.filter(|_| passes(scaled, &held, force_scale, tol));
            (
                phi,
                scaled,
                energy,
                reduced_gradient,
                force_scale,
                closure,
                held,
                stability,
            )
        } else {
            let p = super::dense::project(model, state)?;
            let closure = closures(model, &p.cons, &p.phi, tol.constraint);
            let scaled = Scaling::new(model, &p.cons).residual(&p.phi);
            let projected_gradient = (p.null.transpose() * &p.grad_s).amax();
            let force_scale = p.grad_s.amax();
            let tau = tol.force + tol.relative * force_scale;
            let held = held::held(
                model,
                state,
                &list,
                values,
                forces_backend,
                tau,
                held::Free::Solve,
                None,
            )?;
            (
                p.phi,
                scaled,
                p.energy,
                projected_gradient,
                force_scale,
                closure,
                held,
                None,
            )
        };
    let effort_tolerance = tol.force + tol.relative * force_scale;
    let (strong, weak) = unilateral::report(
        model,
        state,
        &list,
        &held.forces,
        &held.pulling,
        held.friction,
        effort_tolerance,
        &mut contact,
    );
    let imbalance: Vec<Imbalance> = coords
        .iter()
        .zip(held.efforts.iter().zip(&held.locked))
        .map(|((id, dof, _), (&effort, &locked))| Imbalance {
            joint: model.joint(*id).name.clone(),
            dof: *dof,
            effort,
            locked,
        })
        .collect();
    let max_imbalance = imbalance
        .iter()
        .filter(|i| !i.locked)
        .max_by(|a, b| a.effort.abs().total_cmp(&b.effort.abs()))
        .cloned();
    let constraint_residual = phi.amax();
    let balanced = passes(scaled, &held, force_scale, tol);
    let passed = contact.settle(tol.gap, balanced) && balanced;
    if !balanced {
        imbalance_failures(
            model,
            scaled,
            &imbalance,
            held.unassigned,
            effort_tolerance,
            tol,
            &mut contact.failures,
        );
    }
    // The sparse path judged the stability beside the forces where no stop or contact
    // touches; otherwise it is judged here, on the tangent space of those that carry a force
    // and the critical cone of those that touch without one (`solver::cone`).
    let stability = match (passed, sparse) {
        (false, _) => None,
        _ if skip => None,
        (true, true) if strong.is_empty() && weak.is_empty() => stability,
        (true, _) => {
            // With stops or contacts touching: the sparse factors, as before the tree ones.
            let backend = if sparse {
                Backend::Sparse
            } else {
                Backend::Dense
            };
            crate::solver::stability_verdict(model, state, &strong, &weak, backend, eigenvalues)
        }
    };
    Ok(Verification {
        robot: model.name.clone(),
        passed,
        constraint_residual,
        scaled_constraint_residual: scaled,
        closure,
        imbalance,
        max_imbalance,
        unassigned: held.unassigned,
        projected_gradient,
        potential_energy: energy,
        stability,
        tolerances: *tol,
        force_scale,
        effort_tolerance,
        unilateral: contact,
    })
}

/// The failures of the balance, appended to `failures`: the constraint residual `‖D Φ‖∞`, each effort
/// beyond the tolerance (largest first), the unassigned force.
fn imbalance_failures(
    model: &Model,
    residual: f64,
    imbalance: &[Imbalance],
    unassigned: f64,
    effort_tolerance: f64,
    tol: &Tolerances,
    failures: &mut Vec<String>,
) {
    if residual > tol.constraint {
        failures.push(format!(
            "constraint residual ‖D Φ‖∞ = {residual:.3e} beyond the tolerance {:.1e}",
            tol.constraint
        ));
    }
    let mut out: Vec<&Imbalance> = imbalance
        .iter()
        .filter(|i| !i.locked && i.effort.abs() > effort_tolerance)
        .collect();
    // Largest first as printed (4 digits), file order among equals: the dense and the sparse
    // path list them alike.
    let shown = |e: f64| format!("{:.3e}", e.abs()).parse::<f64>().unwrap_or(e.abs());
    out.sort_by(|a, b| shown(b.effort).total_cmp(&shown(a.effort)));
    for i in out {
        let angle = model
            .joint_id(&i.joint)
            .is_none_or(|id| model.joint(id).kind.is_angle(i.dof));
        failures.push(format!(
            "`{}` (dof {}) needs an effort of {:.3e} {} to hold the pose",
            i.joint,
            i.dof,
            i.effort,
            if angle { "N m" } else { "N" }
        ));
    }
    if unassigned > effort_tolerance {
        failures.push(format!(
            "unassigned generalized force {unassigned:.3e} J: no joint coordinate can carry it \
             (a floating base or a spherical joint out of balance)"
        ));
    }
}

/// Whether a pose passes: `‖D Φ‖∞` within the constraint tolerance, every effort of a coordinate
/// no lock holds and the unassigned force within `force + relative · force_scale`.
fn passes(residual: f64, held: &held::Held, force_scale: f64, tol: &Tolerances) -> bool {
    let effort_tolerance = tol.force + tol.relative * force_scale;
    residual <= tol.constraint
        && held
            .efforts
            .iter()
            .zip(&held.locked)
            .all(|(e, &l)| l || e.abs() <= effort_tolerance)
        && held.unassigned <= effort_tolerance
}
