//! The fused assembly of the tree KKT matrix's `W` block: the energy Hessian `V_qq`, the
//! constraint term `−Σ_k μ_k Φ_k,qq` and the augmentation `Φ_qᵀ D R D Φ_q` (module
//! `system::augment`) written by the terms themselves straight into the tree's flat blocks
//! (`K_i`, `C_i`), then scaled in place:
//!
//! ```text
//! K_i[a, b] = D_a (Σ_terms c h_ab) D_b
//! ```
//!
//! instead of into a general block Hessian that is then scattered. The structure is the
//! tree's own (module `shape`): each body pair with a Hessian block has a dense run of slots
//! (the node's diagonal block or its coupling to the parent), is the mirror of a coupling
//! (not stored: the elimination reads its transpose) or, in the border, a slot per entry.
//!
//! Every slot holds one block entry, so the sums are those of the block Hessian, term by term
//! in the same order from `+0`, and the scaling `(w D_a) D_b` is the scatter's: the values
//! are the general assembly's to the last bit. A term on a body pair that the structure does
//! not hold (`missing`) leaves the values incomplete: the caller assembles by the general
//! path instead, which rebuilds the structure.

use super::kkt::TreeKkt;
use super::shape::SKIP;
use crate::jet::{euler_to_local, HessianSink, LMat};
use crate::model::BodyId;
use nalgebra::SMatrix;

/// Where one Hessian block's entries go in the flat values.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Run {
    /// The mirror of a coupling: not stored.
    Skip,
    /// Entry `(i, j)` at `start + i stride + j`.
    Dense { start: usize, stride: usize },
    /// Entry by entry, at the block's slots (the border).
    Scattered,
}

/// The Hessian blocks of a structure by body pair, built at its first fused assembly.
pub(crate) struct BlockMap {
    /// Row body `a`'s blocks: `first[a] .. first[a + 1]` into `cols` and `blocks`.
    first: Vec<u32>,
    cols: Vec<u32>,
    blocks: Vec<u32>,
    /// `(row body, column body)` of each block.
    keys: Vec<(usize, usize)>,
}

impl BlockMap {
    /// The map of the blocks `keys` (`(row body, column body)`) over `bodies` bodies.
    pub(crate) fn new(bodies: usize, keys: &[(usize, usize)]) -> Self {
        let mut count = vec![0u32; bodies + 1];
        for &(a, _) in keys {
            count[a + 1] += 1;
        }
        for a in 0..bodies {
            count[a + 1] += count[a];
        }
        let first = count.clone();
        let mut next = count;
        let (mut cols, mut blocks) = (vec![0u32; keys.len()], vec![0u32; keys.len()]);
        for (k, &(a, b)) in keys.iter().enumerate() {
            let at = next[a] as usize;
            next[a] += 1;
            cols[at] = b as u32;
            blocks[at] = k as u32;
        }
        BlockMap {
            first,
            cols,
            blocks,
            keys: keys.to_vec(),
        }
    }

    /// The block of the body pair `(a, b)`.
    fn find(&self, a: usize, b: usize) -> Option<usize> {
        let r = *self.first.get(a)? as usize..*self.first.get(a + 1)? as usize;
        let at = self.cols[r.clone()].iter().position(|&c| c as usize == b)?;
        Some(self.blocks[r.start + at] as usize)
    }
}

/// The Hessian sink of the fused assembly: adds each term into the tree's values (unscaled).
pub(crate) struct FusedSink<'a> {
    map: &'a BlockMap,
    runs: &'a [Run],
    slots: &'a [[u32; 49]],
    values: &'a mut [f64],
    /// A term reached a body pair the structure does not hold.
    pub(crate) missing: bool,
}

