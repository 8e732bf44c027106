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
    /// Positions are packed as `column · 2³² + row` in one `u64` each (half the memory of
    /// index pairs, and one integer sort).
    pub(crate) fn new(
        nrows: usize,
        ncols: usize,
        positions: impl IntoIterator<Item = (usize, usize)>,
    ) -> Self {
        assert!(nrows < 1 << 32 && ncols < 1 << 32, "pattern too large");
        let mut keys: Vec<u64> = positions
            .into_iter()
            .map(|(r, c)| ((c as u64) << 32) | r as u64)
            .collect();
        keys.sort_unstable();
        keys.dedup();
        assert!(keys.len() < 1 << 32, "pattern too large");
        let mut col_ptr: Vec<Ix> = vec![0; ncols + 1];
        for &k in &keys {
            col_ptr[(k >> 32) as usize + 1] += 1;
        }
        for c in 0..ncols {
            col_ptr[c + 1] += col_ptr[c];
        }
        let row_idx = keys.iter().map(|&k| (k & 0xffff_ffff) as Ix).collect();
        drop(keys);
        Pattern {
            symbolic: SymbolicSparseColMat::new_checked(nrows, ncols, col_ptr, None, row_idx),
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
}
