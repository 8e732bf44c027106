//! Independent checks of a configuration: does it assemble, and is it balanced?
//!
//! The balance check does not use the solver's partition: it takes an orthonormal basis `N`
//! of the null space of the column-scaled Jacobian `Φ_q S` (singular value decomposition) and
//! evaluates the projected gradient `Nᵀ S ∇V`, which is zero exactly at a constrained
//! stationary point whatever coordinates are chosen independent.

use crate::constraints::Constraints;
use crate::error::{Error, Result};
use crate::forces::potential;
use crate::model::Model;
use crate::state::State;
use nalgebra::DVector;

/// Residuals of a configuration.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Balance {
    /// `‖Φ‖∞` over all constraint rows (locks included).
    pub constraint_residual: f64,
    /// `‖Nᵀ S ∇V‖∞` \[J\]: the gradient of the energy along feasible motions, in coordinates
    /// scaled like the solver's (positions by the characteristic length).
    pub projected_gradient: f64,
    /// Potential energy \[J\].
    pub potential_energy: f64,
    /// Degrees of freedom from the rank of `Φ_q` (singular values below 1e-6 of the largest count as zero).
    pub dof: usize,
}

/// Potential energy of a state \[J\], `None` where a force table is out of its range.
pub fn potential_energy(model: &Model, state: &State) -> Option<f64> {
    let mut g = DVector::zeros(state.q.len());
    potential(model, &state.q, &mut g, None).map(|e| e.total)
}

/// Constraint residual and projected energy gradient of `state` (with the model's locks held
/// at their given values, or at the initial value when they have none).
///
/// # Errors
/// [`Error::Undefined`] if the energy cannot be evaluated.
pub fn balance(model: &Model, state: &State) -> Result<Balance> {
    let locks = crate::solver::lock_values(model);
    let cons = Constraints::new(model, &locks);
    let mut phi = DVector::zeros(cons.len());
    let mut jac = crate::constraints::Triplets::default();
    cons.evaluate(model, &state.q, &mut phi, Some(&mut jac));
    let n = state.q.len();
    let scale = crate::solver::system::coordinate_scale(model);
    let mut j = jac.to_dense();
    for c in 0..n {
        j.column_mut(c).scale_mut(scale[c]);
    }
    let mut g = DVector::zeros(n);
    let e = potential(model, &state.q, &mut g, None)
        .ok_or_else(|| Error::Undefined("a force table is out of range".into()))?;
    for c in 0..n {
        g[c] *= scale[c];
    }
    // Null space from the SVD of Jᵀ J (n × n, symmetric): eigenvectors of ~zero eigenvalues.
    let jtj = j.transpose() * &j;
    let eig = nalgebra::SymmetricEigen::new(jtj);
    let smax = eig.eigenvalues.amax().max(1e-300);
    let mut proj: f64 = 0.0;
    let mut dof = 0;
    for k in 0..n {
        if eig.eigenvalues[k] <= 1e-12 * smax {
            dof += 1;
            proj = proj.max(eig.eigenvectors.column(k).dot(&g).abs());
        }
    }
    Ok(Balance {
        constraint_residual: phi.amax(),
        projected_gradient: proj,
        potential_energy: e.total,
        dof,
    })
}

/// Brings `state` onto `Φ = 0` by a damped Newton iteration that changes the dependent
/// coordinates of a fresh partition at each step (as the solver's assembly does).
///
/// # Errors
/// [`Error::Assembly`] if the constraints cannot be satisfied from there.
pub fn assemble(model: &Model, state: &State) -> Result<State> {
    let locks = crate::solver::lock_values(model);
    let q = crate::solver::assemble_only(model, state.q.clone(), &locks)?;
    Ok(State { q })
}
