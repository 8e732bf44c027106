//! What `restpose check` reports beyond the model itself: the number of constraint rows, and
//! whether the initial guess assembles (`Φ(q) = 0` reached by Newton from the initial joint
//! values) with how many degrees of freedom there, `n − rank(Φ_q)`.

use super::{assemble, balance};
use crate::constraints::Constraints;
use crate::model::Model;

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
    let (dof, assembly_error) = match assemble(model, &start).and_then(|s| balance(model, &s)) {
        Ok(b) => (Some(b.dof), None),
        Err(e) => (None, Some(e.to_string())),
    };
    ModelCheck {
        constraint_rows: Constraints::new(model, &crate::solver::lock_values(model)).len(),
        dof,
        assembly_error,
    }
}
