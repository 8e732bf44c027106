//! The fused assembly of the tree KKT matrix's `W` block: the energy Hessian `V_qq`, the
//! constraint term `−Σ_k μ_k Φ_k,qq` and the augmentation `Φ_qᵀ D R D Φ_q` (module
//! `system::augment`) added by the terms themselves into the tree's own `7 × 7` body-pair
//! blocks (found by a direct map, no search, the mirror of a coupling not kept), then stored
//! scaled into the flat blocks `K_i`, `C_i` in one pass:
//!
//! ```text
//! K_i[a, b] = (Σ_terms c h_ab) D_a D_b
//! ```
//!
//! instead of into the general block Hessian (three blocks per joint, found by binary search,
//! cleared whole) that is then scattered. The sums are the block Hessian's, term by term in
//! the same order from `+0`, and the store is its scatter's `(w D_a) D_b`: the values are the
//! general assembly's to the last bit. The terms accumulate in a compact buffer, not in the
//! flat blocks themselves, so that each assembly passes over the `13 × 13` blocks once (at
//! 10,000 bodies they exceed the caches, and passes over them cost more than the
//! instructions saved). A term on a body pair that the structure does not hold (`missing`)
//! leaves the values incomplete: the caller assembles by the general path instead, which
//! rebuilds the structure.

use super::kkt::TreeKkt;
use super::shape::SKIP;
use crate::constraints::Triplet;
use crate::jet::{add_symmetric_part, euler_to_local, HessianSink, LMat};
use crate::model::BodyId;
use nalgebra::SMatrix;

/// Where one Hessian block's entries go in the flat values.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Run {
    /// The mirror of a coupling: not stored.
    Skip,
    /// Entry `(i, j)` at `start + i stride + j`.
    Dense { start: usize, stride: usize },
    /// Entry by entry, at the slots `Shape::scattered_slots[at]` (the border).
    Scattered { at: u32 },
}

/// The Hessian blocks of a structure by body pair, built at its first fused assembly.
pub(crate) struct BlockMap {
    /// Row body `a`'s blocks: `first[a] .. first[a + 1]` into `cols` and `kept`.
    first: Vec<u32>,
    cols: Vec<u32>,
    /// Each block's place in the compact buffer ([`SKIP`]: a mirror, not kept).
    kept: Vec<u32>,
    /// The kept blocks' indices (in the structure's block order).
    blocks: Vec<u32>,
    /// `(row body, column body)` of each block.
    keys: Vec<(usize, usize)>,
}

impl BlockMap {
    /// The map of the blocks `keys` (`(row body, column body)`) over `bodies` bodies, each
    /// going to `runs` (the mirrors not kept).
    pub(crate) fn new(bodies: usize, keys: &[(usize, usize)], runs: &[Run]) -> Self {
        let mut count = vec![0u32; bodies + 1];
        for &(a, _) in keys {
            count[a + 1] += 1;
        }
        for a in 0..bodies {
            count[a + 1] += count[a];
        }
        let first = count.clone();
        let mut next = count;
        let (mut cols, mut kept) = (vec![0u32; keys.len()], vec![SKIP; keys.len()]);
        let mut blocks = Vec::with_capacity(keys.len());
        for (k, &(a, b)) in keys.iter().enumerate() {
            let at = next[a] as usize;
            next[a] += 1;
            cols[at] = b as u32;
            if runs[k] != Run::Skip {
                kept[at] = blocks.len() as u32;
                blocks.push(k as u32);
            }
        }
        BlockMap {
            first,
            cols,
            kept,
            blocks,
            keys: keys.to_vec(),
        }
    }

    /// The compact block of the body pair `(a, b)` ([`SKIP`]: a mirror), `None` if none.
    fn find(&self, a: usize, b: usize) -> Option<u32> {
        let r = *self.first.get(a)? as usize..*self.first.get(a + 1)? as usize;
        let at = self.cols[r.clone()].iter().position(|&c| c as usize == b)?;
        Some(self.kept[r.start + at])
    }
}

