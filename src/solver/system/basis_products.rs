//! The products of the reduced Hessian `Ĥ = Zᵀ (W Z)` with the null-space basis `Z`
//! (`n × dof`, column-major), skipping the zeros of `Z`: on a tree the column of an
//! independent coordinate moves only the bodies on one side of its joint, so about half of
//! `Z`'s 7-row body blocks are zero (a chain: the bodies nearer the root).
//!
//! Both products give the results of the plain loops to the last bit. A skipped term is a
//! product `z · a` with `z = ±0` and a finite `a`, so `±0`; every partial sum starts at `+0`,
//! and a sum of finite terms from `+0` is never `−0` (`+0 + −0 = +0`; exact cancellation gives
//! `+0`), so adding `±0` changes no partial sum. Where a factor is not finite, nothing is
//! skipped.
//!
//! - `W Z`: per body block `(a, b)` of `W` and column `j`, `(W Z)_{a, j} += W_ab Z_{b, j}`,
//!   the sums of [`BlockHessian::mul_add`] in its order (each row's `0 + B_i0 x_0 + … +
//!   B_i6 x_6`), the seven rows of a block at once: the block is read by columns, padded to
//!   eight lanes, once for all columns of `Z`, so that each step `s_i += B_ik x_k` is one
//!   vector operation over `i` (a row's sum keeps its order; lanes do not mix);
//! - `Zᵀ (W Z)`: each entry the dot product of nalgebra's `tr_mul` (eight running sums over
//!   the rows in chunks of 8, `k mod 8` each, then combined as `(s₀ + s₄) + (s₁ + s₅) + …`,
//!   then the rows after the last whole chunk), over the chunks where the column of `Z` is
//!   not zero; four columns of `W Z` at a time (four independent chains of sums), over the
//!   chunks where one of the four is not zero (the others add `±0` there).

use crate::solver::sparse::hessian::BlockHessian;
use nalgebra::DMatrix;

/// The zero pattern of `Z` that both products skip.
pub(super) struct Pattern {
    /// Per column, whether each body block (7 rows) holds a nonzero.
    bodies: Vec<bool>,
    /// The whole chunks of 8 rows that hold a nonzero (chunk numbers), column after column,
    /// in order; column `j`'s are `chunks[starts[j]..starts[j + 1]]`.
    chunks: Vec<u32>,
    starts: Vec<usize>,
    /// Whether every entry of `Z` is finite.
    finite: bool,
}

/// The exponent bits of an `f64`: all set for an infinity or a NaN only.
const EXPONENT: u64 = 0x7ff0_0000_0000_0000;

/// Whether some entry of `values` is nonzero (`±0` both zero): an OR of the bits without the
/// sign, no branch per entry.
fn any_nonzero(values: &[f64]) -> bool {
    values.iter().fold(0u64, |a, v| a | (v.to_bits() << 1)) != 0
}

/// Whether every entry of `values` is finite (no exponent all ones).
fn all_finite(values: &[f64]) -> bool {
    values
        .iter()
        .fold(0u64, |a, v| a.max(v.to_bits() & EXPONENT))
        != EXPONENT
}

impl Pattern {
    /// The zero pattern of `z` (`n × dof`, `n` a multiple of 7).
    pub(super) fn of(z: &DMatrix<f64>) -> Self {
        let n = z.nrows();
        let blocks = n / 7;
        let mut bodies = vec![false; blocks * z.ncols()];
        let mut chunks = Vec::with_capacity(z.ncols() * (n / 8));
        let mut starts = Vec::with_capacity(z.ncols() + 1);
        let mut finite = true;
        for (j, col) in z.as_slice().chunks_exact(n.max(1)).enumerate() {
            for (b, blk) in col.chunks_exact(7).enumerate() {
                bodies[j * blocks + b] = any_nonzero(blk);
            }
            finite &= all_finite(col);
            starts.push(chunks.len());
            for (k, c) in col.chunks_exact(8).enumerate() {
                if any_nonzero(c) {
                    chunks.push(k as u32);
                }
            }
        }
        starts.push(chunks.len());
        Pattern {
            bodies,
            chunks,
            starts,
            finite,
        }
    }

    /// Column `j`'s whole chunks of 8 rows that hold a nonzero.
    fn chunks_of(&self, j: usize) -> &[u32] {
        &self.chunks[self.starts[j]..self.starts[j + 1]]
    }
}

