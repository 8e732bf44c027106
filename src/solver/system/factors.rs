//! The factors of `Φ_u` and the values of `Φ_v` at one configuration: `Φ_u x = b`,
//! `Φ_uᵀ x = b`, `Φ_v x` and `Φ_vᵀ y`, dense (nalgebra's LU with partial pivoting), sparse
//! (faer's sparse LU) or block triangular along the tree (module `tree::phi_u`).

use super::dense_lu::DenseLu;
use super::dense_memo::dense_factors;
use super::{Backend, System};
use crate::solver::partition::Partition;
use crate::solver::sparse::factor::{SparseFactors, Split};
use crate::solver::tree::phi_u::{TreeLu, TreeSplit};
use nalgebra::{DMatrix, DVector};
use std::sync::Arc;

/// The factorization of `Φ_u` and the values of `Φ_v` at one configuration.
#[derive(Clone)]
pub(crate) enum Factors {
    /// Dense LU with partial pivoting (small models).
    Dense {
        lu: Arc<DenseLu>,
        phi_v: Arc<DMatrix<f64>>,
    },
    /// faer's sparse LU.
    Sparse(Box<SparseFactors>),
    /// Block triangular along the tree (shared with the pool that reuses its buffers).
    Tree(Arc<TreeLu>),
}

impl Factors {
    /// `Φ_u x = b`; `None` if `Φ_u` is singular.
    pub(crate) fn solve(&self, b: &DVector<f64>) -> Option<DVector<f64>> {
        match self {
            Factors::Dense { lu, .. } => {
                let mut x = b.clone();
                (b.is_empty() || lu.solve_mut(&mut x)).then_some(x)
            }
            Factors::Sparse(f) => {
                let mut x = b.clone();
                f.solve(x.as_mut_slice()).then_some(x)
            }
            Factors::Tree(f) => {
                let mut x = b.clone();
                f.solve(x.as_mut_slice()).then_some(x)
            }
        }
    }

    /// `Φ_uᵀ x = b`; `None` if `Φ_u` is singular.
    pub(crate) fn solve_transpose(&self, b: DVector<f64>) -> Option<DVector<f64>> {
        match self {
            Factors::Dense { lu, .. } => {
                if b.is_empty() {
                    return Some(b);
                }
                solve_transpose(lu, b)
            }
            Factors::Sparse(f) => {
                let mut x = b;
                f.solve_transpose(x.as_mut_slice()).then_some(x)
            }
            Factors::Tree(f) => {
                let mut x = b;
                f.solve_transpose(x.as_mut_slice()).then_some(x)
            }
        }
    }

    /// `Φ_v x`.
    pub(crate) fn phi_v_mul(&self, x: &DVector<f64>, rows: usize) -> DVector<f64> {
        match self {
            Factors::Dense { phi_v, .. } => phi_v.as_ref() * x,
            Factors::Sparse(f) => DVector::from_vec(f.phi_v_mul(x.as_slice(), rows)),
            Factors::Tree(f) => DVector::from_vec(f.phi_v_mul(x.as_slice(), rows)),
        }
    }

    /// `Φ_vᵀ y`.
    pub(crate) fn phi_v_tr_mul(&self, y: &DVector<f64>, dof: usize) -> DVector<f64> {
        match self {
            Factors::Dense { phi_v, .. } => phi_v.transpose() * y,
            Factors::Sparse(f) => DVector::from_vec(f.phi_v_tr_mul(y.as_slice(), dof)),
            Factors::Tree(f) => DVector::from_vec(f.phi_v_tr_mul(y.as_slice(), dof)),
        }
    }

    /// The smallest pivot of `U` over the largest (dense; the tree factors of a small model:
    /// over their diagonal blocks and border; `None` otherwise): a cheap measure of how well
    /// the dependent coordinates are determined by the independent rows at this configuration.
    pub(crate) fn pivot_ratio(&self) -> Option<f64> {
        match self {
            Factors::Dense { lu, .. } => {
                // `U`'s diagonal, read in place (`lu.u()` would copy the whole triangle).
                let d = lu.packed().diagonal().abs();
                Some(if d.is_empty() { 1.0 } else { d.min() / d.max() })
            }
            Factors::Tree(f) => f.pivot_ratio(),
            Factors::Sparse(_) => None,
        }
    }

    /// Whether `Φ_u` has become ill-conditioned (a pivot below `1e-8` of the largest,
    /// [`Factors::pivot_ratio`]; where that is `None`, the minimizer re-partitions when the
    /// corrector or the line search fails instead).
    pub(crate) fn ill_conditioned(&self) -> bool {
        match self {
            Factors::Dense { .. } | Factors::Tree(_) => {
                self.pivot_ratio().is_some_and(|r| r < 1e-8)
            }
            Factors::Sparse(_) => false,
        }
    }
}

