//! The solver's sparse partition of `D Φ_q S` without the general sparse elimination when it
//! has no fill between bodies (trees): the same pivots, the same arithmetic, on a few rows at
//! a time. `check` counts its free columns (`n − rank`); `verify` takes the partition itself
//! ([`partition`]: the same `Partition` to the last index, so the factors and every number
//! computed from them are the same to the bit).
//!
//! The solver's sparse partition (`solver::sparse::partition`) eliminates the bodies in its
//! order (deepest first); at body `b` it pivots up to seven times on the largest threshold-
//! passing entry `|a_rc| ≥ τ max_k |a_rk|` (τ = 0.1) of `b`'s free columns among the active
//! rows touching `b`, eliminating `a_i ← a_i − (a_ic / a_rc) a_r` from the other rows touching
//! `b`, then pivots the rows that started on `b` alone on the free entry of `b` largest against
//! the row's reach there (its largest starting entry on `b` in columns of the same kind), if at
//! least `OWN_THRESHOLD` of it.
//! When every row touching `b` is a pivot row or redundant after that, the rows changed there
//! are never read again: `b`'s step depends only on the original entries of its own rows. This
//! module repeats exactly those steps body by body on copies of the rows touching `b` (so the
//! same pivots are chosen, in the same order, with the same floating-point operations on every
//! nonzero entry: dense copies, module `rank_block`, of the rows expanded once, module
//! `rank_rows`), and gives up (`None`) at the first body where a row touching it stays active (a
//! loop's rows, which carry fill to other bodies): the caller then runs the full partition.
//! Every row then ends a pivot row or redundant: the pivots in their order are the partition's
//! dependent columns and independent rows, the other rows its redundant ones, the columns left
//! free its independent coordinates, the second pass's pivots its `second_pass` list. Tests
//! check that the partitions agree on every model of the test set, with and without a lock on
//! every joint coordinate (`verify`'s locked system).

use crate::model::Model;
use crate::solver::partition::RANK_TOLERANCE;
use crate::solver::partition::{next_id, Partition};
use crate::solver::sparse::partition::elimination_order;
use crate::solver::system::{Backend, System};
use nalgebra::DVector;

use super::rank_block::Block;
use super::rank_rows::Rows;

/// The number of free columns `n − rank` the sparse partition leaves for the `m × n` Jacobian
/// `entries` with row and column scales, or `None` if the elimination has fill between bodies
/// (then only the partition itself gives it).
pub(super) fn free_columns(
    model: &Model,
    m: usize,
    n: usize,
    entries: &[(usize, usize, f64)],
    row_scale: &[f64],
    scale: &[f64],
) -> Option<usize> {
    eliminate(model, m, n, entries, row_scale, scale).map(|p| n - p.order.len())
}

/// The pivots of the fill-free elimination: `(row, column)` in pivot order, and the second
/// pass's `(row, body, true)`.
struct Pivots {
    order: Vec<(usize, usize)>,
    second: Vec<(usize, usize, bool)>,
}

/// The sparse partition of the rows of `sys` at `q` (`sys.partition(q)`, the same
/// `Partition` but for its id), by the fill-free elimination where the model has neither
/// closed loops nor mimics and the elimination answers; by the solver's partition otherwise.
pub(super) fn partition(sys: &mut System, q: &DVector<f64>) -> Partition {
    let model = sys.problem.model;
    if sys.backend == Backend::Dense || super::coupled(model) {
        return sys.partition(q);
    }
    sys.triplets(q);
    let (jac, s) = (&sys.work.jac, &sys.problem.scaling);
    let (m, n) = (jac.rows, jac.cols);
    let Some(p) = eliminate(model, m, n, &jac.entries, &s.rows, &s.columns) else {
        return sys.partition(q);
    };
    let mut pivot_row = vec![false; m];
    let mut free = vec![true; n];
    for &(r, c) in &p.order {
        pivot_row[r] = true;
        free[c] = false;
    }
    let mut second_pass = p.second;
    second_pass.sort_unstable();
    Partition {
        id: next_id(),
        dependent: p.order.iter().map(|e| e.1).collect(),
        independent: (0..n).filter(|&c| free[c]).collect(),
        rows: p.order.iter().map(|e| e.0).collect(),
        redundant: (0..m).filter(|&r| !pivot_row[r]).collect(),
        second_pass,
    }
}

/// The fill-free elimination ([`free_columns`]): its pivots, or `None` if it has fill between
/// bodies.
fn eliminate(
    model: &Model,
    m: usize,
    n: usize,
    entries: &[(usize, usize, f64)],
    row_scale: &[f64],
    scale: &[f64],
) -> Option<Pivots> {
    let rows = Rows::new(m, n, entries, row_scale, scale)?;
    let amax = rows.rmax.iter().fold(0.0f64, |a, &x| a.max(x));
    let tol = (RANK_TOLERANCE * amax).max(f64::MIN_POSITIVE);
    let mut active: Vec<bool> = rows.rmax.iter().map(|&x| x > tol).collect();
    let mut pivots = Pivots {
        order: Vec::with_capacity(n),
        second: Vec::new(),
    };
    let mut block = Block::default();
    let mut cands = Vec::new();
    for b in elimination_order(model) {
        rows.touching(b, &mut cands);
        block.load(b, &cands, &active, &rows);
        // The body's free columns (none taken before its step).
        let mut free = [true; 7];
        let mut taken = 0;
        while taken < 7 {
            let Some((i, k)) = block.best_pivot(&free, tol) else {
                break;
            };
            pivots.order.push((block.rows[i], 7 * b + k));
            free[k] = false;
            block.pivot(i, k, &mut active, tol);
            taken += 1;
        }
        while taken < 7 {
            let Some((i, k)) = block.best_own_pivot(&free, tol, b, &rows) else {
                break;
            };
            pivots.order.push((block.rows[i], 7 * b + k));
            pivots.second.push((block.rows[i], b, true));
            free[k] = false;
            block.pivot(i, k, &mut active, tol);
            taken += 1;
        }
        if block.live.iter().any(|&l| l) {
            return None;
        }
    }
    if active.iter().any(|&a| a) {
        return None;
    }
    Some(pivots)
}

#[cfg(test)]
#[path = "rank_tests.rs"]
mod tests;