/// `W Z` added into `wz` (both `n × dof`), block by block for all columns, each block of `W`
/// read once (module docs: [`BlockHessian::mul_add`] of each column to the last bit).
pub(super) fn mul_add_columns(
    hess: &BlockHessian,
    z: &DMatrix<f64>,
    pattern: &Pattern,
    wz: &mut DMatrix<f64>,
) {
    let n = z.nrows();
    let blocks = n / 7;
    let (zs, ws) = (z.as_slice(), wz.as_mut_slice());
    for (&(a, b), blk) in hess.keys.iter().zip(&hess.values) {
        let skip = blk.iter().all(|v| v.is_finite());
        let t = by_columns(blk);
        for (j, (x, y)) in zs.chunks_exact(n).zip(ws.chunks_exact_mut(n)).enumerate() {
            if skip && !pattern.bodies[j * blocks + b] {
                continue;
            }
            block_mul_add(&t, &x[7 * b..7 * b + 7], &mut y[7 * a..7 * a + 7]);
        }
    }
}

/// A row-major `7 × 7` block by columns, each padded to eight lanes: `t[k][i] = B_ik`, lane 7
/// zero.
fn by_columns(blk: &[f64; 49]) -> [[f64; 8]; 7] {
    let mut t = [[0.0; 8]; 7];
    for (k, col) in t.iter_mut().enumerate() {
        for (i, v) in col.iter_mut().take(7).enumerate() {
            *v = blk[7 * i + k];
        }
    }
    t
}

/// `y += B x` for the block `B` by columns ([`by_columns`]): each row's sum `0 + B_i0 x_0 +
/// … + B_i6 x_6` in that order, as the plain loop forms it, the rows in eight lanes (lane 7,
/// zero times `x`, is dropped).
#[inline(always)]
fn block_mul_add(t: &[[f64; 8]; 7], x: &[f64], y: &mut [f64]) {
    let mut s = [0.0f64; 8];
    for (col, &xk) in t.iter().zip(&x[..7]) {
        for (si, &c) in s.iter_mut().zip(col) {
            *si += c * xk;
        }
    }
    for (yi, si) in y[..7].iter_mut().zip(&s) {
        *yi += si;
    }
}

/// The eight running sums of nalgebra's `tr_mul` for column `zi` of `Z` and the `K` columns
/// `w` of `W Z` at once (`K` independent chains), over `zi`'s nonzero `chunks` that `keep`
/// marks (a chunk where a column of `w` is zero adds `±0` products: no sum changes).
#[inline(always)]
fn running_sums<const K: usize>(
    zi: &[f64],
    chunks: &[u32],
    keep: &[bool],
    w: &[&[f64]; K],
) -> [[f64; 8]; K] {
    let mut acc = [[0.0f64; 8]; K];
    for &c in chunks.iter().filter(|&&c| keep[c as usize]) {
        let k = 8 * c as usize;
        let a = &zi[k..k + 8];
        for (acc, wt) in acc.iter_mut().zip(w) {
            let b = &wt[k..k + 8];
            for l in 0..8 {
                acc[l] += a[l] * b[l];
            }
        }
    }
    acc
}

