//! What `restpose check` reports beyond the model itself: the number of constraint rows, and
//! whether the initial guess assembles (`Φ(q) = 0` reached by Newton from the initial joint
//! values) with how many degrees of freedom there, `n − rank(Φ_q)`.
//!
//! On the sparse path the rank is that of the solver's sparse partition of `Φ_q` at the
//! assembled guess (one `O(N)` elimination; no energy gradient or multipliers are needed for
//! a count), computed by the same pivots body by body where the elimination has no fill
//! between bodies (module `rank`: every tree), and on the dense path that of
//! [`super::balance`].
//!
//! On a tree of joints whose rows are independent wherever they hold ([`tree_dof`]) the count
//! needs no Jacobian: ordered leaves to root, `Φ_q` is block triangular, each body's block
//! (its normalization and the rows of the joint to its parent, on its own 7 coordinates) has
//! full row rank, so `rank Φ_q = m` and the degrees of freedom are `n − m`. There the rows
//! are evaluated without their derivatives (for the assembly test and the guard).

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
    let structural = tree_dof(model, &cons, start.q.len());
    let mut sys = System::new(
        model,
        cons.on_branches(start.branches.clone()),
        Backend::Sparse,
    );
    if let Some(dof) = structural {
        // `Φ` alone; the rest of this function where the start does not assemble.
        sys.residual(&start.q);
        if sys.dimensionless_residual() <= Options::default().constraint_tolerance {
            let energy = crate::solver::finite::guard_values_energy(
                &sys,
                &start,
                "the assembled initial guess",
            )?;
            return match energy {
                Some(_) => Ok(dof),
                None => Err(undefined(model, &start)),
            };
        }
    }
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
        return Err(undefined(model, &state));
    }
    // The count of the sparse partition's pivots on dense copies; where that route gives up
    // (a long loop, a contact row carried on), the partition counts them.
    let fast = {
        let jac = &sys.work.jac;
        let scaling = &sys.problem.scaling;
        crate::solver::sparse::fill_free::free_columns(
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

/// The error of an energy undefined at the assembled initial guess `state`.
fn undefined(model: &Model, state: &State) -> Error {
    crate::forces::undefined_term(model, &state.branches, &state.q).unwrap_or(
        Error::SingularPartition {
            at: "the assembled initial guess".into(),
            rows: 0,
        },
    )
}

/// `n − m`, the degrees of freedom of the `n` coordinates under the rows `cons`, where every
/// row is independent of the others wherever they hold: a tree (no closed loop, mimic or
/// lock) of joints whose rows on the body they lead to have full row rank with its
/// normalization at every configuration (revolute, continuous, prismatic, fixed, spherical,
/// floating: a point and up to two axes held on a rigid frame). `None` otherwise (a distance
/// of zero length, an axis that may become parallel to a line, a lock on a coordinate of a
/// floating joint's rotation: rows that can be dependent), where the elimination counts.
pub(super) fn tree_dof(model: &Model, cons: &Constraints, n: usize) -> Option<usize> {
    use crate::model::JointKind as K;
    let independent = model.joints.iter().all(|j| {
        j.merged
            || (j.bodies.iter().any(Option::is_some)
                && matches!(
                    j.kind,
                    K::Revolute
                        | K::Continuous
                        | K::Prismatic
                        | K::Fixed
                        | K::Spherical
                        | K::Floating
                ))
    });
    let tree = !super::coupled(model) && crate::solver::lock_values(model).is_empty();
    if independent && tree {
        n.checked_sub(cons.len())
    } else {
        None
    }
}
