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
//! entry), and gives up (`None`) at the first body where a row touching it stays active (a
//! loop's rows, which carry fill to other bodies): the caller then runs the full partition.
//! Every row then ends a pivot row or redundant: the pivots in their order are the partition's
//! dependent columns and independent rows, the other rows its redundant ones, the columns left
//! free its independent coordinates, the second pass's pivots its `second_pass` list. Tests
//! check that the partitions agree on every model of the test set, with and without a lock on
//! every joint coordinate (`verify`'s locked system).

use crate::model::Model;
use crate::solver::partition::RANK_TOLERANCE;
use crate::solver::partition::{next_id, Partition};
use crate::solver::sparse::partition::{elimination_order, OWN_THRESHOLD, THRESHOLD};
use crate::solver::system::{Backend, System};
use nalgebra::DVector;

/// The rows of a Jacobian whose triplets are grouped by row: row `r` is
/// `entries[start[r]..start[r + 1]]`, expanded on demand with its scales.
struct Rows<'e> {
    entries: &'e [(usize, usize, f64)],
    start: Vec<usize>,
    row_scale: &'e [f64],
    scale: &'e [f64],
    /// Where column `c` sits in the row being expanded: `(expansion, position)`.
    seen: Vec<(usize, usize)>,
    expansion: usize,
}

impl<'e> Rows<'e> {
    /// The rows of `entries`, `None` unless they are grouped by ascending row.
    fn new(
        m: usize,
        n: usize,
        entries: &'e [(usize, usize, f64)],
        row_scale: &'e [f64],
        scale: &'e [f64],
    ) -> Option<Self> {
        let mut start = vec![0usize; m + 1];
        let mut last = 0;
        for (k, &(r, c, _)) in entries.iter().enumerate() {
            if r < last || r >= m || c >= n {
                return None;
            }
            for s in &mut start[last + 1..=r] {
                *s = k;
            }
            last = r;
        }
        for s in &mut start[last + 1..] {
            *s = entries.len();
        }
        Some(Rows {
            entries,
            start,
            row_scale,
            scale,
            seen: vec![(usize::MAX, 0); n],
            expansion: 0,
        })
    }

    /// Row `r` into `out` as the partition builds it: the scaled entries
    /// `row_scale[r] · v · scale[c]`, duplicates summed in triplet order into the first one,
    /// zeros dropped, the others in triplet order.
    fn expand(&mut self, r: usize, out: &mut Vec<(usize, f64)>) {
        out.clear();
        self.expansion += 1;
        for &(_, c, v) in &self.entries[self.start[r]..self.start[r + 1]] {
            let a = v * self.row_scale[r] * self.scale[c];
            if self.seen[c].0 == self.expansion {
                out[self.seen[c].1].1 += a;
            } else {
                self.seen[c] = (self.expansion, out.len());
                out.push((c, a));
            }
        }
        out.retain(|e| e.1 != 0.0);
    }
}

/// The elimination at one body: copies of its rows (`slot[i]` is row `cands[i]`).
/// Copies of the active ones only: the others are never read.
struct Local {
    cands: Vec<usize>,
    rows: Vec<Vec<(usize, f64)>>,
    /// `row_max` of each copy, kept current as the copies change (in [`pivot`]).
    rmax: Vec<f64>,
    /// [`on_body`] of each copy at the body, kept current as the copies change and the
    /// body's columns are taken (in [`pivot`]).
    on_b: Vec<([f64; 7], u8)>,
}

fn row_max(row: &[(usize, f64)]) -> f64 {
    row.iter().fold(0.0, |a, &(_, v)| a.max(v.abs()))
}

