//! What `restpose check` reports beyond the model itself: the number of constraint rows, and
//! whether the initial guess assembles (`Φ(q) = 0` reached by Newton from the initial joint
//! values) with how many degrees of freedom there, `n − rank(Φ_q)`.
//!
//! On the sparse path the rank is that of the solver's sparse partition of `Φ_q` at the
//! assembled guess (one `O(N)` elimination; no energy gradient or multipliers are needed for
//! a count), computed by the same pivots body by body where the elimination has no fill
//! between bodies (module `rank`: every tree), and on the dense path that of
//! [`super::balance`].

use super::{assemble, balance, sparse_path};
use crate::constraints::Constraints;
use crate::error::{Error, Result};
use crate::model::Model;
use crate::solver::system::{Backend, System};
use crate::solver::Options;
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
    let counted = if sparse_path(model) {
        sparse_dof(model, start, cons)
    } else {
        assemble(model, &start).and_then(|s| balance(model, &s).map(|b| b.dof))
    };
    let (dof, assembly_error) = match counted {
        Ok(d) => (Some(d), None),
        Err(e) => (None, Some(e.to_string())),
    };
    ModelCheck {
        constraint_rows,
        dof,
        assembly_error,
    }
}

/// Degrees of freedom on the sparse path: assembles `start` with the rows `cons` and counts.
///
/// The assembly's Newton iteration returns its start unchanged when the scaled residual is
/// within the constraint tolerance there (a tree's forward kinematics); that test is made
/// here with the rows already built, and the assembly runs only when it fails.
///
/// # Errors
/// What the assembly reports, [`Error::ForceTableOutOfRange`] (or another undefined term) if
/// the energy cannot be evaluated at the assembled guess.
fn sparse_dof(model: &Model, start: State, cons: Constraints) -> Result<usize> {
    let mut sys = System::new(
        model,
        cons.on_branches(start.branches.clone()),
        Backend::Sparse,
    );
    // `Φ` with the Jacobian (the same values to the last bit): at an assembled start the
    // guard and the count below use these triplets as they are.
    sys.triplets(&start.q);
    let state = if sys.dimensionless_residual() <= Options::default().constraint_tolerance {
        start
    } else {
        let state = assemble(model, &start)?;
        let cons = sys.problem.cons.on_branches(state.branches.clone());
        sys = System::new(model, cons, Backend::Sparse);
        state
    };
    // The rows evaluated for the guard at `state` are the partition's and the rank count's.
    // The guard's energy is the one that must be defined there (one evaluation for both).
    let energy = crate::solver::finite::guard_system_energy(
        &mut sys,
        &state,
        "the assembled initial guess",
    )?;
    if energy.is_none() {
        return Err(
            crate::forces::undefined_term(model, &state.branches, &state.q).unwrap_or(
                Error::SingularPartition {
                    at: "the assembled initial guess".into(),
                    rows: 0,
                },
            ),
        );
    }
    // Closed loops and mimics couple bodies beyond a joint's two: their elimination has fill
    // between bodies, where the fill-free route would give up; the partition counts them.
    let fast = if super::coupled(model) {
        None
    } else {
        let jac = &sys.work.jac;
        let scaling = &sys.problem.scaling;
        super::rank::free_columns(
            model,
            jac.rows,
            jac.cols,
            &jac.entries,
            &scaling.rows,
            &scaling.columns,
        )
    };
    Ok(match fast {
        Some(free) => free,
        None => sys.partition(&state.q).independent.len(),
    })
}
