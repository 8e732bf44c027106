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
    /// The sparse partition's choices for the rows of one body (contacts, stops) in its second
    /// pass (module `sparse::partition`): `(row, body, true)` pivoted at `body`, `(row, body,
    /// false)` refused at `body` and carried on; sorted. They rest on entries that shrink as
    /// the bodies turn: the minimizer re-partitions after a step that changes them. Empty for
    /// the dense partition.
    pub(crate) second_pass: Vec<(usize, usize, bool)>,
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
    //
    // `col_max[j]` is the largest magnitude of column `j` over the rows not yet pivoted. A
    // step changes only the columns where the pivot row is nonzero (`a_kj ≠ 0`); the others
    // keep their entries and lose a zero (the pivot row's), so their maximum stands and only
    // the updated columns are scanned again: on a sparse `Φ_q` a step costs the pivot row's
    // nonzeros times the remaining rows instead of the whole remaining block.
    let col_abs_max = |a: &DMatrix<f64>, j: usize, from: usize| {
        a.column(j)
            .rows_range(from..)
            .iter()
            .fold(0.0_f64, |mx, x| if x.abs() > mx { x.abs() } else { mx })
    };
    let mut col_max: Vec<f64> = (0..n).map(|j| col_abs_max(&a, j, 0)).collect();
    let mut factor = vec![0.0; m];
    for k in 0..m.min(n) {
        let best = search(&a, &col_max, k);
        if best.2 <= RANK_TOLERANCE * amax || best.2 == 0.0 {
            break;
        }
        row_perm.swap(k, best.0);
        a.swap_rows(k, best.0);
        col_perm.swap(k, best.1);
        a.swap_columns(k, best.1);
        col_max.swap(k, best.1);
        let piv = a[(k, k)];
        for ii in k + 1..m {
            factor[ii] = a[(ii, k)] / piv;
        }
        rank = k + 1;
        for jj in k..n {
            let p = a[(k, jj)];
            if p == 0.0 {
                // `x − f · 0 = x` exactly: the column is unchanged.
                continue;
            }
            let mut col = a.column_mut(jj);
            for ii in k + 1..m {
                if factor[ii] != 0.0 {
                    col[ii] -= factor[ii] * p;
                }
            }
            col_max[jj] = col_abs_max(&a, jj, k + 1);
        }
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
        second_pass: Vec::new(),
    }
}

/// Relative window below the largest remaining magnitude in which columns are scanned for the
/// pivot.
///
/// The pivot is the first entry, in column-major scan order, that exceeds every earlier
/// entry by more than the tie factor `1 + 1e-9`. An entry far below the largest magnitude `M`
/// can change that choice only through a chain of entries, each within the tie factor of the
/// next, reaching up to `M`: from `(1 − 1e-6) M` that chain needs about a thousand entries.
/// Columns whose maximum is below the window are therefore skipped, and the choice equals the
/// full scan's unless a column holds such a chain.
const SEARCH_WINDOW: f64 = 1e-6;

/// Pivot of step `k`: position `(row, column)` and magnitude, over rows and columns `k..`,
/// scanning only the columns whose maximum `col_max` lies within [`SEARCH_WINDOW`] of the
/// largest; `(k, k, 0)` when every remaining entry is zero.
fn search(a: &DMatrix<f64>, col_max: &[f64], k: usize) -> (usize, usize, f64) {
    let (m, n) = a.shape();
    let top = col_max[k..]
        .iter()
        .fold(0.0_f64, |mx, &x| if x > mx { x } else { mx });
    let cut = top * (1.0 - SEARCH_WINDOW);
    let (mut best, mut threshold) = ((k, k, 0.0), 0.0);
    for jj in k..n {
        if col_max[jj] < cut || col_max[jj] == 0.0 {
            continue;
        }
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
}

impl Partition {
    /// Whether two partitions choose the same dependent coordinates and rows (in any order).
    pub(crate) fn same_split(&self, other: &Partition) -> bool {
        let sorted = |x: &[usize]| {
            let mut x = x.to_vec();
            x.sort_unstable();
            x
        };
        sorted(&self.dependent) == sorted(&other.dependent)
            && sorted(&self.rows) == sorted(&other.rows)
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

    /// The permuted-index formulation this module used before the in-place swaps and the
    /// fused pivot search (kept as the reference the faster one must equal exactly).
    fn reference(jac: &DMatrix<f64>, row_scale: &[f64], scale: &[f64]) -> Partition {
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
        for k in 0..m.min(n) {
            let mut best = (k, k, 0.0);
            for jj in k..n {
                let c = col_perm[jj];
                for ii in k..m {
                    let v = a[(row_perm[ii], c)].abs();
                    if v > best.2 * (1.0 + 1e-9) {
                        best = (ii, jj, v);
                    }
                }
            }
            if best.2 <= RANK_TOLERANCE * amax || best.2 == 0.0 {
                break;
            }
            row_perm.swap(k, best.0);
            col_perm.swap(k, best.1);
            let (pr, pc) = (row_perm[k], col_perm[k]);
            let piv = a[(pr, pc)];
            for ii in k + 1..m {
                let r = row_perm[ii];
                let f = a[(r, pc)] / piv;
                if f != 0.0 {
                    for jj in k..n {
                        let c = col_perm[jj];
                        a[(r, c)] -= f * a[(pr, c)];
                    }
                }
            }
            rank = k + 1;
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
            second_pass: Vec::new(),
        }
    }

    /// The in-place, fused elimination picks exactly the pivots of the reference (same rank,
    /// same order of dependent columns and rows) on random matrices with ties, zero columns,
    /// redundant rows and scaling.
    #[test]
    fn equals_the_permuted_index_reference() {
        let mut lcg = crate::lcg::Lcg::new(12345);
        let mut next = || lcg.unit();
        for trial in 0..2000 {
            let m = 1 + trial % 17;
            let n = 1 + (trial * 7) % 23;
            let mut j = DMatrix::from_fn(m, n, |_, _| {
                let x = next();
                // Many exact zeros and repeated magnitudes (pivot ties).
                if x < 0.3 {
                    0.0
                } else if x < 0.5 {
                    1.0
                } else if x < 0.6 {
                    // Near-ties within the 1e-9 tie factor, and just outside it.
                    1.0 + (x - 0.5) * 3e-8
                } else {
                    (x - 0.75) * 4.0
                }
            });
            if m > 2 {
                // A redundant row.
                let r = j.row(0) * 2.0 - j.row(1);
                j.set_row(m - 1, &r);
            }
            let rows: Vec<f64> = (0..m).map(|_| 0.5 + next()).collect();
            let cols: Vec<f64> = (0..n)
                .map(|_| if next() < 0.5 { 1.0 } else { 0.3 })
                .collect();
            let (a, b) = (partition(&j, &rows, &cols), reference(&j, &rows, &cols));
            assert_eq!(a.dependent, b.dependent, "trial {trial}");
            assert_eq!(a.independent, b.independent, "trial {trial}");
            assert_eq!(a.rows, b.rows, "trial {trial}");
            assert_eq!(a.redundant, b.redundant, "trial {trial}");
        }
    }
}
