//! `Φ_u` of a tree as a block-triangular matrix, factored block by block.
//!
//! The partition pivots row `rows[k]` at column `dependent[k]`; a **node** is a maximal run of
//! consecutive pivots on one body's columns. With `Φ_u` indexed by pivot position on both
//! sides, node `i` holds the square diagonal block `A_ii` (its rows × its columns). On a tree
//! each node's rows reach only its own body and its parent (a joint, a stop) or nothing else (a
//! normalization, a contact): bodies are eliminated leaves first, so every entry lies in a node
//! at or after the row's own, and `Φ_u` is block upper triangular:
//!
//! ```text
//! Φ_u x = r:   x_i = A_ii⁻¹ (r_i − Σ_{j>i} A_ij x_j)        (last node first)
//! Φ_uᵀ μ = g:  μ_i = A_ii⁻ᵀ (g_i − Σ_{j<i} A_jiᵀ μ_j)       (first node first)
//! ```
//!
//! with one LU with partial pivoting per diagonal block (`≤ 7 × 7`) and no fill. Nodes with an
//! entry before their own (the rows closing a loop, pivoted last) form a **border** `B`; with
//! `T` the rest, `Φ_u = [T C; R D]` is solved through the dense Schur complement
//! `S = D − R T⁻¹ C` (module `border`). Where each Jacobian triplet goes in the factor buffer
//! is laid out once per partition (module `split`).

use super::border::Border;
use super::dense;
use super::segments::Segments;
use super::shape::FIRST;
use crate::constraints::Triplet;
use crate::solver::partition::Partition;
use std::sync::Arc;

mod split;

/// Borders larger than this (pivot positions) are merged into super-nodes instead (module
/// `merge`; the general sparse LU where those would be too large).
pub(crate) const MAX_BORDER: usize = 64;

/// The block structure of `Φ_u` under one partition (built once per partition).
pub(crate) struct Shape {
    /// Number of pivots (the order of `Φ_u`).
    order: usize,
    /// Node `i` covers the pivot positions `span[i].0 .. span[i].1` (tree nodes only).
    span: Vec<(usize, usize)>,
    /// Offset of node `i`'s diagonal block in the flat diagonal values.
    diag_at: Vec<usize>,
    /// Off-diagonal entries of `T` `(row position, column position)`, grouped by row node:
    /// node `i`'s are `off[off_at[i] .. off_at[i + 1]]`.
    off: Vec<(u32, u32)>,
    off_at: Vec<usize>,
    /// The same entries as dense segments (the solves' updates, module `segments`).
    segments: Segments,
    border: Border,
    /// `(row position, independent position)` of the `Φ_v` entries.
    v_at: Vec<(u32, u32)>,
    /// The factor buffers' layout: the diagonal blocks, the off-diagonal entries, the border,
    /// the `Φ_v` entries, then one slot that takes the triplets no block holds.
    off0: usize,
    border0: usize,
    v0: usize,
    len: usize,
}

/// The split of the Jacobian's triplets under one partition into the blocks of `Φ_u` and the
/// entries of `Φ_v`, and a pool of factor buffers (reused once no evaluation holds them).
pub(crate) struct TreeSplit {
    id: usize,
    triplets: usize,
    shape: Arc<Shape>,
    /// Where each Jacobian triplet goes in the factor buffer (the last slot: nowhere), with
    /// [`FIRST`] set on the first triplet to reach its slot.
    slots: Vec<u32>,
    /// The slots that no triplet reaches.
    bare: Vec<u32>,
    pool: Vec<Arc<TreeLu>>,
}

/// The factors of `Φ_u` and the values of `Φ_v` at one configuration.
pub(crate) struct TreeLu {
    shape: Arc<Shape>,
    /// The diagonal blocks (factored in place), the off-diagonal entries, the border, the
    /// `Φ_v` entries and the spare slot, laid out as [`Shape`] says.
    vals: Vec<f64>,
    piv: Vec<u16>,
    border_piv: Vec<u16>,
    ok: bool,
    /// Whether [`TreeLu::pivot_ratio`] reports (module `system::backend`).
    watch: bool,
}

impl TreeSplit {
    /// Whether this split was built for `part` and a Jacobian of `triplets` entries.
    pub(crate) fn fits(&self, part: &Partition, triplets: usize) -> bool {
        self.triplets == triplets && self.id == part.id
    }

