//! `analyze` confirms its answer with `verify`'s independent checks (the constraint residual,
//! closure, the efforts and forces that hold the pose from their own partition of the model's
//! rows with every joint coordinate locked, stops and contacts; no projected gradient, which
//! the pass does not read, and no stability, which the solver has judged) on the pose exactly as `verify` reads it back from the result
//! JSON: the joint values, and the world poses of the bodies joint values cannot place. An
//! answer they reject is reported as `rejected_by_verify` (exit 3), never as converged.
//!
//! Tolerances: `verify`'s defaults, with the constraint tolerance (on the same `‖DΦ‖∞`) no
//! tighter than the solve's.

use super::args::AnalyzeArgs;
use restpose::verify::{Eigenvalues, Tolerances, Unilaterals};
use restpose::{Model, State};

/// Why `verify` would reject `state`, or `None` when it passes.
pub(crate) fn rejection(a: &AnalyzeArgs, model: &Model, state: &State) -> Option<String> {
    let values = state
        .joint_values(model)
        .into_iter()
        .filter(|(_, v)| !v.is_empty())
        .collect();
    // And the floating bases, whose poses `verify` reads from the JSON's `links` too.
    let mut moved = vec![false; model.bodies().len()];
    for j in model.joints().iter().filter(|j| j.tree && !j.merged) {
        if let Some(c) = j.bodies[1] {
            moved[c.index()] = true;
        }
    }
    let roots = model.body_ids().filter(|b| !moved[b.index()]);
    let bodies: Vec<_> = State::bodies_without_values(model)
        .into_iter()
        .chain(roots)
        .map(|b| (b, state.body_pose(b)))
        .collect();
    let read_back = match restpose::verify::pose_state_with_bodies(model, &values, &bodies) {
        Ok((s, _)) => s,
        Err(e) => return Some(e.to_string()),
    };
    let defaults = Tolerances::default();
    let tol = Tolerances {
        constraint: defaults.constraint.max(a.constraint_tolerance),
        ..defaults
    };
    let uni: Unilaterals = a.contact.policy();
    let v = match restpose::verify::verify_reporting(
        model,
        &read_back,
        &tol,
        &uni,
        a.linear_algebra.into(),
        Eigenvalues::Skip,
    ) {
        Ok(v) => v,
        Err(e) => return Some(e.to_string()),
    };
    if v.passed {
        return None;
    }
    let mut why: Vec<String> = v.unilateral.failures.clone();
    if let Some(m) = &v.max_imbalance {
        if m.effort.abs() > v.effort_tolerance {
            why.push(format!(
                "joint `{}` (dof {}) needs an effort of {:.3e} to hold it",
                m.joint, m.dof, m.effort
            ));
        }
    }
    if v.unassigned > v.effort_tolerance {
        why.push(format!("unassigned generalized force {:.3e}", v.unassigned));
    }
    if v.scaled_constraint_residual > tol.constraint {
        why.push(format!(
            "constraint residual ‖DΦ‖∞ = {:.3e}",
            v.scaled_constraint_residual
        ));
    }
    if why.is_empty() {
        why.push("the pose does not pass".into());
    }
    Some(why.join("; "))
}
