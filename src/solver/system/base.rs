//! The [`System`]: a [`Problem`], its [`Workspace`] and its [`Backend`], with the cache of
//! `Φ(q)` and the triplets of `Φ_q(q)` at the last configuration they were taken at (every
//! other evaluation in this module's siblings starts from them).

use super::{Backend, Problem, Workspace};
use crate::constraints::Constraints;
use crate::model::Model;
use crate::solver::partition::Partition;
use nalgebra::DVector;

/// The problem, its scratch space and its linear algebra.
pub(crate) struct System<'a> {
    pub(crate) problem: Problem<'a>,
    pub(crate) work: Workspace,
    pub(crate) backend: Backend,
}

impl<'a> System<'a> {
    /// The system of the rows `cons` of `model` with the linear algebra `backend` (chosen once,
    /// by [`Backend::choose`]).
    pub(crate) fn new(model: &'a Model, cons: Constraints, backend: Backend) -> Self {
        System {
            work: Workspace::new(cons.len()),
            problem: Problem::new(model, cons),
            backend,
        }
    }

    /// `Φ(q)` (invalidates the triplets' `Φ`).
    pub(crate) fn residual(&mut self, q: &DVector<f64>) -> &DVector<f64> {
        self.work.jac_fresh = false;
        self.problem
            .cons
            .evaluate(self.problem.model, q, &mut self.work.phi, None);
        &self.work.phi
    }

    /// `‖D Φ‖∞` at the point of the last evaluation (module `residual`).
    pub(crate) fn dimensionless_residual(&self) -> f64 {
        self.problem.scaling.residual(&self.work.phi)
    }

    /// `Φ` at the point of the last [`System::jacobian`] or [`System::residual`] call.
    pub(crate) fn phi(&self) -> &DVector<f64> {
        &self.work.phi
    }

    /// `Φ(q)` and the triplets of `Φ_q(q)` into the scratch (kept if they are at `q`).
    pub(crate) fn triplets(&mut self, q: &DVector<f64>) {
        let work = &mut self.work;
        if work.jac_fresh && work.jac_at.len() == q.len() && work.jac_at == *q {
            return;
        }
        self.problem
            .cons
            .evaluate(self.problem.model, q, &mut work.phi, Some(&mut work.jac));
        // In place (no allocation) when the length is the same.
        if work.jac_at.len() == q.len() {
            work.jac_at.copy_from(q);
        } else {
            work.jac_at = q.clone();
        }
        work.jac_fresh = true;
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
