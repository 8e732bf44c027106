//! The KKT matrix `[W Φ_qᵀ; Φ_q 0]` of a Newton step factored along the kinematic tree.
//!
//! In the elimination order of module `shape` the matrix is block tree-structured: a diagonal
//! block `K_i` per node (`d ≤ 14`: 7 coordinates and the rows pivoted at the body) and a
//! coupling `C_i` (`d × w`) to the leading unknowns of its parent `p`. Eliminating the leaves
//! first,
//!
//! ```text
//! K_i = L_i D_i L_iᵀ,   X_i = K_i⁻¹ C_i,   K_p ← K_p − C_iᵀ X_i
//! ```
//!
//! fills nothing, in `O(N)` with fixed-size work per body. The pivots are those of the sparse
//! path's simplicial LDLᵀ in the same order (same inertia: its negative pivots minus the rows
//! count the reduced Hessian's negative eigenvalues); where a pivot is zero, or a solve is not
//! accurate, each block is factored by LU with partial pivoting instead. A solve runs
//! `y_i = K_i⁻¹ r_i`, `r_p −= C_iᵀ y_i` from the leaves and `x_i = y_i − X_i x_p` back from
//! the root, then the border (module `border`), then iterative refinement like the sparse
//! path's. Values, factors and scratch are allocated once per structure (the factors at its
//! first factorization).
//!
//! Assembly writes every slot once per Newton step without clearing the values first: a `W`
//! entry stores its (scaled) Hessian block entry, a Jacobian entry stores its first triplet
//! `0 + d_r J_rc s_c` and adds the others in triplet order (the first of each slot flagged
//! once per structure, module `shape`), and only the diagonal slots that no Hessian block
//! writes are zeroed: the same sums, in the same order, as zeroing and adding.

use super::dense;
use super::fused::BlockMap;
use super::jac_runs::EACH;
use super::norm;
use super::shape::{Shape, FIRST, SKIP};
use crate::constraints::Triplet;
use crate::solver::partition::Partition;
use crate::solver::sparse::hessian::BlockHessian;
use crate::solver::sparse::kkt::Factored;
use crate::solver::sparse::shifts::Shifts;
use std::cell::RefCell;

/// The tree KKT matrix under one partition: its structure, values and factors.
pub(crate) struct TreeKkt {
    pub(super) shape: Shape,
    /// The Hessian blocks by body pair (module `fused`; built at the first fused assembly).
    pub(super) map: Option<BlockMap>,
    /// The fused assembly's `7 × 7` blocks of `W` (unscaled; the kept blocks of `map`), in
    /// the block Hessian's buffer during an assembly (empty between them).
    pub(super) w_blocks: Vec<[f64; 49]>,
    id: usize,
    triplets: usize,
    blocks: usize,
    /// Assembled values (shifted): the flat blocks, then the border entries.
    pub(super) values: Vec<f64>,
    /// The shifts `δ` and `−σ` now in `values`.
    pub(super) shifts: Shifts,
    /// Factors: the flat blocks (`L D` or `L U` in place; `X_i` in the coupling slots; empty
    /// until the first factorization, so that memory freed between the assembly and it, such
    /// as the verdict's block Hessian, is reused), the border's values and `S`, the pivots of
    /// LU.
    factors: Vec<f64>,
    border: Vec<f64>,
    piv: Vec<u16>,
    border_piv: Vec<u16>,
    kind: Factored,
    lu_only: bool,
    /// Blocks not yet copied from the values in this factorization (scratch).
    fresh: Vec<bool>,
    /// Row sums of `|K|` in tree-space order (scratch).
    row_sums: Vec<f64>,
    knorm: f64,
    scratch: RefCell<Scratch>,
}

/// Buffers of the solves.
#[derive(Default)]
struct Scratch {
    x: Vec<f64>,
    b: Vec<f64>,
    r: Vec<f64>,
}

