//! The eigen-decomposition of a symmetric matrix block by block, over its decoupled blocks.
//!
//! With a fixed palm or trunk the fingers (legs) of a hand (robot) move independently: the
//! reduced Hessian `Ĥ` (and the Hessian along the search path) is block diagonal up to a
//! permutation, one block per subtree hanging from the part that does not move, exactly (the
//! energy of one finger does not depend on another's coordinates). Its off-block entries
//! computed through `Z` are rounding, 10⁻¹⁵ … 10⁻¹⁸ of the largest on the Allegro hands. A
//! decomposition of the whole matrix mixes identical fingers within a degenerate eigenspace
//! (eigenvectors spread over several fingers); decomposing each block on its own gives
//! eigenvectors that each live on one block:
//!
//! `A = P diag(A_1, …, A_k) Pᵀ`,   `A_b = V_b Λ_b V_bᵀ`,
//!
//! the blocks `A_b` the connected components of the graph with an edge `(i, j)` where
//! `|a_ij| > 10⁻¹³ max |a|`. The entries dropped change the eigenvalues by at most their
//! spectral norm, `≤ n · 10⁻¹³ max |a|`: below the spectrum's tolerance `10⁻¹⁰ |λ|max` up to
//! `n = 1,000` (the exact spectrum stops at 200 degrees of freedom).

use super::eigen::symmetric_eigen;
use nalgebra::{DMatrix, DVector};

/// Off-block entries up to this fraction of the largest entry are rounding (module docs).
const DECOUPLED: f64 = 1e-13;

/// The decoupled blocks of a symmetric `a` (module docs): each a sorted list of indices, in
/// the order of their first index.
pub(crate) fn blocks(a: &DMatrix<f64>) -> Vec<Vec<usize>> {
    let n = a.nrows();
    let tol = DECOUPLED * a.amax();
    // Union–find over the indices.
    let mut root: Vec<usize> = (0..n).collect();
    fn find(root: &mut [usize], mut i: usize) -> usize {
        while root[i] != i {
            root[i] = root[root[i]];
            i = root[i];
        }
        i
    }
    for i in 0..n {
        for j in i + 1..n {
            // NaN joins everything (the whole matrix is then decomposed, and fails as before).
            if !(a[(i, j)].abs() <= tol && a[(j, i)].abs() <= tol) {
                let (ri, rj) = (find(&mut root, i), find(&mut root, j));
                root[ri.max(rj)] = ri.min(rj);
            }
        }
    }
    let mut out: Vec<Vec<usize>> = Vec::new();
    let mut index = vec![usize::MAX; n];
    for i in 0..n {
        let r = find(&mut root, i);
        if index[r] == usize::MAX {
            index[r] = out.len();
            out.push(Vec::new());
        }
        out[index[r]].push(i);
    }
    out
}

/// Eigenvalues (ascending) and orthonormal eigenvectors (columns) of a symmetric `a`,
/// decomposed over its decoupled blocks: every eigenvector is zero outside its block.
pub(crate) fn block_symmetric_eigen(a: &DMatrix<f64>) -> (DVector<f64>, DMatrix<f64>) {
    let n = a.nrows();
    let parts = blocks(a);
    if parts.len() <= 1 {
        return symmetric_eigen(a);
    }
    let mut pairs: Vec<(f64, DVector<f64>)> = Vec::with_capacity(n);
    for b in &parts {
        let sub = DMatrix::from_fn(b.len(), b.len(), |r, c| a[(b[r], b[c])]);
        let (vals, vecs) = symmetric_eigen(&sub);
        for k in 0..b.len() {
            let mut v = DVector::zeros(n);
            for (r, &i) in b.iter().enumerate() {
                v[i] = vecs[(r, k)];
            }
            pairs.push((vals[k], v));
        }
    }
    pairs.sort_by(|x, y| x.0.total_cmp(&y.0));
    let values = DVector::from_iterator(n, pairs.iter().map(|p| p.0));
    let mut vectors = DMatrix::zeros(n, n);
    for (k, p) in pairs.iter().enumerate() {
        vectors.set_column(k, &p.1);
    }
    (values, vectors)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two identical 2 × 2 blocks interleaved (indices {0, 2} and {1, 3}) with rounding-level
    /// coupling: the eigenvalues are the blocks' (each twice), each eigenvector lives on one
    /// block, and `A V = V Λ` to the size of the dropped entries.
    #[test]
    fn identical_decoupled_blocks_give_eigenvectors_on_one_block() {
        let mut a = DMatrix::from_row_slice(
            4,
            4,
            &[
                -2.0, 0.0, 1.0, 0.0, //
                0.0, -2.0, 0.0, 1.0, //
                1.0, 0.0, 3.0, 0.0, //
                0.0, 1.0, 0.0, 3.0,
            ],
        );
        a[(0, 1)] = 3e-17;
        a[(1, 0)] = 3e-17;
        assert_eq!(blocks(&a), vec![vec![0, 2], vec![1, 3]]);
        let (vals, vecs) = block_symmetric_eigen(&a);
        // The closed form of [[-2, 1], [1, 3]]: ½ ± √(25/4 + 1).
        let (lo, hi) = (0.5 - 7.25f64.sqrt(), 0.5 + 7.25f64.sqrt());
        for (k, want) in [lo, lo, hi, hi].into_iter().enumerate() {
            assert!((vals[k] - want).abs() < 1e-14, "{vals}");
            let v = vecs.column(k);
            let on_first = v[0] != 0.0 || v[2] != 0.0;
            let on_second = v[1] != 0.0 || v[3] != 0.0;
            assert!(
                on_first != on_second,
                "eigenvector {k} spans both blocks: {v}"
            );
        }
        assert!((&a * &vecs - &vecs * DMatrix::from_diagonal(&vals)).amax() < 1e-15);
        assert!((vecs.transpose() * &vecs - DMatrix::identity(4, 4)).amax() < 1e-15);
        // A coupling above the rounding joins the blocks.
        a[(0, 1)] = 1e-6;
        a[(1, 0)] = 1e-6;
        assert_eq!(blocks(&a).len(), 1);
    }
}