/// Solves `Aᵀ x = b` with the factors `P A = L U` of `A`: `Uᵀ y = b`, `Lᵀ z = y`, `x = Pᵀ z`,
/// on the packed factors in place (`U` on and above the diagonal, `L` below it with a unit
/// diagonal) instead of the copies `lu.u()` and `lu.l()` (two `r × r` matrices per solve):
/// nalgebra's `tr_solve_upper_triangular` reads only that triangle, and the unit-diagonal
/// substitution is its `tr_solve_lower_triangular` on `lu.l()` step by step (the same dot
/// products, the division by 1 exact), so the same bits.
fn solve_transpose(lu: &DenseLu, mut b: DVector<f64>) -> Option<DVector<f64>> {
    let packed = lu.packed();
    if !packed.tr_solve_upper_triangular_mut(&mut b) {
        return None;
    }
    for i in (0..packed.nrows()).rev() {
        let dot = packed.view_range(i + 1.., i).dot(&b.view_range(i + 1.., 0));
        b[i] = (b[i] - dot) / 1.0;
    }
    lu.p().inv_permute_rows(&mut b);
    Some(b)
}

impl System<'_> {
    /// Factors `Φ_u` of the last triplets under `part`.
    pub(super) fn factors(&mut self, part: &Partition) -> Option<Factors> {
        let n = self.problem.model.coordinate_count();
        let m = self.problem.cons.len();
        let work = &mut self.work;
        if self.backend == Backend::Tree {
            let entries = &work.jac.entries;
            if !work
                .tree_split
                .as_ref()
                .is_some_and(|s| s.fits(part, entries.len()))
                && work.tree_refused != Some((part.id, entries.len()))
            {
                let open = super::backend::open(self.problem.model);
                work.tree_split = TreeSplit::new(part, m, n, entries, open);
                if work.tree_split.is_none() {
                    work.tree_refused = Some((part.id, entries.len()));
                }
            }
            if let Some(split) = work.tree_split.as_mut() {
                let watch = super::backend::tree_watches_pivots(self.problem.model);
                return Some(Factors::Tree(split.factor(entries, watch)));
            }
        }
        if self.backend != Backend::Dense {
            let entries = &work.jac.entries;
            if !work
                .split
                .as_ref()
                .is_some_and(|s| s.fits(part, entries.len()))
            {
                work.split = Some(Split::new(part, m, n, entries)?);
            }
            let split = work.split.as_mut()?;
            return Some(Factors::Sparse(Box::new(split.factor(entries))));
        }
        let r = part.rows.len();
        let dof = part.independent.len();
        let mut row_pos = vec![usize::MAX; m];
        for (k, &i) in part.rows.iter().enumerate() {
            row_pos[i] = k;
        }
        // Column position: dependent k, or independent dof-offset k.
        let mut col_pos = vec![(false, 0usize); n];
        for (k, &c) in part.dependent.iter().enumerate() {
            col_pos[c] = (true, k);
        }
        for (k, &c) in part.independent.iter().enumerate() {
            col_pos[c] = (false, k);
        }
        let entries = &work.jac.entries;
        let (lu, phi_v) = dense_factors(entries, part, || {
            let mut phi_u = DMatrix::zeros(r, r);
            let mut phi_v = DMatrix::zeros(r, dof);
            for &(i, c, v) in entries {
                let a = row_pos[i as usize];
                if a == usize::MAX {
                    continue;
                }
                match col_pos[c as usize] {
                    (true, k) => phi_u[(a, k)] += v,
                    (false, k) => phi_v[(a, k)] += v,
                }
            }
            (DenseLu::new(phi_u), phi_v)
        });
        Some(Factors::Dense { lu, phi_v })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The transposed solve on the packed factors equals the one through the copies `lu.u()`
    /// and `lu.l()` bit for bit, solves `Aᵀ x = b`, and refuses a singular `U`; the pivot
    /// ratio is that of `lu.u()`'s diagonal.
    #[test]
    fn transposed_solve_in_place_is_that_of_the_copies() {
        let mut lcg = crate::lcg::Lcg::new(99);
        let mut r = || lcg.signed();
        let bits = |v: &DVector<f64>| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        for n in [1, 2, 7, 30] {
            let a = DMatrix::from_fn(n, n, |_, _| r());
            let b = DVector::from_fn(n, |_, _| r());
            let lu = a.clone().lu();
            let y = lu.u().tr_solve_upper_triangular(&b).unwrap();
            let mut copies = lu.l().tr_solve_lower_triangular(&y).unwrap();
            lu.p().inv_permute_rows(&mut copies);
            let lu = DenseLu::new(a.clone());
            let packed = solve_transpose(&lu, b.clone()).unwrap();
            assert_eq!(bits(&copies), bits(&packed), "n = {n}");
            assert!((a.transpose() * &packed - &b).amax() < 1e-9, "n = {n}");
            let d = a.clone().lu().u().diagonal().abs();
            let dense = Factors::Dense {
                lu: Arc::new(lu),
                phi_v: Arc::new(DMatrix::zeros(n, 0)),
            };
            assert_eq!(dense.pivot_ratio(), Some(d.min() / d.max()));
        }
        let singular = DenseLu::new(DMatrix::from_row_slice(2, 2, &[1.0, 2.0, 2.0, 4.0]));
        assert!(solve_transpose(&singular, DVector::from_vec(vec![1.0, 1.0])).is_none());
    }
}
