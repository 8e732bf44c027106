//! A sparse matrix in triplet (coordinate) form: the Jacobian `Φ_q` as `(row, column, value)`
//! entries, the form every consumer of the constraint rows reads (the partition, the factors of
//! `Φ_u`, the KKT assembly). Duplicates are summed: `A_ij = Σ_{(i, j, v)} v`.
//!
//! The row and column indices are `u32` (16 bytes an entry, not 24): at 10,000 bodies the
//! Jacobian holds 740,000 entries, written at every evaluation and read by every pass over
//! `Φ_q` (the factors of `Φ_u`, `Φ_v` products, the KKT assembly), and the passes are bound by
//! memory traffic. Indices only: every value and every sum is the same. A mechanism's rows and
//! coordinates stay far below `2³²` (as many coordinates would be 32 GiB of `q` alone).

use nalgebra::DMatrix;

/// One entry `(row, column, value)` of a [`Triplets`] matrix.
pub(crate) type Triplet = (u32, u32, f64);

/// A sparse matrix in triplet (coordinate) form.
#[derive(Clone, Debug, Default)]
pub(crate) struct Triplets {
    pub(crate) rows: usize,
    pub(crate) cols: usize,
    pub(crate) entries: Vec<Triplet>,
}

impl Triplets {
    /// Dense copy (duplicates summed).
    pub(crate) fn to_dense(&self) -> DMatrix<f64> {
        let mut m = DMatrix::zeros(self.rows, self.cols);
        for &(i, j, v) in &self.entries {
            m[(i as usize, j as usize)] += v;
        }
        m
    }
}
