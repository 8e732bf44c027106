//! The layout of `Φ_u`'s blocks under one partition (module `phi_u`): where each Jacobian
//! triplet `(row, column, value)` goes in the factor buffer, built once per partition.
//!
//! With `p` the row's pivot position and `q` the column's (dependent) position, node `i`
//! covering the positions `a_i .. b_i` (`d_i = b_i − a_i`) and the diagonal blocks laid out one
//! after the other from `diag_at[i]`, a triplet goes to
//!
//! ```text
//! node(p) = node(q) = i:   diag_at[i] + (p − a_i) d_i + (q − a_i)    (diagonal block)
//! node(p) < node(q):       the off-diagonal entries of T, grouped by row node
//! p or q in the border:    the border's entries;   q independent: the Φ_v entries
//! ```
//!
//! and anything else (a row that is no pivot) to a spare slot. The first triplet to reach a
//! slot is flagged [`FIRST`] (it stores, the others add). An open mechanism is taken as a tree
//! at once (each run of pivots on one body a node, no border): one pass over the triplets,
//! which gives way to the general construction (the border test over the triplets, module
//! `merge`) at the first entry in an earlier node's column.

use super::{Shape, TreeSplit, MAX_BORDER};
use crate::constraints::Triplet;
use crate::solver::partition::Partition;
use crate::solver::tree::border::Border;
use crate::solver::tree::segments::Segments;
use crate::solver::tree::shape::FIRST;
use std::sync::Arc;

impl TreeSplit {
    /// The structure of `Φ_u` under `part` for the triplets `entries` of an `m × n` Jacobian;
    /// `None` if it is not block triangular up to a border of at most [`MAX_BORDER`] pivots.
    /// `open`: the mechanism has no closed loop (then its `Φ_u` is tried as a tree first).
    pub(crate) fn new(
        part: &Partition,
        m: usize,
        n: usize,
        entries: &[Triplet],
        open: bool,
    ) -> Option<Self> {
        // Positions and triplet numbers are held as `u32`.
        if u32::try_from(entries.len().max(m).max(n)).is_err() {
            return None;
        }
        // An open mechanism as a tree first: each run of pivots on one body a node, no
        // border, no pass over the triplets for it. Its one pass stops at the first entry in an
        // earlier run's column (a row coupling two branches, as a mimic joint's may).
        if open {
            let (run_of, runs) = crate::solver::tree::merge::runs(part);
            let tree = Self::build(part, m, n, entries, &run_of, runs, None);
            if let Some(Built::Split(split)) = tree {
                return Some(split);
            }
        }
        // Runs with an entry in an earlier run's column go to the border, or are merged into
        // super-nodes where it would be too large (`merge`). Then no entry of a tree node
        // lies before its own node.
        let (run_of, runs, bordered) =
            crate::solver::tree::merge::phi_u_runs(part, m, n, entries, MAX_BORDER)?;
        match Self::build(part, m, n, entries, &run_of, runs, Some(&bordered))? {
            Built::Split(split) => Some(split),
            Built::Below => None,
        }
    }