impl TreeKkt {
    /// The structure for `part` (see [`Shape::new`]); `None` where it does not fit a tree with
    /// a small border.
    pub(crate) fn new(
        part: &Partition,
        m: usize,
        n: usize,
        entries: &[Triplet],
        hess: &BlockHessian,
    ) -> Option<Self> {
        let shape = Shape::new(part, m, n, entries, hess)?;
        let total = shape.flat_len + shape.border.len();
        let dim = shape.n + shape.rows;
        Some(TreeKkt {
            map: None,
            w_blocks: Vec::new(),
            id: part.id,
            triplets: entries.len(),
            blocks: hess.keys.len(),
            values: vec![0.0; total],
            shifts: Shifts::default(),
            factors: Vec::new(),
            border: vec![0.0; shape.border.len()],
            piv: vec![0; shape.tree_len],
            border_piv: vec![0; shape.border.size()],
            kind: Factored::None,
            lu_only: false,
            fresh: vec![true; shape.at.len()],
            row_sums: vec![0.0; dim],
            knorm: 0.0,
            scratch: RefCell::new(Scratch {
                x: Vec::with_capacity(dim),
                b: Vec::with_capacity(dim),
                r: Vec::with_capacity(dim),
            }),
            shape,
        })
    }

    /// Whether this structure fits `part`, a Jacobian of `triplets` entries and `blocks` blocks.
    pub(crate) fn fits(&self, part: &Partition, triplets: usize, blocks: usize) -> bool {
        self.triplets == triplets && self.blocks == blocks && self.id == part.id
    }

    /// Fills the values (scaled) from the Jacobian triplets and the Hessian blocks.
    pub(crate) fn assemble(
        &mut self,
        entries: &[Triplet],
        row_scale: &[f64],
        scale: &[f64],
        hess: &BlockHessian,
    ) {
        // Every slot holds one pair of unknowns (module `shape`): a `W` entry takes the value of
        // one Hessian block entry, stored; a Jacobian entry the sum of its triplets, the first
        // stored (as `0 + v`: the same value as zeroing and adding, signed zeros included) and
        // the others added, in triplet order. The slots of neither (the zero blocks of the
        // rows) stay zero from allocation, and the diagonal of a coordinate without a block is
        // zeroed (a shift left there).
        self.shifts.clear();
        let s = &self.shape;
        let values = &mut self.values;
        for &slot in &s.bare_diag {
            values[slot as usize] = 0.0;
        }
        let blocks = hess.keys.iter().zip(&hess.values).zip(&s.block_runs);
        for ((&(a, b), blk), &run) in blocks {
            let (sa, sb) = (&scale[7 * a..7 * a + 7], &scale[7 * b..7 * b + 7]);
            super::fused::store_block(values, run, &s.scattered_slots, blk, sa, sb);
        }
        self.store_jacobian(entries, row_scale, scale);
    }

    /// Stores the Jacobian's entries (scaled) at their slots (see [`TreeKkt::assemble`]), run
    /// by run ([`JacRun`](super::jac_runs::JacRun)): a run of first triplets at consecutive
    /// slots (and its mirror's, `step` apart), the others each at its own.
    pub(super) fn store_jacobian(&mut self, entries: &[Triplet], row_scale: &[f64], scale: &[f64]) {
        let values = &mut self.values[..];
        let mut each = self.shape.jac_each.iter();
        let mut from = 0;
        for run in &self.shape.jac_runs {
            let es = &entries[from..from + run.len as usize];
            from += run.len as usize;
            if run.step == EACH {
                for (e, slots) in es.iter().zip(each.by_ref()) {
                    let v = e.2 * row_scale[e.0 as usize] * scale[e.1 as usize];
                    for &slot in slots {
                        if slot != SKIP {
                            let at = &mut values[(slot & !FIRST) as usize];
                            if slot & FIRST != 0 {
                                *at = 0.0 + v;
                            } else {
                                *at += v;
                            }
                        }
                    }
                }
            } else if run.slot != SKIP {
                // One row: its scale read once (the same product, `(v r) s`, as above).
                let rs = row_scale[es[0].0 as usize];
                let (slot, mirror, step) = (run.slot as usize, run.mirror, run.step as usize);
                if mirror == SKIP {
                    let dst = &mut values[slot..slot + es.len()];
                    for (at, e) in dst.iter_mut().zip(es) {
                        *at = 0.0 + e.2 * rs * scale[e.1 as usize];
                    }
                } else {
                    for (j, e) in es.iter().enumerate() {
                        let v = 0.0 + e.2 * rs * scale[e.1 as usize];
                        values[slot + j] = v;
                        values[mirror as usize + j * step] = v;
                    }
                }
            }
        }
    }

