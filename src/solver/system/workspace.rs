//! Scratch reused from one evaluation to the next: `Φ`, the triplets of `Φ_q` and the point
//! they were taken at, the sparse split of `Φ_q` into `Φ_u` and `Φ_v`, the KKT system and the
//! block-sparse Hessian of the Lagrangian `W = V_qq − Σ μ_k Φ_k,qq`.

use crate::constraints::Triplets;
use crate::solver::sparse::factor::Split;
use crate::solver::sparse::hessian::BlockHessian;
use crate::solver::sparse::kkt::Kkt;
use nalgebra::DVector;

/// Scratch buffers of a [`super::System`].
pub(crate) struct Workspace {
    /// `Φ` at the last evaluation.
    pub(crate) phi: DVector<f64>,
    /// Triplets of `Φ_q`.
    pub(crate) jac: Triplets,
    /// The configuration of the last triplets (`jac` and `phi`); empty when `phi` is newer.
    pub(crate) jac_at: DVector<f64>,
    /// The symbolic split of `Φ_q` under the last partition (sparse path).
    pub(crate) split: Option<Split>,
    /// The KKT system of the last assembly (sparse path).
    pub(crate) kkt: Option<Kkt>,
    /// `W` in body blocks (sparse path).
    pub(crate) hess: BlockHessian,
}

impl Workspace {
    /// Empty scratch for `rows` constraint rows.
    pub(crate) fn new(rows: usize) -> Self {
        Workspace {
            phi: DVector::zeros(rows),
            jac: Triplets::default(),
            jac_at: DVector::zeros(0),
            split: None,
            kkt: None,
            hess: BlockHessian::default(),
        }
    }
}
