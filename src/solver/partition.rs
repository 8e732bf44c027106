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
    partition_owned(jac.clone(), row_scale, scale)
}

/// [`partition`] of a Jacobian the caller gives up (eliminated in place, no copy).
pub(crate) fn partition_owned(mut a: DMatrix<f64>, row_scale: &[f64], scale: &[f64]) -> Partition {
    let (m, n) = a.shape();
    // `(x s_j) r_i`, column by column (the order of scaling the columns, then the rows).
    for (col, &s) in a.as_mut_slice().chunks_exact_mut(m.max(1)).zip(scale) {
        for (x, &r) in col.iter_mut().zip(row_scale) {
            *x = *x * s * r;
        }
    }
    let mut row_perm: Vec<usize> = (0..m).collect();
    let mut col_perm: Vec<usize> = (0..n).collect();
    let amax = amax(a.as_slice());
    let mut rank = 0;
    // Rows and columns are swapped in place (position `i` holds row `row_perm[i]`), so that the
    // pivot search and the elimination run down contiguous columns; the search order, the
    // pivots and every update are those of the permuted-index formulation.
    //
    // `col_max[j]` is the largest magnitude of column `j` over the rows not yet pivoted, found
    // at row `col_arg[j]`. A step changes only the columns where the pivot row is nonzero
    // (`a_kj ≠ 0`), and in them only the rows where the pivot column is nonzero (a zero
    // multiplier leaves `x − 0 · p = x`): those rows are listed once per step, so that on a
    // sparse `Φ_q` a step costs the pivot row's nonzeros times the pivot column's. A changed
    // column's maximum is its old one or one of the changed entries where the old one sits in
    // a row that did not change or that now holds at least as much (and is not the pivot row);
    // only otherwise is the column scanned again, and the pivot's own column, which leaves,
    // not at all. The other columns keep their entries and lose a zero (the pivot row's), so
    // their maximum stands. A maximum is exact (no rounding, any order): the same as a scan.
    let mut col_max = Vec::with_capacity(n);
    let mut col_arg = Vec::with_capacity(n);
    for col in a.as_slice().chunks_exact(m.max(1)).take(n) {
        let (v, at) = abs_max(col, 0);
        col_max.push(v);
        col_arg.push(at);
    }
    let mut factor = vec![0.0; m];
    let mut changed = vec![false; m];
    let mut changed_rows: Vec<usize> = Vec::with_capacity(m);
    let mut row_reach: Vec<usize> = Vec::with_capacity(n);
    for k in 0..m.min(n) {
        let best = search(&a, &col_max, k);
        if best.2 <= RANK_TOLERANCE * amax || best.2 == 0.0 {
            break;
        }
        row_perm.swap(k, best.0);
        col_perm.swap(k, best.1);
        col_max.swap(k, best.1);
        col_arg.swap(k, best.1);
        let data = a.as_mut_slice();
        // The swaps move only what is read again: the rows from `k` of the columns from `k`
        // (the eliminated rows and columns are not).
        if best.1 != k {
            let (left, right) = data.split_at_mut(best.1 * m);
            left[k * m + k..(k + 1) * m].swap_with_slice(&mut right[k..m]);
        }
        // The columns the pivot row reaches (after the swaps), listed in the same pass.
        row_reach.clear();
        if best.0 != k {
            for (c, col) in data[k * m..].chunks_exact_mut(m).enumerate() {
                col.swap(k, best.0);
                if col[k] != 0.0 {
                    row_reach.push(k + c);
                }
            }
            for at in col_arg.iter_mut() {
                if *at == k {
                    *at = best.0;
                } else if *at == best.0 {
                    *at = k;
                }
            }
        } else {
            for (c, col) in data[k * m..].chunks_exact(m).enumerate() {
                if col[k] != 0.0 {
                    row_reach.push(k + c);
                }
            }
        }
        let piv = data[k * m + k];
        for &ii in &changed_rows {
            changed[ii] = false;
        }
        changed_rows.clear();
        // A zero's factor (`±0`) is never read: only the changed rows' are.
        for (ii, &x) in data[k * m..(k + 1) * m].iter().enumerate().skip(k + 1) {
            if x == 0.0 {
                continue;
            }
            let f = x / piv;
            factor[ii] = f;
            if f != 0.0 {
                changed_rows.push(ii);
                changed[ii] = true;
            }
        }
        rank = k + 1;
        // Only the columns the pivot row reaches change (`x − f · 0 = x` exactly).
        for &jj in &row_reach {
            let col = &mut data[jj * m..(jj + 1) * m];
            let p = col[k];
            for &ii in &changed_rows {
                col[ii] -= factor[ii] * p;
            }
            if jj == k {
                // The pivot's column leaves: its maximum is never read again.
                continue;
            }
            let at = col_arg[jj];
            // The old maximum stands in its row, or its row changed and holds at least as
            // much: then no entry outside the changed rows exceeds it.
            if at > k && (!changed[at] || col[at].abs() >= col_max[jj]) {
                let (mut mx, mut arg) = (col_max[jj], at);
                for &ii in &changed_rows {
                    let v = col[ii].abs();
                    if v > mx {
                        (mx, arg) = (v, ii);
                    }
                }
                (col_max[jj], col_arg[jj]) = (mx, arg);
            } else {
                let (v, at) = abs_max(&col[k + 1..], k + 1);
                (col_max[jj], col_arg[jj]) = (v, at);
            }
        }
    }
    Partition::of_pivots(&row_perm, &col_perm, rank)
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

/// Entries of a column tested at once against the pivot search's threshold.
const SEARCH_CHUNK: usize = 8;

/// Pivot of step `k`: position `(row, column)` and magnitude, over rows and columns `k..`,
/// scanning only the columns whose maximum `col_max` lies within [`SEARCH_WINDOW`] of the
/// largest; `(k, k, 0)` when every remaining entry is zero.
fn search(a: &DMatrix<f64>, col_max: &[f64], k: usize) -> (usize, usize, f64) {
    let (m, n) = a.shape();
    let data = a.as_slice();
    let top = col_max[k..]
        .iter()
        .fold(0.0_f64, |mx, &x| if x > mx { x } else { mx });
    let cut = top * (1.0 - SEARCH_WINDOW);
    let (mut best, mut threshold) = ((k, k, 0.0), 0.0);
    for jj in k..n {
        // A column whose largest entry does not exceed the threshold (never below 0: a zero
        // column too) changes nothing.
        if col_max[jj] < cut || col_max[jj] <= threshold {
            continue;
        }
        // Chunk by chunk: one without an entry above the threshold (most of a sparse
        // Jacobian's, zeros) changes nothing, and the threshold only rises.
        let mut at = k;
        for chunk in data[jj * m + k..(jj + 1) * m].chunks(SEARCH_CHUNK) {
            if chunk.iter().fold(0.0_f64, |mx, x| mx.max(x.abs())) > threshold {
                for (i, &x) in chunk.iter().enumerate() {
                    let v = x.abs();
                    if v > threshold {
                        best = (at + i, jj, v);
                        threshold = v * (1.0 + 1e-9);
                    }
                }
            }
            at += chunk.len();
        }
    }
    best
}

/// The largest magnitude in `x` and its index plus `offset` (`(0, offset)` if none is above 0;
/// a NaN is passed over): the first entry above all before it, found chunk by chunk (a chunk
/// whose largest magnitude does not exceed the maximum so far changes nothing).
pub(crate) fn abs_max(x: &[f64], offset: usize) -> (f64, usize) {
    let (mut mx, mut at) = (0.0_f64, offset);
    for (c, chunk) in x.chunks(SEARCH_CHUNK).enumerate() {
        let top = chunk
            .iter()
            .fold(0.0_f64, |t, v| if v.abs() > t { v.abs() } else { t });
        if top <= mx {
            continue;
        }
        for (i, v) in chunk.iter().enumerate() {
            if v.abs() > mx {
                (mx, at) = (v.abs(), offset + c * SEARCH_CHUNK + i);
            }
        }
    }
    (mx, at)
}

/// `DMatrix::amax` of the entries `x`: its fold, `|x₀|` then `a ≥ |x| ? a : |x|`, is the
/// largest magnitude in any order where no entry is a NaN, so it is taken over eight lanes at
/// once, and in nalgebra's order where one is.
fn amax(x: &[f64]) -> f64 {
    let mut lanes = [0.0_f64; 8];
    let mut nan = false;
    let chunks = x.chunks_exact(8);
    let rest = chunks.remainder();
    for chunk in chunks {
        for (l, v) in lanes.iter_mut().zip(chunk) {
            let v = v.abs();
            nan |= v.is_nan();
            *l = if *l >= v { *l } else { v };
        }
    }
    for v in rest {
        nan |= v.is_nan();
    }
    let Some((first, tail)) = x.split_first() else {
        return 0.0;
    };
    let fold = |a: f64, v: &f64| {
        let v = v.abs();
        if a >= v {
            a
        } else {
            v
        }
    };
    if nan {
        return tail.iter().fold(first.abs(), fold);
    }
    rest.iter().fold(lanes.iter().fold(0.0, fold), fold)
}

impl Partition {
    /// The partition of an elimination that made `rank` pivots, position `k` of the permuted
    /// rows and columns holding row `row_perm[k]` and column `col_perm[k]`: the first `rank`
    /// are the independent rows and dependent coordinates in pivot order, the others the
    /// redundant rows and independent coordinates, ascending.
    pub(crate) fn of_pivots(row_perm: &[usize], col_perm: &[usize], rank: usize) -> Self {
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
#[path = "partition_tests.rs"]
mod tests;