    /// The largest diagonal entry of the (scaled) `W` block.
    pub(crate) fn max_diagonal(&self) -> f64 {
        self.shifts
            .max_diagonal(&self.shape.diag_slots, &self.values)
    }

    /// Subtracts `σ` from the diagonal of the independent coordinates `columns` in place of
    /// the last such shift (see `sparse::kkt::Kkt::shift_independent`).
    pub(crate) fn shift_independent(&mut self, columns: &[usize], sigma: f64) {
        self.shifts
            .shift_independent(&self.shape.diag_slots, &mut self.values, columns, sigma);
    }

    /// Factors the matrix with `δ` added to the diagonal of the `W` block: block LDLᵀ (with the
    /// number of negative pivots), or block LU with partial pivoting where LDLᵀ meets a zero
    /// pivot or after [`TreeKkt::fall_back_to_lu`].
    pub(crate) fn factor(&mut self, delta: f64) -> Factored {
        self.shifts
            .shift_all(&self.shape.diag_slots, &mut self.values, delta);
        self.kind = Factored::None;
        if !self.lu_only {
            if let Some(negative) = self.factor_blocks(false) {
                self.kind = Factored::Ldlt { negative };
                return self.kind;
            }
        }
        if self.factor_blocks(true).is_some() {
            self.kind = Factored::Lu;
        }
        self.kind
    }

    /// Block LU for this and all later factorizations of this structure.
    pub(crate) fn fall_back_to_lu(&mut self) -> Factored {
        self.lu_only = true;
        self.kind = Factored::None;
        if self.factor_blocks(true).is_some() {
            self.kind = Factored::Lu;
        }
        self.kind
    }

    /// Factors every block (LU if `lu`, else LDLᵀ); the number of negative pivots, or `None`.
    /// Also sets `‖K‖∞`.
    fn factor_blocks(&mut self, lu: bool) -> Option<usize> {
        let negative = self.factor_tree(lu);
        self.knorm = self.row_sums.iter().fold(0.0f64, |a, &x| a.max(x));
        let negative = negative?;
        self.factor_border(lu, negative)
    }

