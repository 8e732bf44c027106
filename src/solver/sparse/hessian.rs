//! The Hessian of the Lagrangian `W = V_qq − Σ_k μ_k ∇²Φ_k` stored by 7 × 7 body blocks.
//!
//! Every energy term and constraint row depends on at most two bodies, so `W` has a dense
//! 7 × 7 block `(a, b)` exactly where bodies `a` and `b` share a term: `O(N)` blocks for `N`
//! bodies. Blocks are found through a short list per row body (the bodies it shares a term
//! with: a handful) and accumulated in place.

use crate::jet::{HessianSink, LMat};
use crate::model::BodyId;
use nalgebra::SMatrix;

/// A symmetric matrix over `7 N` coordinates stored as dense 7 × 7 body blocks.
#[derive(Clone, Debug, Default)]
pub(crate) struct BlockHessian {
    /// For each row body `a`, the `(column body, block index)` of its blocks, sorted.
    index: Vec<Vec<(usize, usize)>>,
    /// `(row body, column body)` of each block, in creation order.
    pub(crate) keys: Vec<(usize, usize)>,
    /// Row-major 7 × 7 values of each block.
    pub(crate) values: Vec<[f64; 49]>,
}

impl BlockHessian {
    /// Adds the blocks, scaled (`D_a H_ab D_b`, `scale` the coordinate scaling), into the
    /// values of a KKT matrix at their slots (`slots[k]` for block `k`, row-major; `u32::MAX`:
    /// an entry the matrix does not hold). The sparse KKT matrix assembles its `W` block this
    /// way (the tree's stores each block along its run: `tree::fused::store_block`).
    pub(crate) fn scatter_scaled(&self, slots: &[[u32; 49]], scale: &[f64], values: &mut [f64]) {
        for ((&(a, b), blk), slots) in self.keys.iter().zip(&self.values).zip(slots) {
            for i in 0..7 {
                for j in 0..7 {
                    let slot = slots[7 * i + j];
                    if slot != u32::MAX {
                        values[slot as usize] +=
                            blk[7 * i + j] * scale[7 * a + i] * scale[7 * b + j];
                    }
                }
            }
        }
    }

    /// Room for `blocks` blocks over `bodies` row bodies before the first are added: a large
    /// model's blocks without the regrowth copies (a hint; more still fit).
    pub(crate) fn reserve(&mut self, bodies: usize, blocks: usize) {
        self.index.reserve(bodies);
        self.keys.reserve(blocks);
        self.values.reserve(blocks);
    }

    /// Sets every block to zero, keeping the structure (and restores values left empty by
    /// a fused assembly, which borrows their memory: `System::assemble_fused`).
    pub(crate) fn clear(&mut self) {
        self.values.clear();
        self.values.resize(self.keys.len(), [0.0; 49]);
    }

    fn block(&mut self, a: usize, b: usize) -> &mut [f64; 49] {
        if a >= self.index.len() {
            self.index.resize_with(a + 1, Vec::new);
        }
        // Sorted by column body: `O(log k)` for a body sharing terms with `k` others.
        let k = match self.index[a].binary_search_by_key(&b, |e| e.0) {
            Ok(i) => self.index[a][i].1,
            Err(i) => {
                let k = self.keys.len();
                self.index[a].insert(i, (b, k));
                self.keys.push((a, b));
                self.values.push([0.0; 49]);
                k
            }
        };
        &mut self.values[k]
    }

    /// `y += W x`.
    pub(crate) fn mul_add(&self, x: &[f64], y: &mut [f64]) {
        debug_assert_eq!(
            self.values.len(),
            self.keys.len(),
            "values lent to a fused assembly"
        );
        for (&(a, b), blk) in self.keys.iter().zip(&self.values) {
            for i in 0..7 {
                let mut s = 0.0;
                for j in 0..7 {
                    s += blk[7 * i + j] * x[7 * b + j];
                }
                y[7 * a + i] += s;
            }
        }
    }
}