impl FusedSink<'_> {
    /// The block of `(a, b)`, or `None` (and `missing`) if there is none.
    fn block(&mut self, a: BodyId, b: BodyId) -> Option<usize> {
        let k = self.map.find(a.0, b.0);
        self.missing |= k.is_none();
        k
    }

    /// Adds `f(i, j)` to the entries `(i, j) ∈ rows × cols` of block `k`.
    fn add_to(
        &mut self,
        k: usize,
        rows: std::ops::Range<usize>,
        cols: std::ops::Range<usize>,
        f: impl Fn(usize, usize) -> f64,
    ) {
        match self.runs[k] {
            Run::Skip => {}
            Run::Dense { start, stride } => {
                for i in rows {
                    let row = &mut self.values[start + i * stride..start + i * stride + 7];
                    for j in cols.clone() {
                        row[j] += f(i, j);
                    }
                }
            }
            Run::Scattered => {
                for i in rows {
                    for j in cols.clone() {
                        let slot = self.slots[k][7 * i + j];
                        if slot != SKIP {
                            self.values[slot as usize] += f(i, j);
                        }
                    }
                }
            }
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
                    self.add_to(k, 0..7, 0..7, |i, j| c * h[(7 * sa + i, 7 * sb + j)]);
                }
            }
        }
    }

    fn add_entry(&mut self, i: usize, j: usize, v: f64) {
        if let Some(k) = self.block(BodyId(i / 7), BodyId(j / 7)) {
            self.add_to(k, i % 7..i % 7 + 1, j % 7..j % 7 + 1, |_, _| v);
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
                    self.add_to(k, 3..7, 3..7, |i, j| {
                        c * hp[(4 * sa + i - 3, 4 * sb + j - 3)]
                    });
                }
            }
        }
    }
}

impl TreeKkt {
    /// Starts a fused assembly: the `W` slots zeroed (the Jacobian's are stored by
    /// [`TreeKkt::fused_finish`]) and the sink that adds the terms into them. `keys` are the
    /// block Hessian's (its first blocks are this structure's: [`TreeKkt::fits`]).
    pub(crate) fn fused_begin(&mut self, keys: &[(usize, usize)]) -> FusedSink<'_> {
        if self.map.is_none() {
            let blocks = self.shape.block_slots.len();
            self.map = Some(BlockMap::new(self.shape.n / 7, &keys[..blocks]));
        }
        self.shifts.clear();
        let s = &self.shape;
        let values = &mut self.values;
        for &slot in &s.bare_diag {
            values[slot as usize] = 0.0;
        }
        for (run, slots) in s.block_runs.iter().zip(&s.block_slots) {
            match *run {
                Run::Skip => {}
                Run::Dense { start, stride } => {
                    for i in 0..7 {
                        values[start + i * stride..start + i * stride + 7].fill(0.0);
                    }
                }
                Run::Scattered => {
                    for &slot in slots.iter().filter(|&&x| x != SKIP) {
                        values[slot as usize] = 0.0;
                    }
                }
            }
        }
        self.fused_sink()
    }

    /// The sink of a fused assembly in progress (more terms: the augmentation); before
    /// [`TreeKkt::fused_begin`] an empty map, on which every term is `missing`.
    pub(crate) fn fused_sink(&mut self) -> FusedSink<'_> {
        FusedSink {
            map: self.map.get_or_insert_with(|| BlockMap::new(0, &[])),
            runs: &self.shape.block_runs,
            slots: &self.shape.block_slots,
            values: &mut self.values,
            missing: false,
        }
    }

    /// The (unscaled) diagonal entry `W_cc` of a fused assembly in progress.
    pub(crate) fn fused_diagonal(&self, c: usize) -> f64 {
        self.values[self.shape.diag_slots[c] as usize]
    }

    /// Ends a fused assembly: `W` scaled in place (`(w D_a) D_b`, as the general scatter),
    /// the Jacobian's entries stored (as [`TreeKkt::assemble`]).
    pub(crate) fn fused_finish(
        &mut self,
        entries: &[(usize, usize, f64)],
        row_scale: &[f64],
        scale: &[f64],
    ) {
        let s = &self.shape;
        let values = &mut self.values;
        let keys = self.map.as_ref().map_or(&[][..], |m| &m.keys[..]);
        for ((run, slots), &(a, b)) in s.block_runs.iter().zip(&s.block_slots).zip(keys) {
            let (sa, sb) = (&scale[7 * a..7 * a + 7], &scale[7 * b..7 * b + 7]);
            match *run {
                Run::Skip => {}
                Run::Dense { start, stride } => {
                    for i in 0..7 {
                        let row = &mut values[start + i * stride..start + i * stride + 7];
                        for (v, &d) in row.iter_mut().zip(sb) {
                            *v = *v * sa[i] * d;
                        }
                    }
                }
                Run::Scattered => {
                    for i in 0..7 {
                        for j in 0..7 {
                            let slot = slots[7 * i + j];
                            if slot != SKIP {
                                let v = &mut values[slot as usize];
                                *v = *v * sa[i] * sb[j];
                            }
                        }
                    }
                }
            }
        }
        self.store_jacobian(entries, row_scale, scale);
    }
}

#[cfg(test)]
#[path = "fused_tests.rs"]
mod tests;
