//! The sparse partition as `verify` and `check` take it. The solver's partition
//! (`System::partition`) runs the elimination on dense copies of each body's rows
//! (`solver::sparse::fill_free`) wherever that route answers (trees, ladders), the general
//! sparse elimination otherwise, and gives the same `Partition` either way (to the last
//! index, so the factors and every number computed from them are the same to the bit):
//! `verify`'s locked system (the model's rows and a lock row per joint coordinate) and
//! `check`'s count of free columns take it from there. Tests check that the two routes agree
//! on every model of the test set, with and without a lock on every joint coordinate.

use crate::model::Model;
use crate::solver::partition::Partition;
use crate::solver::system::System;
use nalgebra::DVector;

/// The number of free columns `n − rank` the sparse partition leaves for the `m × n` Jacobian
/// `entries` with row and column scales, or `None` where the dense-copy route gives up (then
/// only the partition itself gives it).
pub(super) fn free_columns(
    model: &Model,
    m: usize,
    n: usize,
    entries: &[(usize, usize, f64)],
    row_scale: &[f64],
    scale: &[f64],
) -> Option<usize> {
    crate::solver::sparse::fill_free::free_columns(model, m, n, entries, row_scale, scale)
}

/// The partition of the rows of `sys` at `q`: `sys.partition(q)`, by the dense copies where
/// they answer.
pub(super) fn partition(sys: &mut System, q: &DVector<f64>) -> Partition {
    sys.partition(q)
}

#[cfg(test)]
#[path = "rank_tests.rs"]
mod tests;