    /// The split with the runs `run_of` (`runs` of them) as nodes but the `bordered` ones
    /// (none if `None`); [`Built::Below`] at the first entry of a tree node in an earlier
    /// node's column, `None` if the border or the buffers are too large.
    fn build(
        part: &Partition,
        m: usize,
        n: usize,
        entries: &[Triplet],
        run_of: &[u32],
        runs: usize,
        bordered: Option<&[bool]>,
    ) -> Option<Built> {
        let order = part.rows.len();
        let bordered = |k: usize| bordered.is_some_and(|b| b[run_of[k] as usize]);
        let border_positions: Vec<usize> = (0..order).filter(|&k| bordered(k)).collect();
        if border_positions.len() > MAX_BORDER {
            return None;
        }
        // Tree nodes: the runs not in the border (a run's positions are consecutive).
        let mut node_of = vec![u32::MAX; order];
        let mut span: Vec<(usize, usize)> = Vec::with_capacity(runs);
        let mut last_run = u32::MAX;
        for k in 0..order {
            if bordered(k) {
                continue;
            }
            if run_of[k] != last_run {
                span.push((k, k));
                last_run = run_of[k];
            }
            if let Some(s) = span.last_mut() {
                s.1 = k + 1;
            }
            node_of[k] = (span.len() - 1) as u32;
        }
        let nodes = span.len();
        let mut diag_at = Vec::with_capacity(nodes + 1);
        diag_at.push(0usize);
        for i in 0..nodes {
            let d = span[i].1 - span[i].0;
            diag_at.push(diag_at[i] + d * d);
        }
        // Every slot lies below the spare one, which must stay below [`FIRST`].
        let diag_len = diag_at[nodes];
        if diag_len >= FIRST as usize {
            return None;
        }
        // Each row's and column's place, looked up once per triplet.
        let (rows, cols) = places(part, m, n, &node_of, &span, &diag_at);
        // One pass in the triplets' order: a diagonal block's slot at once (flagged [`FIRST`]
        // if no triplet before reached it); the others listed, placed once all are counted
        // (each such triplet has a slot of its own but the spare one). The off-diagonal
        // entries of T are grouped by row node (counting sort).
        let mut count = vec![0usize; nodes + 1];
        let mut border = Border::new(&border_positions, order);
        let mut reached = vec![false; diag_len];
        let mut slots = vec![u32::MAX; entries.len()];
        // Sized for every triplet (untouched capacity costs no page): no regrowth copies.
        let mut v_at = Vec::with_capacity(entries.len());
        let mut pending = Vec::with_capacity(entries.len());
        let mut pending_v = Vec::with_capacity(entries.len());
        let (mut border_at, mut spare_at) = (Vec::new(), Vec::new());
        for (t, (e, slot)) in entries.iter().zip(&mut slots).enumerate() {
            let t = t as u32;
            let (row, col) = (rows[e.0 as usize], cols[e.1 as usize]);
            if row.node.max(col.node) < FREE {
                // Both in tree nodes.
                if row.node == col.node {
                    let at = (row.at + col.at) as usize;
                    *slot = at as u32;
                    if !reached[at] {
                        reached[at] = true;
                        *slot |= FIRST;
                    }
                } else if col.node < row.node {
                    return Some(Built::Below);
                } else {
                    count[row.node as usize + 1] += 1;
                    pending.push((t, row.node, row.pos, col.pos));
                }
            } else if row.node == OUT || col.node == OUT {
                spare_at.push(t);
            } else if col.node == FREE {
                pending_v.push(t);
                v_at.push((row.pos, col.pos));
            } else {
                border_at.push((t, border.add(row.pos as usize, col.pos as usize) as u32));
            }
        }
        for i in 0..nodes {
            count[i + 1] += count[i];
        }
        let off_at = count.clone();
        let mut off = vec![(0u32, 0u32); pending.len()];
        for &(t, i, p, q) in &pending {
            let at = count[i as usize];
            count[i as usize] += 1;
            off[at] = (p, q);
            slots[t as usize] = (diag_len + at) as u32 | FIRST;
        }
        let off0 = diag_len;
        let border0 = off0 + off.len();
        let v0 = border0 + border.len();
        let len = v0 + v_at.len() + 1;
        let spare = u32::try_from(len - 1).ok().filter(|&s| s < FIRST)?;
        for &(t, k) in &border_at {
            slots[t as usize] = (border0 + k as usize) as u32 | FIRST;
        }
        for (k, &t) in pending_v.iter().enumerate() {
            slots[t as usize] = (v0 + k) as u32 | FIRST;
        }
        // The first triplet to reach the spare slot stores its value, the others add theirs.
        for (k, &t) in spare_at.iter().enumerate() {
            slots[t as usize] = if k == 0 { spare | FIRST } else { spare };
        }
        // The slots no triplet reaches (zeros of the diagonal blocks, factored in place; the
        // border's Schur complement) are zeroed by each factorization: no pass over the whole
        // buffer.
        let mut bare = Vec::with_capacity(diag_len);
        for (k, &r) in reached.iter().enumerate() {
            if !r {
                bare.push(k as u32);
            }
        }
        bare.extend((border0 + border_at.len()) as u32..v0 as u32);
        if spare_at.is_empty() {
            bare.push(spare);
        }
        Some(Built::Split(TreeSplit {
            id: part.id,
            triplets: entries.len(),
            shape: Arc::new(Shape {
                order,
                span,
                diag_at,
                segments: Segments::new(&off, &off_at),
                off,
                off_at,
                border,
                v_at,
                off0,
                border0,
                v0,
                len,
            }),
            slots,
            bare,
            pool: Vec::new(),
        }))
    }