    /// The tree part of [`TreeKkt::factor_blocks`] (and the row sums).
    fn factor_tree(&mut self, lu: bool) -> Option<usize> {
        let s = &self.shape;
        // Each block is copied from the values when first touched (its own turn, or its first
        // child's update), so that a body's values are read once, while in cache. The first
        // factorization copies them all at once instead, into a buffer so allocated (not
        // zeroed first: reused memory would be cleared, fresh pages faulted in, for nothing).
        let fresh = &mut self.fresh;
        if self.factors.len() == s.flat_len {
            fresh.iter_mut().for_each(|f| *f = true);
        } else {
            self.factors = self.values[..s.flat_len].to_vec();
            fresh.iter_mut().for_each(|f| *f = false);
        }
        let (values, factors) = (&self.values, &mut self.factors);
        // ‖K‖∞ (for the backward error of solves; every factorization is solved), row sums
        // taken while the blocks are in cache (module `norm`).
        let sums = &mut self.row_sums;
        sums.iter_mut().for_each(|x| *x = 0.0);
        s.border.add_row_sums(&values[s.flat_len..], sums);
        let mut negative = 0;
        for i in 0..s.at.len() {
            let (at, d, w) = (s.at[i], s.d[i], s.w[i]);
            if std::mem::take(&mut fresh[i]) {
                let r = s.diag_at[i]..s.diag_at[i] + d * d;
                factors[r.clone()].copy_from_slice(&values[r]);
            }
            let blk = &values[s.diag_at[i]..s.diag_at[i] + d * d];
            if s.parent[i] != u32::MAX && w > 0 {
                // The parent's unknowns come after the node's own in tree-space order.
                let pa = s.at[s.parent[i] as usize];
                let (head, tail) = sums.split_at_mut(pa);
                let c = &values[s.coup_at[i]..s.coup_at[i] + d * w];
                norm::add_node(blk, c, &mut head[at..at + d], tail, (d, w));
            } else {
                norm::add_node(blk, &[], &mut sums[at..at + d], &mut [], (d, 0));
            }
            let (fd, rest) = factors.split_at_mut(s.diag_at[i] + d * d);
            let blk = &mut fd[s.diag_at[i]..];
            let piv = &mut self.piv[s.at[i]..s.at[i] + d];
            if lu {
                if !dense::lu(blk, d, piv) {
                    return None;
                }
            } else {
                negative += dense::ldlt(blk, d)?;
            }
            let p = s.parent[i];
            if p == u32::MAX || w == 0 {
                continue;
            }
            // X_i = K_i⁻¹ C_i in the coupling slot; K_p −= C_iᵀ X_i.
            let base = s.diag_at[i] + d * d;
            let (before, after) = rest.split_at_mut(s.coup_at[i] - base);
            let x = &mut after[..d * w];
            let c = &values[s.coup_at[i]..s.coup_at[i] + d * w];
            x.copy_from_slice(c);
            if lu {
                dense::lu_solve(blk, piv, d, x, w);
            } else {
                dense::ldlt_solve(blk, d, x, w);
            }
            let p = p as usize;
            let dp = s.d[p];
            if fresh[p] {
                fresh[p] = false;
                let r = s.diag_at[p]..s.diag_at[p] + dp * dp;
                before[r.start - base..r.end - base].copy_from_slice(&values[r]);
            }
            let pblk = &mut before[s.diag_at[p] - base..s.diag_at[p] - base + dp * dp];
            dense::sub_tr_mul_block(c, x, pblk, (d, w, dp), !lu);
        }
        Some(negative)
    }

    /// The border part of [`TreeKkt::factor_blocks`], after the tree's `negative` pivots.
    fn factor_border(&mut self, lu: bool, negative: usize) -> Option<usize> {
        let s = &self.shape;
        if s.border.is_empty() {
            return Some(negative);
        }
        self.border.copy_from_slice(&self.values[s.flat_len..]);
        let mut border = std::mem::take(&mut self.border);
        let mut bpiv = std::mem::take(&mut self.border_piv);
        let got = s.border.factor(
            &mut border,
            &mut bpiv,
            |x, lo, _, need| self.tree_solve_from(x, lu, lo, need),
            !lu,
        );
        self.border = border;
        self.border_piv = bpiv;
        match got? {
            Some(b) => Some(negative + b),
            None if lu => Some(0),
            None => None,
        }
    }

    /// `x ← T⁻¹ x` over the tree part (tree-space order; the border untouched).
    fn tree_solve(&self, x: &mut [f64], lu: bool) {
        self.tree_solve_from(x, lu, 0, 0);
    }

    /// [`TreeKkt::tree_solve`] for an `x` that is zero before the tree-space position `lo`:
    /// the forward pass starts at the node holding `lo` (the nodes before it, leaves whose
    /// right side is zero, would pass zeros on); the backward pass (each node from its
    /// parent) ends at the node holding `need`, below which `x` is not read.
    fn tree_solve_from(&self, x: &mut [f64], lu: bool, lo: usize, need: usize) {
        let s = &self.shape;
        let nodes = s.at.len();
        let first = s.at.partition_point(|&a| a <= lo).saturating_sub(1);
        for i in first..nodes {
            let (at, d, w) = (s.at[i], s.d[i], s.w[i]);
            let blk = &self.factors[s.diag_at[i]..s.diag_at[i] + d * d];
            let (head, tail) = x.split_at_mut(at + d);
            let y = &mut head[at..];
            if lu {
                dense::lu_solve(blk, &self.piv[at..at + d], d, y, 1);
            } else {
                dense::ldlt_solve(blk, d, y, 1);
            }
            let p = s.parent[i];
            if p == u32::MAX {
                continue;
            }
            // r_p −= C_iᵀ y_i (the coupling's original values).
            let pa = s.at[p as usize] - at - d;
            let c = &self.values[s.coup_at[i]..s.coup_at[i] + d * w];
            dense::sub_tr_mul(c, y, &mut tail[pa..pa + w], d, w);
        }
        let last = s.at.partition_point(|&a| a <= need).saturating_sub(1);
        for i in (last..nodes).rev() {
            let p = s.parent[i];
            if p == u32::MAX {
                continue;
            }
            let (at, d, w) = (s.at[i], s.d[i], s.w[i]);
            let pa = s.at[p as usize];
            let xm = &self.factors[s.coup_at[i]..s.coup_at[i] + d * w];
            let (head, tail) = x.split_at_mut(pa);
            dense::sub_mul(xm, &tail[..w], &mut head[at..at + d], d, w);
        }
    }