    /// Refills the blocks from `entries` and factors them, in a buffer of the pool that no
    /// evaluation holds any more (a new one if all are held); with `watch`, the factors report
    /// their pivot ratio.
    pub(crate) fn factor(&mut self, entries: &[Triplet], watch: bool) -> Arc<TreeLu> {
        let shape = &self.shape;
        let free = self.pool.iter().position(|f| Arc::strong_count(f) == 1);
        let mut lu = match free {
            Some(k) => self.pool.swap_remove(k),
            None => Arc::new(TreeLu {
                shape: shape.clone(),
                vals: vec![0.0; shape.len],
                piv: vec![0; shape.order],
                border_piv: vec![0; shape.border.size()],
                ok: false,
                watch,
            }),
        };
        if let Some(f) = Arc::get_mut(&mut lu) {
            // One pass: every triplet reaches its slot in the triplets' order, the first
            // storing `0 + v` and the others adding (the sums of zeroing first and adding, so
            // those of a block-by-block scatter); the slots no triplet reaches are zeroed.
            let vals = &mut f.vals[..];
            for &at in &self.bare {
                vals[at as usize] = 0.0;
            }
            for (&slot, e) in self.slots.iter().zip(entries) {
                let at = &mut vals[(slot & !FIRST) as usize];
                if slot & FIRST != 0 {
                    *at = 0.0 + e.2;
                } else {
                    *at += e.2;
                }
            }
            f.ok = f.factor_blocks();
            f.watch = watch;
        }
        self.pool.push(lu.clone());
        // Keep at most a few buffers (the current point, trial points of a line search).
        if self.pool.len() > 4 {
            if let Some(k) = self.pool.iter().position(|f| Arc::strong_count(f) == 1) {
                self.pool.swap_remove(k);
            }
        }
        lu
    }
}

impl TreeLu {
    /// Factors the diagonal blocks, then the border's Schur complement.
    fn factor_blocks(&mut self) -> bool {
        let shape = self.shape.clone();
        for i in 0..shape.span.len() {
            let (a, b) = shape.span[i];
            let d = b - a;
            let blk = &mut self.vals[shape.diag_at[i]..shape.diag_at[i + 1]];
            if !dense::lu(blk, d, &mut self.piv[a..b]) {
                return false;
            }
        }
        if shape.border.is_empty() {
            return true;
        }
        let range = shape.border0..shape.v0;
        let mut border = self.vals[range.clone()].to_vec();
        let mut piv = std::mem::take(&mut self.border_piv);
        let ok = shape
            .border
            .factor(
                &mut border,
                &mut piv,
                |x, _, hi, need| self.tree_solve_to(x, hi, need),
                false,
            )
            .is_some();
        self.vals[range].copy_from_slice(&border);
        self.border_piv = piv;
        ok
    }

    /// `T x = r` (or `Tᵀ x = r`) in place over the tree positions (border positions untouched).
    fn tree_solve(&self, x: &mut [f64], transpose: bool) {
        let s = &*self.shape;
        let nodes = s.span.len();
        if !transpose {
            self.solve_nodes(x, 0, nodes);
            return;
        }
        let (diag, rest) = self.vals.split_at(s.off0);
        let off = &rest[..s.border0 - s.off0];
        for i in 0..nodes {
            let (a, b) = s.span[i];
            let blk = &diag[s.diag_at[i]..s.diag_at[i + 1]];
            dense::lu_solve_transpose(blk, &self.piv[a..b], b - a, &mut x[a..b]);
            s.segments.transposed(i, off, x);
        }
    }

    /// `T x = r` for an `r` that is zero after the position `hi`: the nodes after the one
    /// holding `hi` have a zero right side and only later nodes' entries (last node first),
    /// so their part of `x` is zero and the solve starts at that node. Only the positions
    /// from `need` on are solved for (a node's part needs only later nodes'): the solve ends
    /// at the node holding `need`.
    fn tree_solve_to(&self, x: &mut [f64], hi: usize, need: usize) {
        let s = &*self.shape;
        let first = s.span.partition_point(|&(_, b)| b <= need);
        self.solve_nodes(x, first, s.span.partition_point(|&(a, _)| a <= hi));
    }

    /// `T x = r` over the nodes `first .. nodes`, last first.
    fn solve_nodes(&self, x: &mut [f64], first: usize, nodes: usize) {
        let s = &*self.shape;
        let (diag, rest) = self.vals.split_at(s.off0);
        let off = &rest[..s.border0 - s.off0];
        for i in (first..nodes).rev() {
            s.segments.forward(i, off, x);
            let (a, b) = s.span[i];
            let blk = &diag[s.diag_at[i]..s.diag_at[i + 1]];
            dense::lu_solve(blk, &self.piv[a..b], b - a, &mut x[a..b], 1);
        }
    }