    /// Every field of the layout (the segments follow from the off-diagonal entries).
    #[cfg(test)]
    #[allow(clippy::type_complexity)]
    pub(crate) fn layout(
        &self,
    ) -> (
        (&[u32], &[u32], usize, &[(usize, usize)], &[usize]),
        (&[(u32, u32)], &[usize], &Border, &[(u32, u32)]),
        [usize; 4],
    ) {
        let s = &*self.shape;
        (
            (&self.slots, &self.bare, s.order, &s.span, &s.diag_at),
            (&s.off, &s.off_at, &s.border, &s.v_at),
            [s.off0, s.border0, s.v0, s.len],
        )
    }
}

/// What [`TreeSplit::build`] found.
enum Built {
    Split(TreeSplit),
    /// An entry of a tree node lies in an earlier node's column.
    Below,
}

/// Where a row or a column of the Jacobian sits in the blocks of `Φ_u` and `Φ_v`.
#[derive(Clone, Copy)]
struct Place {
    /// Its tree node, or [`OUT`], [`BORDERED`], [`FREE`].
    node: u32,
    /// Its pivot position (a pivot row, a dependent column) or independent position.
    pos: u32,
    /// A tree row: the offset of its row in the diagonal values; a tree column: its offset
    /// in its node. Their sum is the slot of the entry in the diagonal block.
    at: u32,
}

/// Neither a pivot row nor a coordinate of either kind (its triplets go to the spare slot).
const OUT: u32 = u32::MAX;
/// A pivot row or dependent column in the border.
const BORDERED: u32 = u32::MAX - 1;
/// An independent column (`Φ_v`).
const FREE: u32 = u32::MAX - 2;

/// The places of the `m` rows and `n` columns under `part`, with the tree nodes' positions
/// `span` and diagonal offsets `diag_at` (`node_of`: each pivot position's node, `u32::MAX`
/// in the border).
fn places(
    part: &Partition,
    m: usize,
    n: usize,
    node_of: &[u32],
    span: &[(usize, usize)],
    diag_at: &[usize],
) -> (Vec<Place>, Vec<Place>) {
    let out = Place {
        node: OUT,
        pos: 0,
        at: 0,
    };
    let (mut rows, mut cols) = (vec![out; m], vec![out; n]);
    for (k, &c) in part.independent.iter().enumerate() {
        cols[c] = Place {
            node: FREE,
            pos: k as u32,
            at: 0,
        };
    }
    for (k, &i) in node_of.iter().enumerate() {
        let (row, col) = if i == u32::MAX {
            let b = Place {
                node: BORDERED,
                pos: k as u32,
                at: 0,
            };
            (b, b)
        } else {
            let (a, b) = span[i as usize];
            let row_at = diag_at[i as usize] + (k - a) * (b - a);
            let place = |at: usize| Place {
                node: i,
                pos: k as u32,
                at: at as u32,
            };
            (place(row_at), place(k - a))
        };
        rows[part.rows[k]] = row;
        cols[part.dependent[k]] = col;
    }
    (rows, cols)
}
