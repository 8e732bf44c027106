//! The KKT matrix of the last assembly: the general sparse one (module `sparse::kkt`) or, with
//! the tree backend where the partition fits, the tree-structured one (module `tree::kkt`).
//! Both store the same matrix in the same elimination order and answer the same calls.

use crate::constraints::Triplet;
use crate::solver::partition::Partition;
use crate::solver::sparse::hessian::BlockHessian;
use crate::solver::sparse::kkt::{Factored, Kkt};
use crate::solver::tree::kkt::TreeKkt;

/// The KKT matrix, its values and factors.
pub(crate) enum KktMatrix {
    /// faer's simplicial LDLᵀ (LU as the fallback).
    Sparse(Box<Kkt>),
    /// Block LDLᵀ along the tree (block LU as the fallback).
    Tree(Box<TreeKkt>),
}

macro_rules! both {
    ($self:expr, $k:ident => $e:expr) => {
        match $self {
            KktMatrix::Sparse($k) => $e,
            KktMatrix::Tree($k) => $e,
        }
    };
}

impl KktMatrix {
    /// Whether this structure fits `part`, a Jacobian of `triplets` entries and `blocks` blocks.
    pub(crate) fn fits(&self, part: &Partition, triplets: usize, blocks: usize) -> bool {
        both!(self, k => k.fits(part, triplets, blocks))
    }

    /// Fills the values (scaled) from the Jacobian triplets and the Hessian blocks.
    pub(crate) fn assemble(
        &mut self,
        entries: &[Triplet],
        row_scale: &[f64],
        scale: &[f64],
        hess: &BlockHessian,
    ) {
        both!(self, k => k.assemble(entries, row_scale, scale, hess))
    }

    /// Factors with `δ` on the diagonal of the `W` block.
    pub(crate) fn factor(&mut self, delta: f64) -> Factored {
        both!(self, k => k.factor(delta))
    }

    /// LU from now on (an LDLᵀ solve was not accurate).
    pub(crate) fn fall_back_to_lu(&mut self) -> Factored {
        both!(self, k => k.fall_back_to_lu())
    }

    /// The largest diagonal entry of the (scaled) `W` block.
    pub(crate) fn max_diagonal(&self) -> f64 {
        both!(self, k => k.max_diagonal())
    }

    /// The shift `−σ` on the independent coordinates' diagonal.
    pub(crate) fn shift_independent(&mut self, columns: &[usize], sigma: f64) {
        both!(self, k => k.shift_independent(columns, sigma))
    }

    /// Solves in place with refinement to the backward error `target`.
    pub(crate) fn solve(&self, rhs: &mut [f64], target: f64) -> bool {
        both!(self, k => k.solve(rhs, target))
    }

    /// Number of constraint rows.
    pub(crate) fn rows(&self) -> usize {
        both!(self, k => k.rows())
    }

    /// Number of coordinates `n`.
    pub(crate) fn coordinates(&self) -> usize {
        both!(self, k => k.coordinates())
    }
}