impl HessianSink for BlockHessian {
    fn add_block(&mut self, bodies: &[Option<BodyId>; 2], h: &LMat, c: f64) {
        for sa in 0..2 {
            let Some(a) = bodies[sa] else { continue };
            for sb in 0..2 {
                let Some(b) = bodies[sb] else { continue };
                let blk = self.block(a.0, b.0);
                for i in 0..7 {
                    for j in 0..7 {
                        blk[7 * i + j] += c * h[(7 * sa + i, 7 * sb + j)];
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
                crate::jet::add_symmetric_part(self.block(a.0, b.0), h, sa, sb, c);
            }
        }
    }

    fn add_entry(&mut self, i: usize, j: usize, v: f64) {
        self.block(i / 7, j / 7)[7 * (i % 7) + j % 7] += v;
    }

    /// The Euler-parameter entries only (4 × 4 of each 7 × 7 block), the blocks found in the
    /// order of [`BlockHessian::add_block`]: the other entries would add `c · 0`, a signed
    /// zero for a finite `c`, which changes no entry (a block entry starts at `+0` and sums
    /// of finite terms are never `−0`), so the values are those of `add_block` to the last
    /// bit. A `c` that is not finite takes the full block.
    fn add_euler_block(&mut self, bodies: &[Option<BodyId>; 2], hp: &SMatrix<f64, 8, 8>, c: f64) {
        if !c.is_finite() {
            self.add_block(bodies, &crate::jet::euler_to_local(hp), c);
            return;
        }
        for sa in 0..2 {
            let Some(a) = bodies[sa] else { continue };
            for sb in 0..2 {
                let Some(b) = bodies[sb] else { continue };
                let blk = self.block(a.0, b.0);
                for i in 0..4 {
                    for j in 0..4 {
                        blk[7 * (3 + i) + 3 + j] += c * hp[(4 * sa + i, 4 * sb + j)];
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::jet::NL;
    use nalgebra::DMatrix;

    /// The Euler-parameter shortcut adds what the full block adds, bit for bit, on fresh and
    /// on filled blocks (and takes the full block for a `c` that is not finite).
    #[test]
    fn euler_blocks_equal_full_blocks_bit_for_bit() {
        let mut hp = SMatrix::<f64, 8, 8>::zeros();
        for a in 0..8 {
            for b in 0..8 {
                hp[(a, b)] = ((a * 8 + b) as f64 * 0.37).sin() * if a == b { -1.0 } else { 1e-3 };
            }
        }
        hp[(1, 2)] = -0.0;
        let full = crate::jet::euler_to_local(&hp);
        let mut filler = LMat::zeros();
        for i in 0..NL {
            for j in 0..NL {
                filler[(i, j)] = ((i + 2 * j) as f64).cos();
            }
        }
        for bodies in [[Some(BodyId(1)), Some(BodyId(0))], [Some(BodyId(2)), None]] {
            for c in [1.0, -2.5, 1e-300, f64::INFINITY] {
                let (mut x, mut y) = (BlockHessian::default(), BlockHessian::default());
                x.add_block(&bodies, &full, c);
                y.add_euler_block(&bodies, &hp, c);
                x.add_block(&bodies, &filler, 0.5);
                y.add_block(&bodies, &filler, 0.5);
                x.add_block(&bodies, &full, c);
                y.add_euler_block(&bodies, &hp, c);
                assert_eq!(x.keys, y.keys);
                for (p, q) in x.values.iter().zip(&y.values) {
                    let same = p.iter().zip(q).all(|(u, v)| u.to_bits() == v.to_bits());
                    assert!(same, "c = {c}");
                }
            }
        }
    }

    /// A symmetric local Hessian read along its columns adds what `add_block` adds, bit for
    /// bit, on one body and on two.
    #[test]
    fn symmetric_blocks_equal_full_blocks_bit_for_bit() {
        let mut h = LMat::zeros();
        for i in 0..NL {
            for j in 0..=i {
                let v = ((i * 31 + j * 17) % 23) as f64 * 0.37 - 3.1 + 1e-3 * (i + j) as f64;
                (h[(i, j)], h[(j, i)]) = (v, v);
            }
        }
        for bodies in [[Some(BodyId(3)), Some(BodyId(1))], [Some(BodyId(2)), None]] {
            for c in [1.0, -0.7] {
                let (mut x, mut y) = (BlockHessian::default(), BlockHessian::default());
                x.add_block(&bodies, &h, c);
                y.add_symmetric_block(&bodies, &h, c);
                assert_eq!(x.keys, y.keys);
                for (p, q) in x.values.iter().zip(&y.values) {
                    assert!(p.iter().zip(q).all(|(u, v)| u.to_bits() == v.to_bits()));
                }
            }
        }
    }

    #[test]
    fn blocks_add_up_like_the_dense_matrix() {
        let mut h = LMat::zeros();
        for i in 0..NL {
            for j in 0..NL {
                h[(i, j)] = (i * NL + j) as f64 * 0.01;
            }
        }
        let bodies = [Some(BodyId(2)), Some(BodyId(0))];
        let mut dense = DMatrix::zeros(21, 21);
        let mut blocks = BlockHessian::default();
        dense.add_block(&bodies, &h, 1.5);
        blocks.add_block(&bodies, &h, 1.5);
        dense.add_entry(8, 3, 2.0);
        blocks.add_entry(8, 3, 2.0);
        let x: Vec<f64> = (0..21).map(|i| (i as f64).sin()).collect();
        let mut y = vec![0.0; 21];
        blocks.mul_add(&x, &mut y);
        let yd = &dense * nalgebra::DVector::from_column_slice(&x);
        for i in 0..21 {
            assert!((y[i] - yd[i]).abs() < 1e-12);
        }
    }
}
