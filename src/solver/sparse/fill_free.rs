//! The sparse partition of `D Φ_q S` (module `partition`) computed on dense copies of each
//! body's rows: the same pivots, in the same order, with the same arithmetic on every nonzero
//! entry, without the general sparse elimination's row lists, position maps and sorts.
//!
//! The sparse partition eliminates the bodies in its order (deepest first); at body `b` it
//! pivots up to seven times on the largest threshold-passing entry `|a_rc| ≥ τ max_k |a_rk|`
//! (τ = 0.1) of `b`'s free columns among the active rows touching `b`, eliminating
//! `a_i ← a_i − (a_ic / a_rc) a_r` from the other rows touching `b`, then pivots the rows that
//! started on `b` alone on the free entry of `b` largest against the row's reach there (its
//! largest starting entry on `b` in columns of the same kind), if at least `OWN_THRESHOLD` of
//! it. Body `b`'s step reads only the active rows touching `b`, and changes only them.
//!
//! This module repeats those steps body by body on dense copies of the rows touching `b`
//! (module `block`) over the columns of every body they touch: the rows as first expanded from
//! the triplets (module `rows`), or, for a row that an earlier body's step changed and left
//! active (a closed loop's rows, which carry fill to the loop's other bodies: the ladder's
//! border), its changed copy kept from that step (`block::Changed`). On a tree no row is
//! left active after its body's step and nothing is kept; on a ladder a level's rows are
//! resolved within its three bodies. Every row ends a pivot row or redundant: the pivots in
//! their order are the partition's dependent columns and independent rows, the other rows its
//! redundant ones, the columns left free its independent coordinates, the second pass's
//! pivots its `second_pass` list. The route gives up (`None`, the caller runs the sparse
//! partition) where the sparse partition would do what it does not: carry a row that started
//! on one body on to the bodies its fill reached (a contact below a vertical link), finish
//! rows left after the last body by full pivoting, or (for its cost) span more than
//! [`MAX_BODIES`] bodies in one step (a long loop's rows gather every body they pass).
//! `verify`'s tests check that the partitions agree to the last index on every model of
//! their set, with and without a lock on every joint coordinate.

use super::block::{Block, Changed};
use super::partition::elimination_order;
use super::rows::Rows;
use crate::constraints::Triplet;
use crate::model::Model;
use crate::solver::partition::{next_id, Partition, RANK_TOLERANCE};

/// The most bodies one body's step may span (beyond it the sparse partition is used).
pub(crate) const MAX_BODIES: usize = 32;

/// The number of free columns `n − rank` the sparse partition leaves for the `m × n` Jacobian
/// `entries` with row and column scales, or `None` where this route gives up (then only the
/// sparse partition gives it).
pub(crate) fn free_columns(
    model: &Model,
    m: usize,
    n: usize,
    entries: &[Triplet],
    row_scale: &[f64],
    scale: &[f64],
) -> Option<usize> {
    eliminate(model, m, n, entries, row_scale, scale).map(|p| n - p.order.len())
}

/// The pivots of the elimination: `(row, column)` in pivot order, and the second pass's
/// `(row, body, true)`.
struct Pivots {
    order: Vec<(usize, usize)>,
    second: Vec<(usize, usize, bool)>,
}

/// The sparse partition (`sparse::partition::partition`, the same `Partition` but for its id)
/// of the `m × n` Jacobian `entries` with row and column scales, or `None` where this route
/// gives up.
pub(crate) fn partition(
    model: &Model,
    m: usize,
    n: usize,
    entries: &[Triplet],
    row_scale: &[f64],
    scale: &[f64],
) -> Option<Partition> {
    let p = eliminate(model, m, n, entries, row_scale, scale)?;
    let mut pivot_row = vec![false; m];
    let mut free = vec![true; n];
    for &(r, c) in &p.order {
        pivot_row[r] = true;
        free[c] = false;
    }
    let mut second_pass = p.second;
    second_pass.sort_unstable();
    Some(Partition {
        id: next_id(),
        dependent: p.order.iter().map(|e| e.1).collect(),
        independent: (0..n).filter(|&c| free[c]).collect(),
        rows: p.order.iter().map(|e| e.0).collect(),
        redundant: (0..m).filter(|&r| !pivot_row[r]).collect(),
        second_pass,
    })
}

/// The elimination ([`partition`]): its pivots, or `None` where this route gives up.
fn eliminate(
    model: &Model,
    m: usize,
    n: usize,
    entries: &[Triplet],
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
    let mut changed = Changed::new(m, n / 7);
    let mut cands = Vec::new();
    for b in elimination_order(model) {
        rows.touching(b, &mut cands);
        changed.touching(b, &mut cands);
        block.load(b, &cands, &active, &rows, &changed);
        if block.bodies() > MAX_BODIES {
            return None;
        }
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
        if block.carries_own_row(&free, tol, b, &rows) {
            return None;
        }
        block.keep(&mut changed);
    }
    if active.iter().any(|&a| a) {
        return None;
    }
    Some(pivots)
}
