//! Coordinate partitioning by Gaussian elimination with full pivoting of `Φ_q` (paper §3).
//!
//! The Jacobian is first made dimensionless, `D Φ_q S`: `S = diag(L …, 1 …)` scales position
//! columns by the characteristic length `L` (Euler-parameter columns by 1), and `D` divides
//! each row by `L^k` for a row in m^k, so that the choice does not depend on the length unit.
//! Near-ties (within a relative 1e-9) go to the first candidate, so that rounding differences
//! cannot flip the choice. At step `k` the entry of largest magnitude in the remaining block is the
//! pivot; its column becomes a dependent coordinate `u_k` and its row an independent row. The
//! elimination stops when the largest remaining entry is below `tol · max|Φ_q S|`: the number
//! of steps is the rank `r`, the unpivoted rows are redundant, the unpivoted columns are the
//! independent coordinates `v` (`n − r` degrees of freedom).

use nalgebra::DMatrix;

/// Result of a partition.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Partition {
    /// Distinct for every partition computed in this process (the sparse path keys its cached
    /// structures on it).
    pub(crate) id: usize,
    /// Dependent coordinates `u` (pivot columns), in pivot order.
    pub(crate) dependent: Vec<usize>,
    /// Independent coordinates `v`, ascending.
    pub(crate) independent: Vec<usize>,
    /// Independent constraint rows (pivot rows), in pivot order.
    pub(crate) rows: Vec<usize>,
    /// Redundant constraint rows, ascending.
    pub(crate) redundant: Vec<usize>,
}

/// A fresh partition id.
pub(crate) fn next_id() -> usize {
    static NEXT: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(1);
    NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed)
}

/// Relative rank tolerance of the full-pivoting elimination.
pub(crate) const RANK_TOLERANCE: f64 = 1e-9;

/// Partitions the (dense) Jacobian `jac` with row scales `row_scale` and column scales `scale`.
pub(crate) fn partition(jac: &DMatrix<f64>, row_scale: &[f64], scale: &[f64]) -> Partition {
    let (m, n) = jac.shape();
    let mut a = jac.clone();
    for j in 0..n {
        a.column_mut(j).scale_mut(scale[j]);
    }
    for i in 0..m {
        a.row_mut(i).scale_mut(row_scale[i]);
    }
    let mut row_perm: Vec<usize> = (0..m).collect();
    let mut col_perm: Vec<usize> = (0..n).collect();
    let amax = a.amax();
    let mut rank = 0;
    // Rows and columns are swapped in place (position `i` holds row `row_perm[i]`), so that the
    // pivot search and the elimination run down contiguous columns; the search order, the
    // pivots and every update are those of the permuted-index formulation.
    // The pivot search of step `k + 1` runs inside the elimination of step `k` (same order:
    // columns, then rows, from `k + 1`), so the matrix is read once per step.
    let mut factor = vec![0.0; m];
    let search = |a: &DMatrix<f64>, k: usize| {
        let (mut best, mut threshold) = ((k, k, 0.0), 0.0);
        for jj in k..n {
            let col = a.column(jj);
            for ii in k..m {
                let v = col[ii].abs();
                if v > threshold {
                    best = (ii, jj, v);
                    threshold = v * (1.0 + 1e-9);
                }
            }
        }
        best
    };
    let mut best = search(&a, 0);
    for k in 0..m.min(n) {
        if best.2 <= RANK_TOLERANCE * amax || best.2 == 0.0 {
            break;
        }
        row_perm.swap(k, best.0);
        a.swap_rows(k, best.0);
        col_perm.swap(k, best.1);
        a.swap_columns(k, best.1);
        let piv = a[(k, k)];
        for ii in k + 1..m {
            factor[ii] = a[(ii, k)] / piv;
        }
        rank = k + 1;
        let mut next = (k + 1, k + 1, 0.0);
        let mut threshold = 0.0;
        for jj in k..n {
            let p = a[(k, jj)];
            let mut col = a.column_mut(jj);
            for ii in k + 1..m {
                if factor[ii] != 0.0 {
                    col[ii] -= factor[ii] * p;
                }
                if jj > k {
                    let v = col[ii].abs();
                    if v > threshold {
                        next = (ii, jj, v);
                        threshold = v * (1.0 + 1e-9);
                    }
                }
            }
        }
        best = next;
    }
    let mut independent = col_perm[rank..].to_vec();
    independent.sort_unstable();
    let mut redundant = row_perm[rank..].to_vec();
    redundant.sort_unstable();
    Partition {
        id: next_id(),
        dependent: col_perm[..rank].to_vec(),
        independent,
        rows: row_perm[..rank].to_vec(),
        redundant,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn detects_rank_and_redundant_row() {
        // Row 2 = row 0 + row 1.
        let j = DMatrix::from_row_slice(
            3,
            4,
            &[1.0, 2.0, 0.0, 0.0, 0.0, 1.0, 3.0, 0.0, 1.0, 3.0, 3.0, 0.0],
        );
        let p = partition(&j, &[1.0; 3], &[1.0; 4]);
        assert_eq!(p.dependent.len(), 2);
        assert_eq!(p.redundant.len(), 1);
        assert_eq!(p.independent.len(), 2);
        assert!(p.independent.contains(&3));
    }

    #[test]
    fn full_pivot_picks_largest() {
        let j = DMatrix::from_row_slice(1, 3, &[0.1, -5.0, 2.0]);
        let p = partition(&j, &[1.0; 1], &[1.0; 3]);
        assert_eq!(p.dependent, vec![1]);
        assert_eq!(p.independent, vec![0, 2]);
    }
}