/// The Hessian sink of the fused assembly: adds each term into its compact block (unscaled).
pub(crate) struct FusedSink<'a> {
    map: &'a BlockMap,
    blocks: &'a mut [[f64; 49]],
    /// A term reached a body pair the structure does not hold.
    pub(crate) missing: bool,
}

impl FusedSink<'_> {
    /// The compact block of `(a, b)` (`None` for a mirror, and for a pair not held, which
    /// sets `missing`).
    fn block(&mut self, a: BodyId, b: BodyId) -> Option<usize> {
        match self.map.find(a.0, b.0) {
            None => {
                self.missing = true;
                None
            }
            Some(SKIP) => None,
            Some(k) => Some(k as usize),
        }
    }
}

impl HessianSink for FusedSink<'_> {
    /// As `BlockHessian::add_block`, into the slots.
    fn add_block(&mut self, bodies: &[Option<BodyId>; 2], h: &LMat, c: f64) {
        for sa in 0..2 {
            let Some(a) = bodies[sa] else { continue };
            for sb in 0..2 {
                let Some(b) = bodies[sb] else { continue };
                if let Some(k) = self.block(a, b) {
                    let blk = &mut self.blocks[k];
                    for i in 0..7 {
                        for j in 0..7 {
                            blk[7 * i + j] += c * h[(7 * sa + i, 7 * sb + j)];
                        }
                    }
                }
            }
        }
    }

    /// As [`HessianSink::add_block`], reading `h` along its columns
    /// ([`crate::jet::add_symmetric_part`]).
    fn add_symmetric_block(&mut self, bodies: &[Option<BodyId>; 2], h: &LMat, c: f64) {
        for sa in 0..2 {
            let Some(a) = bodies[sa] else { continue };
            for sb in 0..2 {
                let Some(b) = bodies[sb] else { continue };
                if let Some(k) = self.block(a, b) {
                    add_symmetric_part(&mut self.blocks[k], h, sa, sb, c);
                }
            }
        }
    }

    fn add_entry(&mut self, i: usize, j: usize, v: f64) {
        if let Some(k) = self.block(BodyId(i / 7), BodyId(j / 7)) {
            self.blocks[k][7 * (i % 7) + j % 7] += v;
        }
    }

    /// As `BlockHessian::add_euler_block`: the 4 × 4 Euler-parameter entries of each block
    /// for a finite `c` (the others would add signed zeros), the full blocks otherwise.
    fn add_euler_block(&mut self, bodies: &[Option<BodyId>; 2], hp: &SMatrix<f64, 8, 8>, c: f64) {
        if !c.is_finite() {
            self.add_block(bodies, &euler_to_local(hp), c);
            return;
        }
        for sa in 0..2 {
            let Some(a) = bodies[sa] else { continue };
            for sb in 0..2 {
                let Some(b) = bodies[sb] else { continue };
                if let Some(k) = self.block(a, b) {
                    let blk = &mut self.blocks[k];
                    for i in 0..4 {
                        for j in 0..4 {
                            blk[7 * (3 + i) + 3 + j] += c * hp[(4 * sa + i, 4 * sb + j)];
                        }
                    }
                }
            }
        }
    }
}