/// A row's entries on the free columns of body `b`, by column offset `c − 7 b`, and the mask
/// of the offsets present (a row's columns are distinct): the entries a filter and a sort by
/// column would list, in that order.
fn on_body(row: &[(usize, f64)], free: &[bool], b: usize) -> ([f64; 7], u8) {
    let (mut vals, mut mask) = ([0.0; 7], 0u8);
    for &(c, v) in row {
        let k = c.wrapping_sub(7 * b);
        if k < 7 && free[c] {
            vals[k] = v;
            mask |= 1 << k;
        }
    }
    (vals, mask)
}

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
    let nb = n / 7;
    let mut rows = Rows::new(m, n, entries, row_scale, scale)?;
    let mut row = Vec::with_capacity(14);
    // Every row expanded once, kept row after row (`expanded[at[r]..at[r + 1]]`): the passes
    // below and each body's copies read it instead of expanding again.
    let mut expanded: Vec<(usize, f64)> = Vec::with_capacity(entries.len());
    let mut at = Vec::with_capacity(m + 1);
    at.push(0);
    // Each row's largest entry; the rows touching each body (ascending, each once, counted
    // then filled); the body of the rows lying on one body alone.
    let mut rmax = vec![0.0f64; m];
    let mut body_start = vec![0usize; nb + 1];
    let mut own_of = vec![usize::MAX; m];
    let mut reach = vec![[0.0f64; 2]; m];
    for r in 0..m {
        rows.expand(r, &mut row);
        expanded.extend_from_slice(&row);
        at.push(expanded.len());
        rmax[r] = row_max(&row);
        let mut last = usize::MAX;
        for &(c, _) in &row {
            if c / 7 != last {
                last = c / 7;
                body_start[last + 1] += 1;
            }
        }
        if let Some(&(c0, _)) = row.first() {
            if row.iter().all(|e| e.0 / 7 == c0 / 7) {
                own_of[r] = c0 / 7;
                for &(c, v) in &row {
                    let k = usize::from(c % 7 >= 3);
                    reach[r][k] = reach[r][k].max(v.abs());
                }
            }
        }
    }
    let amax = rmax.iter().fold(0.0f64, |a, &x| a.max(x));
    let tol = (RANK_TOLERANCE * amax).max(f64::MIN_POSITIVE);
    let mut active: Vec<bool> = rmax.iter().map(|&x| x > tol).collect();
    for (r, o) in own_of.iter_mut().enumerate() {
        if !active[r] {
            *o = usize::MAX;
        }
    }
    for b in 0..nb {
        body_start[b + 1] += body_start[b];
    }
    let mut body_rows = vec![usize::MAX; body_start[nb]];
    let mut body_fill = body_start.clone();
    for r in 0..m {
        let mut last = usize::MAX;
        for &(c, _) in &expanded[at[r]..at[r + 1]] {
            if c / 7 != last {
                last = c / 7;
                body_rows[body_fill[last]] = r;
                body_fill[last] += 1;
            }
        }
    }
    let mut free = vec![true; n];
    let mut pivots = Pivots {
        order: Vec::with_capacity(n),
        second: Vec::new(),
    };
    let mut local = Local {
        cands: Vec::new(),
        rows: Vec::new(),
        rmax: Vec::new(),
        on_b: Vec::new(),
    };
    let (mut all, mut own) = (Vec::new(), Vec::new());
    for b in elimination_order(model) {
        local.cands.clear();
        local
            .cands
            .extend_from_slice(&body_rows[body_start[b]..body_fill[b]]);
        local.cands.dedup();
        let k = local.cands.len();
        if local.rows.len() < k {
            local.rows.resize_with(k, Vec::new);
            local.rmax.resize(k, 0.0);
            local.on_b.resize(k, ([0.0; 7], 0));
        }
        for (slot, &r) in local.cands.iter().enumerate() {
            let copy = &mut local.rows[slot];
            copy.clear();
            if active[r] {
                copy.extend_from_slice(&expanded[at[r]..at[r + 1]]);
                local.rmax[slot] = rmax[r];
                local.on_b[slot] = on_body(copy, &free, b);
            }
        }
        all.clear();
        all.extend(0..k);
        let mut taken = 0;
        while taken < 7 {
            match best_pivot(&local, &all, &active, tol, b) {
                Some((slot, c)) => {
                    pivots.order.push((local.cands[slot], c));
                    pivot(&mut local, slot, c, &mut active, &mut free, tol, b);
                }
                None => break,
            }
            taken += 1;
        }
        own.clear();
        own.extend((0..k).filter(|&s| own_of[local.cands[s]] == b));
        while taken < 7 {
            match best_own_pivot(&local, &own, &active, tol, b, &reach) {
                Some((slot, c)) => {
                    pivots.order.push((local.cands[slot], c));
                    pivots.second.push((local.cands[slot], b, true));
                    pivot(&mut local, slot, c, &mut active, &mut free, tol, b);
                }
                None => break,
            }
            taken += 1;
        }
        if local.cands.iter().any(|&r| active[r]) {
            return None;
        }
    }
    if active.iter().any(|&a| a) {
        return None;
    }
    Some(pivots)
}

