//! The guard every check of a pose passes first: `q`, `Φ(q)`, `Φ_q(q)`, `V(q)` and `∇V(q)`
//! finite. Nothing non-finite reaches a decomposition (nalgebra's SVD panics on NaN and
//! iterates without end on ±1e308) or a report (JSON has no NaN): the error names the row or
//! the energy term instead.

use crate::constraints::{Constraints, Triplets};
use crate::error::{Error, Result};
use crate::forces::Energy;
use crate::model::Model;
use crate::solver::system::System;
use crate::state::State;
use nalgebra::DVector;

/// [`Error::NonFiniteConstraint`] or [`Error::NonFiniteEnergy`] unless the constraints and the
/// energy of `model` (its locks held) are finite at `state`; `at` says where (`the given pose`).
pub(crate) fn guard(model: &Model, state: &State, at: &str) -> Result<()> {
    finite_coordinates(model, state, at)?;
    let cons = Constraints::new(model, &crate::solver::lock_values(model))
        .on_branches(state.branches.clone());
    let mut phi = DVector::zeros(cons.len());
    let mut jac = Triplets::default();
    cons.evaluate(model, &state.q, &mut phi, Some(&mut jac));
    finite_rows(model, &cons, &phi, &jac, at)?;
    finite_energy(model, state, at).map(|_| ())
}

/// [`guard`] with the rows of `sys` (the model's rows and locks on the state's branches, as
/// [`guard`] builds them), evaluated into its scratch: the partition and evaluation that
/// follow at the same point reuse them instead of evaluating them again. Returns what the
/// energy check evaluated, the energy `V` and the gradient `∇V` at `state` (`None` where a
/// force-table term is undefined there: that error is the caller's), so that a caller needing
/// them does not evaluate them again.
pub(crate) fn guard_system_energy(
    sys: &mut System,
    state: &State,
    at: &str,
) -> Result<Option<(Energy, DVector<f64>)>> {
    let model = sys.problem.model;
    finite_coordinates(model, state, at)?;
    sys.triplets(&state.q);
    finite_rows(model, &sys.problem.cons, &sys.work.phi, &sys.work.jac, at)?;
    finite_energy(model, state, at)
}

/// [`guard_system_energy`] where the rows of `sys` were evaluated without their derivatives
/// (`System::residual` at `state.q`): `q`, `Φ(q)`, `V(q)` and `∇V(q)` finite.
pub(crate) fn guard_values_energy(
    sys: &System,
    state: &State,
    at: &str,
) -> Result<Option<(Energy, DVector<f64>)>> {
    let model = sys.problem.model;
    finite_coordinates(model, state, at)?;
    finite_rows(
        model,
        &sys.problem.cons,
        &sys.work.phi,
        &Triplets::default(),
        at,
    )?;
    finite_energy(model, state, at)
}

fn finite_coordinates(model: &Model, state: &State, at: &str) -> Result<()> {
    let q = &state.q;
    if q.iter().any(|x| !x.is_finite()) {
        return Err(Error::NonFiniteEnergy {
            at: at.into(),
            term: crate::forces::finite::non_finite_term(model, &state.branches, q),
        });
    }
    Ok(())
}

fn finite_rows(
    model: &Model,
    cons: &Constraints,
    phi: &DVector<f64>,
    jac: &Triplets,
    at: &str,
) -> Result<()> {
    let bad_entry = jac
        .entries
        .iter()
        .find(|e| !e.2.is_finite())
        .map(|e| e.0 as usize);
    if let Some(r) = phi.iter().position(|x| !x.is_finite()).or(bad_entry) {
        let row = cons.row_name(model, r);
        return Err(Error::NonFiniteConstraint {
            site: model.row_site(&row).map(Box::new),
            row,
            at: at.into(),
        });
    }
    Ok(())
}

/// `V(q)` and `∇V(q)` finite: what it evaluated (`None` where a force-table term is undefined
/// at `state`: that error has its own message, raised by the caller's checks).
fn finite_energy(model: &Model, state: &State, at: &str) -> Result<Option<(Energy, DVector<f64>)>> {
    let q = &state.q;
    let mut g = DVector::zeros(q.len());
    let Some(e) = crate::forces::potential(model, &state.branches, q, &mut g, None) else {
        return Ok(None);
    };
    crate::forces::finite::check(model, &state.branches, q, e.total, &g, at)?;
    Ok(Some((e, g)))
}