impl TreeKkt {
    /// Starts a fused assembly: the compact blocks zeroed and the sink that adds the terms
    /// into them. `keys` are the block Hessian's (its first blocks are this structure's:
    /// [`TreeKkt::fits`]); the compact blocks are laid in `buffer`, the block Hessian's
    /// values lent for the assembly (the fused path leaves them unused, and they hold at
    /// least as many blocks: no memory of its own), given back by [`TreeKkt::fused_end`].
    pub(crate) fn fused_begin(
        &mut self,
        keys: &[(usize, usize)],
        buffer: Vec<[f64; 49]>,
    ) -> FusedSink<'_> {
        if self.map.is_none() {
            let blocks = self.shape.block_runs.len();
            let map = BlockMap::new(self.shape.n / 7, &keys[..blocks], &self.shape.block_runs);
            self.map = Some(map);
        }
        let kept = self.map.as_ref().map_or(0, |m| m.blocks.len());
        self.w_blocks = buffer;
        self.w_blocks.clear();
        self.w_blocks.resize(kept, [0.0; 49]);
        self.fused_sink()
    }

    /// Ends a fused assembly (after [`TreeKkt::fused_finish`], or where a term was
    /// `missing`): the buffer lent to [`TreeKkt::fused_begin`], emptied.
    pub(crate) fn fused_end(&mut self) -> Vec<[f64; 49]> {
        let mut buffer = std::mem::take(&mut self.w_blocks);
        buffer.clear();
        buffer
    }

    /// The sink of a fused assembly in progress (more terms: the augmentation); before
    /// [`TreeKkt::fused_begin`] an empty map, on which every term is `missing`.
    pub(crate) fn fused_sink(&mut self) -> FusedSink<'_> {
        FusedSink {
            map: self.map.get_or_insert_with(|| BlockMap::new(0, &[], &[])),
            blocks: &mut self.w_blocks,
            missing: false,
        }
    }

    /// `W`'s scaled diagonal `D_c² |W_cc|` of a fused assembly in progress, into `wdiag`
    /// (zero where a body has no diagonal block), as `system::augment` takes it from the
    /// block Hessian.
    pub(crate) fn fused_diagonal(&self, columns: &[f64], wdiag: &mut Vec<f64>) {
        wdiag.clear();
        wdiag.resize(self.shape.n, 0.0);
        let Some(map) = &self.map else { return };
        for (blk, &k) in self.w_blocks.iter().zip(&map.blocks) {
            let (a, b) = map.keys[k as usize];
            if a == b {
                for i in 0..7 {
                    wdiag[7 * a + i] = blk[8 * i].abs() * columns[7 * a + i].powi(2);
                }
            }
        }
    }

    /// Ends a fused assembly: `W` stored scaled into the flat blocks (`(w D_a) D_b`, as the
    /// general scatter), the Jacobian's entries stored (as [`TreeKkt::assemble`]).
    pub(crate) fn fused_finish(&mut self, entries: &[Triplet], row_scale: &[f64], scale: &[f64]) {
        self.shifts.clear();
        let s = &self.shape;
        let values = &mut self.values;
        for &slot in &s.bare_diag {
            values[slot as usize] = 0.0;
        }
        let Some(map) = &self.map else { return };
        for (blk, &k) in self.w_blocks.iter().zip(&map.blocks) {
            let k = k as usize;
            let (a, b) = map.keys[k];
            let (sa, sb) = (&scale[7 * a..7 * a + 7], &scale[7 * b..7 * b + 7]);
            store_block(values, s.block_runs[k], &s.scattered_slots, blk, sa, sb);
        }
        self.store_jacobian(entries, row_scale, scale);
    }
}

/// Stores the block `blk` of `W` (row-major, unscaled) at its `run`'s slots, scaled
/// `(w D_a) D_b` with `sa`, `sb` the scaling of its row and column bodies (the mirror of a
/// coupling: nothing). The general assembly and the fused one store every block this way.
#[inline]
pub(super) fn store_block(
    values: &mut [f64],
    run: Run,
    scattered_slots: &[[u32; 49]],
    blk: &[f64; 49],
    sa: &[f64],
    sb: &[f64],
) {
    match run {
        Run::Skip => {}
        Run::Dense { start, stride } => {
            for i in 0..7 {
                let row = &mut values[start + i * stride..start + i * stride + 7];
                let src = &blk[7 * i..7 * i + 7];
                for ((v, &w), &d) in row.iter_mut().zip(src).zip(sb) {
                    *v = w * sa[i] * d;
                }
            }
        }
        Run::Scattered { at } => {
            let slots = &scattered_slots[at as usize];
            for i in 0..7 {
                for j in 0..7 {
                    let slot = slots[7 * i + j];
                    if slot != SKIP {
                        values[slot as usize] = blk[7 * i + j] * sa[i] * sb[j];
                    }
                }
            }
        }
    }
}

#[cfg(test)]
#[path = "fused_tests.rs"]
mod tests;