/// The partition's pivot choice among the rows at `slots` (ascending) in the free columns of
/// body `b`: the largest `|a_rc| > tol` with `|a_rc| ≥ THRESHOLD · max_k |a_rk|`, a later one
/// only if larger by a relative `1e-9`.
fn best_pivot(
    local: &Local,
    slots: &[usize],
    active: &[bool],
    tol: f64,
    b: usize,
) -> Option<(usize, usize)> {
    let mut best: Option<(usize, usize, f64)> = None;
    for &s in slots {
        if !active[local.cands[s]] {
            continue;
        }
        let rmax = local.rmax[s];
        let (vals, mask) = local.on_b[s];
        for k in (0..7).filter(|k| mask & (1 << k) != 0) {
            let a = vals[k].abs();
            if a > tol && a >= THRESHOLD * rmax && best.is_none_or(|x| a > x.2 * (1.0 + 1e-9)) {
                best = Some((s, 7 * b + k, a));
            }
        }
    }
    best.map(|(s, c, _)| (s, c))
}

/// The partition's second-pass pivot at body `b` among the rows at `slots` (ascending) that
/// started on `b` alone: the entry on a free column of `b` largest relative to the row's
/// `reach` there (same kind of column), if at least `OWN_THRESHOLD` of it; a later one only
/// if larger by a relative `1e-9`.
fn best_own_pivot(
    local: &Local,
    slots: &[usize],
    active: &[bool],
    tol: f64,
    b: usize,
    reach: &[[f64; 2]],
) -> Option<(usize, usize)> {
    let mut best: Option<(usize, usize, f64)> = None;
    for &s in slots {
        let r = local.cands[s];
        if !active[r] {
            continue;
        }
        let (vals, mask) = local.on_b[s];
        for k in (0..7).filter(|k| mask & (1 << k) != 0) {
            let (c, v) = (7 * b + k, vals[k]);
            let ratio = v.abs() / reach[r][usize::from(c % 7 >= 3)].max(f64::MIN_POSITIVE);
            if v.abs() > tol
                && ratio >= OWN_THRESHOLD
                && best.is_none_or(|x| ratio > x.2 * (1.0 + 1e-9))
            {
                best = Some((s, c, ratio));
            }
        }
    }
    best.map(|(s, c, _)| (s, c))
}

/// The partition's pivot on `(slot, c)`: column `c` eliminated from the other active rows.
fn pivot(
    local: &mut Local,
    slot: usize,
    c: usize,
    active: &mut [bool],
    free: &mut [bool],
    tol: f64,
    b: usize,
) {
    active[local.cands[slot]] = false;
    free[c] = false;
    // Column `c` is no longer free: gone from every row's entries on the body (those of the
    // rows changed below are gathered again).
    let k = c.wrapping_sub(7 * b);
    if k < 7 {
        for e in &mut local.on_b {
            e.1 &= !(1u8 << k);
        }
    }
    let pivot_row = std::mem::take(&mut local.rows[slot]);
    let a_rc = pivot_row.iter().find(|e| e.0 == c).map_or(0.0, |e| e.1);
    for s in 0..local.cands.len() {
        if !active[local.cands[s]] {
            continue;
        }
        let row = &mut local.rows[s];
        let Some(k) = row.iter().position(|e| e.0 == c) else {
            continue;
        };
        let f = row[k].1 / a_rc;
        row.swap_remove(k);
        for &(col, v) in &pivot_row {
            if col == c {
                continue;
            }
            match row.iter_mut().find(|e| e.0 == col) {
                Some(e) => e.1 -= f * v,
                None => row.push((col, -f * v)),
            }
        }
        local.rmax[s] = row_max(row);
        local.on_b[s] = on_body(row, free, b);
        if local.rmax[s] <= tol {
            active[local.cands[s]] = false;
        }
    }
    local.rows[slot] = pivot_row;
}

#[cfg(test)]
#[path = "rank_tests.rs"]
mod tests;
