//! The fill-free elimination (module `fill_free`) on a mechanism whose every row is resolved at
//! the first body it touches: each body's dense copies read straight from the triplets.
//!
//! The elimination visits the bodies in its order; the rows touching body `b` at its step are
//! the active rows whose first body (in that order, among the bodies of their nonzero entries)
//! is `b`, its **own** rows, and the rows an earlier step changed and left active. Where no step
//! leaves a row active (on a tree: a body's joint rows and normalization all pivoted at the
//! body), the second kind never occurs and each step reads its own rows alone, as first
//! expanded:
//!
//! ```text
//! a_rc = v · row_scale[r] · scale[c]   (zeros left out),   rows(b) = { r active : first(r) = b }
//! ```
//!
//! So this route needs no row lists, no rows by body and no kept copies: one pass over the
//! triplets gives each row's nonzero entries (sums of terms as module `rows` forms them), largest
//! entry, first body and (for a row on one
//! body alone) its reach there; the steps load their copies from those entries and make the
//! same pivot choices and updates, both passes, in the same order, as module `fill_free` (the
//! same methods of module `block`). It gives way (`None`, the general route follows) before any
//! work where the triplets are not grouped by ascending row, and at the first step that leaves
//! a row active (a row the general route carries on or keeps). Where it answers, the general route gives the same pivots
//! (`tree_tests`).

use super::{Pivots, MAX_BODIES};
use crate::constraints::Triplet;
use crate::solver::partition::RANK_TOLERANCE;
use crate::solver::sparse::block::Block;

/// A row on several bodies (`own_of`).
const MULTI: usize = usize::MAX - 1;

/// The pivots of the elimination in the body order `order` of the `m × n` triplets `entries`
/// with row and column scales, or `None` where this route gives way.
pub(super) fn eliminate(
    order: &[usize],
    m: usize,
    n: usize,
    entries: &[Triplet],
    row_scale: &[f64],
    scale: &[f64],
) -> Option<Pivots> {
    let nb = n / 7;
    // Finite scales: a zero triplet scales to zero (skipped before its products).
    let finite = |s: &[f64]| s.iter().all(|x| x.is_finite());
    if order.len() != nb || !finite(row_scale) || !finite(scale) {
        return None;
    }
    // Each body's place in the order.
    let mut place = vec![0u32; nb];
    for (k, &b) in order.iter().enumerate() {
        place[b] = k as u32;
    }
    // One pass: each row's nonzero entries `(c, a_rc)` (row `r`'s at `at[r] .. at[r + 1]`;
    // duplicates summed in triplet order and zero sums dropped, as module `rows` does), largest
    // entry and first body (`u32::MAX`: none); the body of each row on one body alone
    // (`usize::MAX`: none, `MULTI`: several) and its reach there, for the second pass.
    let mut expanded: Vec<(u32, f64)> = Vec::with_capacity(entries.len());
    let mut at = Vec::with_capacity(m + 1);
    at.push(0u32);
    let mut rmax = vec![0.0f64; m];
    let mut first = vec![u32::MAX; m];
    let mut own_of = vec![usize::MAX; m];
    let mut reach = vec![[0.0f64; 2]; m];
    // Where column `c` sits in the row being read: `(row, index in expanded)`.
    let mut seen = vec![(u32::MAX, 0u32); n];
    let mut rest = entries;
    for r in 0..m {
        let len = rest.iter().take_while(|e| e.0 as usize == r).count();
        let (row, tail) = rest.split_at(len);
        rest = tail;
        let start = expanded.len();
        let mut summed = false;
        for e in row {
            let c = e.1 as usize;
            if c >= n {
                return None;
            }
            // A zero triplet scales to zero: left out unscaled.
            if e.2 == 0.0 {
                continue;
            }
            let a = e.2 * row_scale[r] * scale[c];
            if a == 0.0 {
                continue;
            }
            let s = &mut seen[c];
            if s.0 == r as u32 {
                expanded[s.1 as usize].1 += a;
                summed = true;
                continue;
            }
            *s = (r as u32, expanded.len() as u32);
            expanded.push((e.1, a));
        }
        if summed {
            let mut kept = start;
            for k in start..expanded.len() {
                if expanded[k].1 != 0.0 {
                    expanded[kept] = expanded[k];
                    kept += 1;
                }
            }
            expanded.truncate(kept);
        }
        for &(c, a) in &expanded[start..] {
            let (c, a) = (c as usize, a.abs());
            // `max_c |a_rc|` as `fold(0, f64::max)` gives it (NaN ignored).
            if a > rmax[r] {
                rmax[r] = a;
            }
            let body = c / 7;
            first[r] = first[r].min(place[body]);
            if own_of[r] == usize::MAX {
                own_of[r] = body;
            } else if own_of[r] != body {
                own_of[r] = MULTI;
            }
            let kind = usize::from(c % 7 >= 3);
            reach[r][kind] = reach[r][kind].max(a);
        }
        at.push(expanded.len() as u32);
    }
    // Triplets left over: a row out of order or beyond `m`.
    if !rest.is_empty() {
        return None;
    }
    let amax = rmax.iter().fold(0.0f64, |a, &x| a.max(x));
    let tol = (RANK_TOLERANCE * amax).max(f64::MIN_POSITIVE);
    let mut active: Vec<bool> = rmax.iter().map(|&x| x > tol).collect();
    // The active rows by their first body's place (ascending rows in each).
    let mut own_at = vec![0usize; nb + 1];
    for r in 0..m {
        if active[r] {
            own_at[first[r] as usize + 1] += 1;
        }
    }
    for k in 0..nb {
        own_at[k + 1] += own_at[k];
    }
    let mut fill = own_at.clone();
    let mut own = vec![0usize; own_at[nb]];
    for r in 0..m {
        if active[r] {
            let k = first[r] as usize;
            own[fill[k]] = r;
            fill[k] += 1;
        }
    }
    let mut pivots = Pivots {
        order: Vec::with_capacity(n),
        second: Vec::new(),
    };
    let mut block = Block::default();
    for (k, &b) in order.iter().enumerate() {
        let rows = &own[own_at[k]..own_at[k + 1]];
        block.load_expanded(b, rows, &rmax, &at, &expanded);
        if block.bodies() > MAX_BODIES {
            return None;
        }
        let mut free = [true; 7];
        let mut taken = 0;
        while taken < 7 {
            let Some((i, c)) = block.best_pivot(&free, tol) else {
                break;
            };
            pivots.order.push((block.rows[i], 7 * b + c));
            free[c] = false;
            block.pivot(i, c, &mut active, tol);
            taken += 1;
        }
        while taken < 7 {
            let Some((i, c)) = block.best_own_pivot(&free, tol, b, &own_of, &reach) else {
                break;
            };
            pivots.order.push((block.rows[i], 7 * b + c));
            pivots.second.push((block.rows[i], b, true));
            free[c] = false;
            block.pivot(i, c, &mut active, tol);
            taken += 1;
        }
        if block.any_live() {
            return None;
        }
    }
    Some(pivots)
}