/// `Zᵀ (W Z)` (`dof × dof`): nalgebra's `z.tr_mul(wz)` to the last bit (module docs), over
/// the chunks of 8 rows where both the column of `Z` and one of a group of four columns of
/// `W Z` hold a nonzero (a chain: the bodies below both joints, a third of the rows on
/// average instead of a half). The groups run four chains of sums at once, each chunk's
/// step taking about its add's latency alone.
pub(super) fn tr_mul(z: &DMatrix<f64>, wz: &DMatrix<f64>, pattern: &Pattern) -> DMatrix<f64> {
    let (n, dof) = (z.nrows(), z.ncols());
    let whole = n / 8;
    // Per column of `W Z`, whether each whole chunk of 8 rows holds a nonzero; `None` where
    // an entry is not finite (then nothing is skipped).
    let mut used = vec![false; whole * wz.ncols()];
    let finite = wz
        .as_slice()
        .chunks_exact(n.max(1))
        .enumerate()
        .all(|(j, col)| {
            for (c, chunk) in col.chunks_exact(8).enumerate() {
                used[j * whole + c] = any_nonzero(chunk);
            }
            all_finite(col)
        });
    if !pattern.finite || !finite {
        return z.tr_mul(wz);
    }
    let main = n - n % 8;
    let cols = wz.ncols();
    let ws = wz.as_slice();
    // Per group of four columns of `W Z`, whether any of them holds a nonzero in each chunk.
    let groups = cols / 4;
    let mut any = vec![false; whole * groups];
    for (g, any) in any.chunks_exact_mut(whole.max(1)).enumerate().take(groups) {
        for (c, a) in any.iter_mut().enumerate() {
            *a = (0..4).any(|t| used[(4 * g + t) * whole + c]);
        }
    }
    let finish = |acc: &[f64; 8], zi: &[f64], wj: &[f64]| {
        let mut res = 0.0;
        res += acc[0] + acc[4];
        res += acc[1] + acc[5];
        res += acc[2] + acc[6];
        res += acc[3] + acc[7];
        for k in main..n {
            res += zi[k] * wj[k];
        }
        res
    };
    let mut out = DMatrix::zeros(dof, cols);
    for (i, zi) in z.as_slice().chunks_exact(n).enumerate() {
        let chunks = pattern.chunks_of(i);
        // Four columns at once over the chunks where one of them is nonzero: four independent
        // chains of sums. A column zero in such a chunk adds `±0` products, which change no
        // sum (module docs: every entry is finite here).
        for g in 0..groups {
            let w: [&[f64]; 4] = std::array::from_fn(|t| &ws[(4 * g + t) * n..(4 * g + t + 1) * n]);
            let acc = running_sums(zi, chunks, &any[g * whole..(g + 1) * whole], &w);
            for (t, (acc, wt)) in acc.iter().zip(&w).enumerate() {
                out[(i, 4 * g + t)] = finish(acc, zi, wt);
            }
        }
        for j in 4 * groups..cols {
            let wj = &ws[j * n..(j + 1) * n];
            let [acc] = running_sums(zi, chunks, &used[j * whole..(j + 1) * whole], &[wj]);
            out[(i, j)] = finish(&acc, zi, wj);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Both products equal the plain loops bit for bit on a `Z` with zero blocks, signed
    /// zeros and a row count that is not a multiple of 8.
    #[test]
    fn skipping_zeros_changes_no_bit() {
        let (n, dof) = (7 * 11, 9);
        let mut lcg = crate::lcg::Lcg::new(12345);
        let mut r = || lcg.signed();
        let z = DMatrix::from_fn(n, dof, |i, j| {
            let body = i / 7;
            if body < j {
                if (i + j) % 3 == 0 {
                    -0.0
                } else {
                    0.0
                }
            } else {
                r()
            }
        });
        let mut hess = BlockHessian::default();
        for b in 0..11 {
            hess.keys.push((b, b));
            hess.values.push(std::array::from_fn(|_| r()));
            if b > 0 {
                hess.keys.push((b - 1, b));
                hess.values.push(std::array::from_fn(|_| r()));
                hess.keys.push((b, b - 1));
                hess.values.push(std::array::from_fn(|_| r()));
            }
        }
        let pattern = Pattern::of(&z);
        let mut plain = DMatrix::zeros(n, dof);
        for j in 0..dof {
            hess.mul_add(z.column(j).as_slice(), plain.column_mut(j).as_mut_slice());
        }
        let mut skipped = DMatrix::zeros(n, dof);
        mul_add_columns(&hess, &z, &pattern, &mut skipped);
        let bits = |m: &DMatrix<f64>| m.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&plain), bits(&skipped));
        assert!(plain.iter().any(|&v| v == 0.0) && plain.iter().any(|&v| v != 0.0));
        assert_eq!(bits(&z.tr_mul(&plain)), bits(&tr_mul(&z, &plain, &pattern)));
        // Whole chunks of `W Z` that are zero (signed zeros too) where `Z` is not: skipped
        // there as well, to the same bits.
        let mut signed = plain.clone();
        for j in 0..dof {
            for k in (8 * (j + 1)..(8 * (j + 1) + 8).min(n)).chain(40..48) {
                signed[(k, j)] = if (k + j) % 2 == 0 { -0.0 } else { 0.0 };
            }
        }
        assert_eq!(
            bits(&z.tr_mul(&signed)),
            bits(&tr_mul(&z, &signed, &pattern))
        );
        let mut infinite = signed.clone();
        infinite[(3, 2)] = f64::INFINITY;
        assert_eq!(
            bits(&z.tr_mul(&infinite)),
            bits(&tr_mul(&z, &infinite, &pattern))
        );
        // `W Z` with an infinite block entry (nothing skipped for that block: `∞ · 0` is a
        // NaN) and a NaN in `Z`: the lanes give each row the plain loop's bits still.
        let mut odd = hess.clone();
        odd.values[4][9] = f64::INFINITY;
        odd.values[7][48] = f64::NEG_INFINITY;
        let mut z_nan = z.clone();
        z_nan[(30, 5)] = f64::NAN;
        for (h, z) in [(&odd, &z), (&hess, &z_nan), (&odd, &z_nan)] {
            let mut plain = DMatrix::zeros(n, dof);
            for j in 0..dof {
                h.mul_add(z.column(j).as_slice(), plain.column_mut(j).as_mut_slice());
            }
            let mut lanes = DMatrix::zeros(n, dof);
            mul_add_columns(h, z, &Pattern::of(z), &mut lanes);
            assert_eq!(bits(&plain), bits(&lanes));
            assert!(plain.iter().any(|v| v.is_nan()));
        }
    }

    /// On the tree factors, `Ĥ` and `Z` of `reduced_hessian_and_basis` (all columns in one
    /// solve, zeros skipped) equal the column-by-column formation bit for bit: `Z e_b` by
    /// `tangent_step`, `W Z e_b` by `mul_add`, nalgebra's `Zᵀ (W Z)`; on a chain (no
    /// border), Solo-12 with its base welded (a branched tree) and a spatial four-bar (a
    /// border: the columns one by one).
    #[test]
    fn reduced_hessian_on_the_tree_factors_is_that_of_the_columns() {
        use crate::constraints::Constraints;
        use crate::solver::system::{Backend, System};
        use crate::urdf::{load_file, load_str, ImportOptions};
        use nalgebra::DVector;
        let text = |t: &str| {
            load_str(t, "t.urdf", &ImportOptions::default())
                .unwrap()
                .model
        };
        let solo = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/robots/solo12/solo12_ground.urdf"
        );
        let models = [
            text(&crate::generate::chain(12, false)),
            load_file(solo, &ImportOptions::default()).unwrap().model,
            text(include_str!("../../../robots/four_bar_spatial.urdf")),
        ];
        let bits = |m: &DMatrix<f64>| m.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        for model in &models {
            let q0 = crate::solver::initial_state(model).q;
            let mut q = crate::solver::assemble_only(model, q0, &mut Default::default(), &[])
                .expect("assembles");
            // Away from the start, so that the multipliers and `W` are not trivial.
            for (i, v) in q.iter_mut().enumerate() {
                *v += 1e-3 * ((i as f64) * 0.7).sin();
            }
            let mut sys = System::new(model, Constraints::new(model, &[]), Backend::Tree);
            let part = sys.partition(&q);
            sys.correct(&mut q, &part, 1e-12, 20).expect("corrector");
            let eval = sys.evaluate(&q, &part).expect("evaluation");
            assert!(matches!(
                eval.factors,
                crate::solver::system::Factors::Tree(_)
            ));
            let (h, basis) = sys.reduced_hessian_and_basis(&q, &part, &eval);
            let basis = basis.expect("kept");
            let (n, dof) = (q.len(), part.independent.len());
            let mut z = DMatrix::zeros(n, dof);
            let mut wz = DMatrix::zeros(n, dof);
            for b in 0..dof {
                let mut e = DVector::zeros(dof);
                e[b] = 1.0;
                z.set_column(b, &sys.tangent_step(&part, &eval, &e));
                sys.work
                    .hess
                    .mul_add(z.column(b).as_slice(), wz.column_mut(b).as_mut_slice());
            }
            let hr = z.tr_mul(&wz);
            assert_eq!(bits(&basis), bits(&z));
            assert_eq!(bits(&h), bits(&((&hr + hr.transpose()) * 0.5)));
            assert!(h.amax() > 0.0 && dof > 0);
        }
    }
}
