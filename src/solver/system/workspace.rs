//! Scratch reused from one evaluation to the next: `Φ`, the triplets of `Φ_q` and the point
//! they were taken at, the sparse split of `Φ_q` into `Φ_u` and `Φ_v`, the KKT system and the
//! block-sparse Hessian of the Lagrangian `W = V_qq − Σ μ_k Φ_k,qq`.

use super::augment::AugmentPlan;
use super::kkt_matrix::KktMatrix;
use crate::constraints::Triplets;
use crate::solver::sparse::factor::Split;
use crate::solver::sparse::hessian::BlockHessian;
use crate::solver::tree::phi_u::TreeSplit;
use nalgebra::DVector;

/// Scratch buffers of a [`super::System`].
pub(crate) struct Workspace {
    /// `Φ` at the last evaluation.
    pub(crate) phi: DVector<f64>,
    /// Triplets of `Φ_q`.
    pub(crate) jac: Triplets,
    /// The configuration of the last triplets (`jac` and `phi`), valid while `jac_fresh`
    /// (false once `phi` is newer; the buffer is kept).
    pub(crate) jac_at: DVector<f64>,
    pub(crate) jac_fresh: bool,
    /// The symbolic split of `Φ_q` under the last partition (sparse path).
    pub(crate) split: Option<Split>,
    /// The KKT system of the last assembly (sparse path; tree backend: tree-structured where
    /// the partition fits).
    pub(crate) kkt: Option<KktMatrix>,
    /// The block-triangular split of `Φ_q` under the last partition (tree backend).
    pub(crate) tree_split: Option<TreeSplit>,
    /// The partition id and triplet count that did not fit a tree (tree backend: sparse).
    pub(crate) tree_refused: Option<(usize, usize)>,
    pub(crate) tree_kkt_refused: Option<(usize, usize)>,
    /// `W` in body blocks (sparse path).
    pub(crate) hess: BlockHessian,
    /// The rows of the augmentation of `W` under the last partition (module `augment`).
    pub(crate) augment: Option<AugmentPlan>,
    /// Scratch of each assembly of `W` (module `reduced`, `augment`): the energy gradient
    /// that comes with its Hessian, the multiplier weights over all rows, `W`'s scaled
    /// diagonal and each body's largest entry of it.
    pub(crate) grad: DVector<f64>,
    pub(crate) weights: DVector<f64>,
    pub(crate) wdiag: Vec<f64>,
    pub(crate) body_max: Vec<f64>,
}

impl Workspace {
    /// Empty scratch for `rows` constraint rows.
    pub(crate) fn new(rows: usize) -> Self {
        Workspace {
            phi: DVector::zeros(rows),
            jac: Triplets::default(),
            jac_at: DVector::zeros(0),
            jac_fresh: false,
            split: None,
            kkt: None,
            tree_split: None,
            tree_refused: None,
            tree_kkt_refused: None,
            hess: BlockHessian::default(),
            augment: None,
            grad: DVector::zeros(0),
            weights: DVector::zeros(0),
            wdiag: Vec::new(),
            body_max: Vec::new(),
        }
    }
}
