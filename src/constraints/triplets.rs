//! A sparse matrix in triplet (coordinate) form: the Jacobian `Φ_q` as `(row, column, value)`
//! entries, the form every consumer of the constraint rows reads (the partition, the factors of
//! `Φ_u`, the KKT assembly). Duplicates are summed: `A_ij = Σ_{(i, j, v)} v`.

use nalgebra::DMatrix;

/// A sparse matrix in triplet (coordinate) form.
#[derive(Clone, Debug, Default)]
pub(crate) struct Triplets {
    pub(crate) rows: usize,
    pub(crate) cols: usize,
    pub(crate) entries: Vec<(usize, usize, f64)>,
}

impl Triplets {
    /// Dense copy (duplicates summed).
    pub(crate) fn to_dense(&self) -> DMatrix<f64> {
        let mut m = DMatrix::zeros(self.rows, self.cols);
        for &(i, j, v) in &self.entries {
            m[(i, j)] += v;
        }
        m
    }
}