    fn solve_with(&self, x: &mut [f64], transpose: bool) -> bool {
        if x.is_empty() {
            return true;
        }
        if !self.ok {
            return false;
        }
        let s = &*self.shape;
        if s.border.is_empty() {
            self.tree_solve(x, transpose);
        } else {
            s.border.solve(
                &self.vals[s.border0..s.v0],
                &self.border_piv,
                x,
                transpose,
                |y, t| self.tree_solve(y, t),
            );
        }
        x.iter().all(|v| v.is_finite())
    }

    /// The smallest pivot of the diagonal blocks' `U` (and of the border's `S`) over the
    /// largest: how well the dependent coordinates are determined by the independent rows (an
    /// Euler parameter taken as independent near its turning point folds the chart and makes
    /// its body's block nearly singular); `None` if the factors failed or do not watch.
    pub(crate) fn pivot_ratio(&self) -> Option<f64> {
        if !self.ok || !self.watch {
            return None;
        }
        let s = &*self.shape;
        let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
        for i in 0..s.span.len() {
            let d = s.span[i].1 - s.span[i].0;
            let blk = &self.vals[s.diag_at[i]..s.diag_at[i + 1]];
            for k in 0..d {
                let v = blk[k * d + k].abs();
                (lo, hi) = (lo.min(v), hi.max(v));
            }
        }
        if !s.border.is_empty() {
            let (a, b) = s.border.pivot_range(&self.vals[s.border0..s.v0]);
            (lo, hi) = (lo.min(a), hi.max(b));
        }
        Some(if hi > 0.0 { lo / hi } else { 1.0 })
    }

    /// Pivots in the border (0 on a tree).
    #[cfg(test)]
    pub(crate) fn border_size(&self) -> usize {
        self.shape.border.size()
    }

    /// `Φ_u x = b` in place; `false` if `Φ_u` is singular.
    pub(crate) fn solve(&self, b: &mut [f64]) -> bool {
        self.solve_with(b, false)
    }

    /// `Φ_uᵀ x = b` in place; `false` if `Φ_u` is singular.
    pub(crate) fn solve_transpose(&self, b: &mut [f64]) -> bool {
        self.solve_with(b, true)
    }

    /// `Φ_v x` (length: independent rows).
    pub(crate) fn phi_v_mul(&self, x: &[f64], r: usize) -> Vec<f64> {
        let s = &*self.shape;
        let mut y = vec![0.0; r];
        for (&(i, j), v) in s.v_at.iter().zip(&self.vals[s.v0..]) {
            y[i as usize] += v * x[j as usize];
        }
        y
    }

    /// `Φ_vᵀ y` (length: degrees of freedom).
    pub(crate) fn phi_v_tr_mul(&self, y: &[f64], dof: usize) -> Vec<f64> {
        let s = &*self.shape;
        let mut x = vec![0.0; dof];
        for (&(i, j), v) in s.v_at.iter().zip(&self.vals[s.v0..]) {
            x[j as usize] += v * y[i as usize];
        }
        x
    }

    /// `B += Φ_v diag(scale)` into the row-major `order × w` zeros `b`: column `j` is
    /// [`TreeLu::phi_v_mul`] of `scale[j] e_j` to the bit (the others' terms add zeros).
    pub(crate) fn add_phi_v_scaled(&self, scale: &[f64], b: &mut [f64], w: usize) {
        let s = &*self.shape;
        for (&(i, j), v) in s.v_at.iter().zip(&self.vals[s.v0..]) {
            b[i as usize * w + j as usize] += v * scale[j as usize];
        }
    }

    /// `Φ_u X = B` in place for the `w` columns of the row-major `order × w` `x` in one pass,
    /// each column [`TreeLu::solve`]'s operations in its order; `false` on a singular `Φ_u`,
    /// a border or a non-finite entry (then solve column by column).
    pub(crate) fn solve_columns(&self, x: &mut [f64], w: usize) -> bool {
        let s = &*self.shape;
        if !self.ok || !s.border.is_empty() || x.len() != s.order * w {
            return x.is_empty();
        }
        let (diag, off) = self.vals[..s.border0].split_at(s.off0);
        for i in (0..s.span.len()).rev() {
            let r = s.off_at[i]..s.off_at[i + 1];
            for (&(p, q), &v) in s.off[r.clone()].iter().zip(&off[r]) {
                let (p, q) = (p as usize * w, q as usize * w);
                (0..w).for_each(|c| x[p + c] -= v * x[q + c]);
            }
            let (a, b) = s.span[i];
            let blk = &diag[s.diag_at[i]..s.diag_at[i + 1]];
            dense::lu_solve(blk, &self.piv[a..b], b - a, &mut x[a * w..b * w], w);
        }
        x.iter().all(|v| v.is_finite())
    }
}