    fn solve_once(&self, x: &mut [f64]) {
        let lu = self.kind == Factored::Lu;
        if self.kind == Factored::None {
            x.iter_mut().for_each(|v| *v = f64::NAN);
        } else if self.shape.border.is_empty() {
            self.tree_solve(x, lu);
        } else {
            self.shape
                .border
                .solve(&self.border, &self.border_piv, x, false, |y, _| {
                    self.tree_solve(y, lu)
                });
        }
    }

    /// `r −= K x` in tree-space order from the stored values.
    fn residual(&self, x: &[f64], r: &mut [f64]) {
        let s = &self.shape;
        for i in 0..s.at.len() {
            let (at, d, w) = (s.at[i], s.d[i], s.w[i]);
            let blk = &self.values[s.diag_at[i]..s.diag_at[i] + d * d];
            dense::sub_mul(blk, &x[at..at + d], &mut r[at..at + d], d, d);
            if s.parent[i] != u32::MAX {
                let pa = s.at[s.parent[i] as usize];
                let c = &self.values[s.coup_at[i]..s.coup_at[i] + d * w];
                dense::sub_mul(c, &x[pa..pa + w], &mut r[at..at + d], d, w);
                dense::sub_tr_mul(c, &x[at..at + d], &mut r[pa..pa + w], d, w);
            }
        }
        s.border.sub_product(&self.values[s.flat_len..], x, r);
    }

    /// Solves with the last factors in place (`rhs` of length `n + rows`), with iterative
    /// refinement until the normwise backward error is below `target` (at most three steps);
    /// `false` if singular or if it stays above 10⁻¹⁰ (as `sparse::kkt::Kkt::solve`).
    pub(crate) fn solve(&self, rhs: &mut [f64], target: f64) -> bool {
        let mut scratch = self.scratch.borrow_mut();
        let Scratch { x, b, r } = &mut *scratch;
        let perm = &self.shape.perm;
        b.clear();
        b.extend(perm.iter().map(|&o| rhs[o]));
        x.clear();
        x.extend_from_slice(b);
        let bnorm = b.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        self.solve_once(x);
        let mut omega = f64::INFINITY;
        for _ in 0..3 {
            r.clear();
            r.extend_from_slice(b);
            self.residual(x, r);
            let rnorm = r.iter().fold(0.0f64, |a, v| a.max(v.abs()));
            let xnorm = x.iter().fold(0.0f64, |a, v| a.max(v.abs()));
            omega = rnorm / (self.knorm * xnorm + bnorm).max(f64::MIN_POSITIVE);
            if !omega.is_finite() || omega <= target {
                break;
            }
            self.solve_once(r);
            for (x, d) in x.iter_mut().zip(r.iter()) {
                *x += d;
            }
        }
        for (k, &o) in perm.iter().enumerate() {
            rhs[o] = x[k];
        }
        rhs.iter().all(|x| x.is_finite()) && omega <= 1e-10
    }

    /// Number of constraint rows.
    pub(crate) fn rows(&self) -> usize {
        self.shape.rows
    }

    /// Number of coordinates `n`.
    pub(crate) fn coordinates(&self) -> usize {
        self.shape.n
    }

    /// Unknowns in the border (0 on a tree).
    #[cfg(test)]
    pub(crate) fn border_size(&self) -> usize {
        self.shape.border.size()
    }
}
