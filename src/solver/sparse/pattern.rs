//! A compressed-column sparsity pattern, built once from (row, column) positions, that knows the
//! slot of every position: values are then refilled in place at each evaluation
//! (`values[slot(i, j)] += a_ij`) and handed to faer with the same symbolic structure.

use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};

/// Index type of the sparse structures: 32 bits (half the memory of `usize` for the patterns
/// and factors; up to 4·10⁹ rows).
pub(crate) type Ix = u32;

/// Marks a position outside the pattern (or a triplet that does not belong to a sub-matrix).
pub(crate) const NONE: usize = usize::MAX;

/// The sorted, de-duplicated positions of a sparse matrix in compressed-column form.
#[derive(Clone, Debug)]
pub(crate) struct Pattern {
    symbolic: SymbolicSparseColMat<Ix>,
}

impl Pattern {
    /// The pattern of `positions` (any order, duplicates allowed) in an `nrows × ncols` matrix.
    pub(crate) fn new(
        nrows: usize,
        ncols: usize,
        positions: impl IntoIterator<Item = (usize, usize)>,
    ) -> Self {
        let positions = positions.into_iter();
        let capacity = positions.size_hint().0;
        Self::with_capacity(nrows, ncols, capacity, positions)
    }

    /// [`Pattern::new`] with room for `capacity` positions reserved (no reallocation while
    /// they are collected when it is their number).
    ///
    /// Positions are packed as `column · 2³² + row` in one `u64` each (half the memory of
    /// index pairs), then sorted by a counting sort on the column (`O(nnz + ncols)`) followed
    /// by a sort of each column's few rows: a global sort of the 1.5·10⁶ positions of a
    /// 10,000-link chain's KKT matrix cost 6 % of `verify`.
    pub(crate) fn with_capacity(
        nrows: usize,
        ncols: usize,
        capacity: usize,
        positions: impl IntoIterator<Item = (usize, usize)>,
    ) -> Self {
        assert!(nrows < 1 << 32 && ncols < 1 << 32, "pattern too large");
        let mut keys: Vec<u64> = Vec::with_capacity(capacity);
        keys.extend(
            positions
                .into_iter()
                .map(|(r, c)| ((c as u64) << 32) | r as u64),
        );
        assert!(keys.len() < 1 << 32, "pattern too large");
        // Counting sort by column: `start[c]` the first place of column `c`.
        let mut start: Vec<usize> = vec![0; ncols + 1];
        for &k in &keys {
            start[(k >> 32) as usize + 1] += 1;
        }
        for c in 0..ncols {
            start[c + 1] += start[c];
        }
        let mut rows: Vec<Ix> = vec![0; keys.len()];
        let mut next = start.clone();
        for &k in &keys {
            let c = (k >> 32) as usize;
            rows[next[c]] = (k & 0xffff_ffff) as Ix;
            next[c] += 1;
        }
        drop((keys, next));
        // Each column's rows sorted and de-duplicated, compacted in place.
        let mut col_ptr: Vec<Ix> = vec![0; ncols + 1];
        let mut len = 0;
        for c in 0..ncols {
            let column = &mut rows[start[c]..start[c + 1]];
            column.sort_unstable();
            let mut last = None;
            for k in start[c]..start[c + 1] {
                let r = rows[k];
                if last != Some(r) {
                    rows[len] = r;
                    len += 1;
                    last = Some(r);
                }
            }
            col_ptr[c + 1] = len as Ix;
        }
        rows.truncate(len);
        rows.shrink_to_fit();
        Pattern {
            symbolic: SymbolicSparseColMat::new_checked(nrows, ncols, col_ptr, None, rows),
        }
    }

    /// Number of stored entries.
    pub(crate) fn nnz(&self) -> usize {
        self.symbolic.row_idx().len()
    }

    /// The slot of position `(r, c)`, or [`NONE`].
    pub(crate) fn slot(&self, r: usize, c: usize) -> usize {
        let ptr = self.symbolic.col_ptr();
        let (a, b) = (ptr[c] as usize, ptr[c + 1] as usize);
        self.symbolic.row_idx()[a..b]
            .binary_search(&(r as Ix))
            .map_or(NONE, |k| a + k)
    }

    /// The structure, for faer's symbolic factorizations.
    pub(crate) fn symbolic(&self) -> faer::sparse::SymbolicSparseColMatRef<'_, Ix> {
        self.symbolic.as_ref()
    }

    /// The matrix with this pattern and `values` (one per slot).
    pub(crate) fn matrix<'a>(&'a self, values: &'a [f64]) -> SparseColMatRef<'a, Ix, f64> {
        SparseColMatRef::new(self.symbolic.as_ref(), values)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slots_cover_positions_and_duplicates_share_a_slot() {
        let p = Pattern::new(3, 3, vec![(2, 0), (0, 0), (1, 2), (2, 0), (0, 2)]);
        assert_eq!(p.nnz(), 4);
        assert_eq!(p.slot(0, 0), 0);
        assert_eq!(p.slot(2, 0), 1);
        assert_eq!(p.slot(0, 2), 2);
        assert_eq!(p.slot(1, 2), 3);
        assert_eq!(p.slot(1, 1), NONE);
    }

    /// The counting sort gives the pattern of a global sort: random positions with
    /// duplicates, every column's rows ascending and unique, each position found.
    #[test]
    fn counting_sort_equals_a_global_sort() {
        let mut lcg = crate::lcg::Lcg::new(7);
        let mut next = |m: u64| ((lcg.next_u64() >> 33) % m) as usize;
        let positions: Vec<(usize, usize)> = (0..2000).map(|_| (next(50), next(40))).collect();
        let p = Pattern::with_capacity(50, 40, positions.len(), positions.iter().copied());
        let mut sorted: Vec<(usize, usize)> = positions.iter().map(|&(r, c)| (c, r)).collect();
        sorted.sort_unstable();
        sorted.dedup();
        assert_eq!(p.nnz(), sorted.len());
        let sym = p.symbolic();
        let (ptr, idx) = (sym.col_ptr(), sym.row_idx());
        let mut k = 0;
        for c in 0..40 {
            for j in ptr[c] as usize..ptr[c + 1] as usize {
                assert_eq!((c, idx[j] as usize), sorted[k]);
                k += 1;
            }
        }
        for &(r, c) in &positions {
            assert_ne!(p.slot(r, c), NONE);
        }
    }
}
