//! Evaluation of the partitioned problem at a configuration: the corrector, the reduced
//! gradient and the reduced Hessian.
//!
//! With `q = [u; v]`, `Φ_q = [Φ_u Φ_v]` (independent rows only) and `H = −Φ_u⁻¹ Φ_v`:
//! - corrector: Newton on `Φ(u; v) = 0` for fixed `v`: `Φ_u δu = −Φ` (module `corrector`);
//! - multipliers: `Φ_uᵀ μ = V_uᵀ`, so that `V_qᵀ = Φ_qᵀ μ` at equilibrium;
//! - reduced gradient (eq. 37): `∂V/∂v = V_v + V_u H = V_v − Φ_vᵀ μ` (module `reduced`);
//! - reduced Hessian: `Zᵀ (V_qq − Σ_k μ_k Φ_k,qq) Z`, `Z = [H; I]`, exact at feasible points
//!   (module `reduced`; on the sparse path Newton steps come from the KKT system, module
//!   `kkt`).
//!
//! Independent coordinates are scaled, `v = S v̂` (positions by the characteristic length), and
//! gradients and Hessians are reported in the scaled coordinates `v̂`.
//!
//! A [`System`] is a [`Problem`] (model, constraint rows, scaling: built once), a
//! [`Workspace`] (scratch, reused) and a [`Backend`] (dense or sparse, chosen once). The
//! factors of `Φ_u` are module `factors`.

mod backend;
mod corrector;
mod factors;
mod kkt;
mod problem;
mod reduced;
#[cfg(test)]
mod tests;
mod workspace;

pub(crate) use backend::Backend;
pub(crate) use factors::Factors;
pub(crate) use problem::{coordinate_scale, Problem, Scaling};
pub(crate) use reduced::Eval;
pub(crate) use workspace::Workspace;

use super::partition::Partition;
use crate::constraints::Constraints;
use crate::model::Model;
use nalgebra::DVector;

/// The problem, its scratch space and its linear algebra.
pub(crate) struct System<'a> {
    pub(crate) problem: Problem<'a>,
    pub(crate) work: Workspace,
    pub(crate) backend: Backend,
}

impl<'a> System<'a> {
    /// The system with the automatic choice of linear algebra (by size).
    pub(crate) fn new(model: &'a Model, cons: Constraints) -> Self {
        Self::with_backend(
            model,
            cons,
            Backend::choose(model, super::LinearAlgebra::Auto),
        )
    }

    /// The system with the linear algebra of `options` (automatic: by size).
    pub(crate) fn with_options(
        model: &'a Model,
        cons: Constraints,
        options: &super::Options,
    ) -> Self {
        Self::with_backend(model, cons, Backend::choose(model, options.linear_algebra))
    }

    /// The system with the given linear algebra.
    pub(crate) fn with_backend(model: &'a Model, cons: Constraints, backend: Backend) -> Self {
        System {
            work: Workspace::new(cons.len()),
            problem: Problem::new(model, cons),
            backend,
        }
    }

    /// `Φ(q)` (invalidates the triplets' `Φ`).
    pub(crate) fn residual(&mut self, q: &DVector<f64>) -> &DVector<f64> {
        self.work.jac_at = DVector::zeros(0);
        self.problem
            .cons
            .evaluate(self.problem.model, q, &mut self.work.phi, None);
        &self.work.phi
    }

    /// `‖D Φ‖∞` at the point of the last evaluation: the residual with each row in m^k divided
    /// by `L^k`, so that one tolerance means the same in any length unit.
    pub(crate) fn dimensionless_residual(&self) -> f64 {
        self.problem.scaling.residual(&self.work.phi)
    }

    /// `Φ` at the point of the last [`System::jacobian`] or [`System::residual`] call.
    pub(crate) fn phi(&self) -> &DVector<f64> {
        &self.work.phi
    }

    /// `Φ(q)` and the triplets of `Φ_q(q)` into the scratch (kept if they are at `q`).
    fn triplets(&mut self, q: &DVector<f64>) {
        let work = &mut self.work;
        if work.jac_at.len() == q.len() && work.jac_at == *q {
            return;
        }
        self.problem
            .cons
            .evaluate(self.problem.model, q, &mut work.phi, Some(&mut work.jac));
        work.jac_at.clone_from(q);
    }

    /// Dense `Φ_q(q)` (and `Φ(q)` into the scratch).
    #[cfg(test)]
    pub(crate) fn jacobian(&mut self, q: &DVector<f64>) -> nalgebra::DMatrix<f64> {
        self.triplets(q);
        self.work.jac.to_dense()
    }

    /// Partition at `q` (see [`Backend::partition`]).
    pub(crate) fn partition(&mut self, q: &DVector<f64>) -> Partition {
        self.triplets(q);
        self.backend
            .partition(&self.problem, &self.work.jac, q.len())
    }
}
