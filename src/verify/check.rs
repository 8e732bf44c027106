//! What `restpose check` reports beyond the model itself: the number of constraint rows, and
//! whether the initial guess assembles (`Φ(q) = 0` reached by Newton from the initial joint
//! values) with how many degrees of freedom there, `n − rank(Φ_q)`.
//!
//! On the sparse path the rank is that of the solver's sparse partition of `Φ_q` at the
//! assembled guess (one `O(N)` elimination; no energy gradient or multipliers are needed for
//! a count), on the dense path that of [`super::balance`].

use super::{assemble, balance, sparse_path};
use crate::constraints::Constraints;
use crate::error::{Error, Result};
use crate::model::Model;
use crate::solver::system::{Backend, System};
use crate::state::State;

/// Constraint rows and assembly of a model at its initial guess.
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize)]
pub struct ModelCheck {
    /// Constraint rows (normalization, locks and mimics included).
    pub constraint_rows: usize,
    /// Degrees of freedom at the assembled initial guess (`None` if it does not assemble).
    pub dof: Option<usize>,
    /// Why the initial guess does not assemble, if it does not.
    pub assembly_error: Option<String>,
}

/// Counts the constraint rows and assembles the initial guess.
pub fn check(model: &Model) -> ModelCheck {
    let start = crate::solver::initial_state(model);
    let cons = Constraints::new(model, &crate::solver::lock_values(model));
    let constraint_rows = cons.len();
    let (dof, assembly_error) = match assemble(model, &start).and_then(|s| dof(model, &s, cons)) {
        Ok(d) => (Some(d), None),
        Err(e) => (None, Some(e.to_string())),
    };
    ModelCheck {
        constraint_rows,
        dof,
        assembly_error,
    }
}

/// Degrees of freedom at the feasible `state` with the rows `cons`.
///
/// # Errors
/// [`Error::ForceTableOutOfRange`] (or another undefined term) if the energy cannot be
/// evaluated there, [`Error::SingularPartition`] if the dense partition fails.
fn dof(model: &Model, state: &State, cons: Constraints) -> Result<usize> {
    if !sparse_path(model) {
        return balance(model, state).map(|b| b.dof);
    }
    if super::potential_energy(model, state).is_none() {
        return Err(
            crate::forces::undefined_term(model, &state.branches, &state.q).unwrap_or(
                Error::SingularPartition {
                    at: "the assembled initial guess".into(),
                    rows: 0,
                },
            ),
        );
    }
    let cons = cons.on_branches(state.branches.clone());
    let mut sys = System::with_backend(model, cons, Backend::Sparse);
    let t0 = std::time::Instant::now();
    let mut phi = nalgebra::DVector::zeros(sys.problem.cons.len());
    let mut jac = crate::constraints::Triplets::default();
    sys.problem
        .cons
        .evaluate(model, &state.q, &mut phi, Some(&mut jac));
    eprint!("eval {:.1} ", t0.elapsed().as_secs_f64()*1e3);
    let scaling = &sys.problem.scaling;
    let fast = super::rank::free_columns(
        model,
        jac.rows,
        jac.cols,
        &jac.entries,
        &scaling.rows,
        &scaling.columns,
    );
    Ok(match fast {
        Some(free) => free,
        None => sys.partition(&state.q).independent.len(),
    })
}
