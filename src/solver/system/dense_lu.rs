//! LU with partial pivoting of the dense path's `Φ_u`, `P A = L U`: nalgebra's `LU::new` to
//! the last bit, with the elimination skipping the zeros of `A`'s structure.
//!
//! Step `i` of nalgebra's elimination scales the column below the pivot, `c_j = a_ji / a_ii`,
//! and updates every entry of the trailing matrix, `a_jk ← (−a_ik) c_j + a_jk`. `Φ_u` of a
//! robot is mostly zeros (each row couples the coordinates of two bodies), and so are the
//! pivot rows and columns of most steps: Talos reduced spent 44 % of its process in these
//! updates. Where `a_ik = ±0` or `c_j = ±0` (and every factor is finite), the product is
//! `±0` and the update leaves `a_jk` as it is, unless `a_jk = −0` (then `−0 + +0 = +0`); the
//! trailing entries are never `−0` (an input without `−0`, and a sum is `−0` only where both
//! terms are), so skipping those updates changes no bit. With a non-finite factor in a step, or
//! a `−0` in the input, every update is made as nalgebra makes it. The rows `j` with
//! `c_j ≠ 0` and the columns `k` with `a_ik ≠ 0` are listed once per step (one pass down the
//! pivot's column, one along its row, which also test that every factor is finite), and only
//! their products are updated: a step costs those counts' product, not the trailing matrix.
//! The pivot search is nalgebra's `icamax` (the first largest magnitude) chunk by chunk.
//!
//! The solves are nalgebra's on the packed factors (`LU::solve_mut`'s three calls: the row
//! permutation, `L y = P b` and `U x = y`), bit for bit, skipping likewise. Step `i` of either
//! triangular solve updates the entries after (before) it, `b_j ← (−c) t_ji + b_j` with
//! `c = b_i` (`b_i / u_ii`); where `c = ±0` and the factors are finite, each product is `±0`
//! and leaves `b_j` as it is unless `b_j = −0`. A right-hand column without `−0` (and
//! finite) never gets one, so such a column's zero steps are skipped: a column of `Φ_v` meets
//! `Φ_u⁻¹` mostly as zeros (in the dense null-space basis 62 % of the steps of alex's solves).
//! A column with a `−0`, or factors with a non-finite entry, is solved step by step as
//! nalgebra solves it.

use crate::solver::partition::abs_max;
use nalgebra::{DMatrix, Dim, Dyn, IsContiguous, Matrix, PermutationSequence, StorageMut};

/// The factors `P A = L U` of a square or rectangular `A`, packed as nalgebra's `LU`: `U` on
/// and above the diagonal, `L` (unit diagonal) below it.
#[derive(Clone, Debug)]
pub(crate) struct DenseLu {
    lu: DMatrix<f64>,
    p: PermutationSequence<Dyn>,
    /// Every factor finite, and square with no zero on `U`'s diagonal: the solves may skip
    /// (module docs).
    skips: bool,
}

impl DenseLu {
    /// Factors `m` (module docs): the same packed factors and permutation as
    /// `nalgebra::LU::new(m)`.
    pub(crate) fn new(mut m: DMatrix<f64>) -> Self {
        let (rows, cols) = m.shape();
        let steps = rows.min(cols);
        let mut p = PermutationSequence::identity_generic(Dyn(steps));
        // A `−0` anywhere: every update as nalgebra makes it (module docs).
        let signed_zero = m
            .as_slice()
            .iter()
            .any(|x| *x == 0.0 && x.is_sign_negative());
        // Per step, the rows below the pivot where its column is nonzero and the columns
        // after it where its row is: the only updates that change a bit (module docs).
        let mut nonzero: Vec<usize> = Vec::with_capacity(rows);
        let mut row_nonzero: Vec<usize> = Vec::with_capacity(cols);
        // Every factor finite and every pivot nonzero so far (`L`'s column and `U`'s row of
        // each step are final when the step has made them).
        let mut skips = rows == cols;
        for i in 0..steps {
            let piv = icamax(&m.as_slice()[i * rows + i..(i + 1) * rows]) + i;
            let diag = m[(piv, i)];
            skips &= diag.is_finite();
            if diag == 0.0 {
                // No nonzero entry in this column.
                skips = false;
                continue;
            }
            if piv != i {
                p.append_permutation(i, piv);
                m.swap_rows(i, piv);
            }
            let inv = 1.0 / diag;
            // Column-major: column `k` at `k rows ..`; the pivot's column and the later ones.
            let (head, tail) = m.as_mut_slice().split_at_mut((i + 1) * rows);
            let column = &mut head[i * rows..];
            let mut finite = true;
            for x in &mut column[i + 1..] {
                *x *= inv;
                finite &= x.is_finite();
            }
            row_nonzero.clear();
            for (k, later) in tail.chunks_exact(rows).enumerate() {
                let a = later[i];
                finite &= a.is_finite();
                if a != 0.0 {
                    row_nonzero.push(k);
                }
            }
            skips &= finite;
            let finite = finite && !signed_zero;
            nonzero.clear();
            nonzero.extend((i + 1..rows).filter(|&j| !finite || column[j] != 0.0));
            let column = &*column;
            let update = |later: &mut [f64]| {
                let a = -later[i];
                for &j in &nonzero {
                    later[j] += a * column[j];
                }
            };
            if finite {
                for &k in &row_nonzero {
                    update(&mut tail[k * rows..(k + 1) * rows]);
                }
            } else {
                tail.chunks_exact_mut(rows).for_each(update);
            }
        }
        DenseLu { lu: m, p, skips }
    }

    /// The packed factors (`U` on and above the diagonal, `L` below it).
    pub(crate) fn packed(&self) -> &DMatrix<f64> {
        &self.lu
    }

    /// The row permutation `P`.
    pub(crate) fn p(&self) -> &PermutationSequence<Dyn> {
        &self.p
    }

    /// `A x = b` in place (square `A`): `nalgebra::LU::solve_mut` bit for bit; `false` where
    /// `U` has a zero on its diagonal. Zero steps are skipped in each column that allows it
    /// (module docs).
    pub(crate) fn solve_mut<C: Dim, S: StorageMut<f64, Dyn, C> + IsContiguous>(
        &self,
        b: &mut Matrix<f64, Dyn, C, S>,
    ) -> bool {
        self.p.permute_rows(b);
        if !self.skips {
            let _ = self.lu.solve_lower_triangular_with_diag_mut(b, 1.0);
            return self.lu.solve_upper_triangular_mut(b);
        }
        let n = self.lu.nrows();
        let t = self.lu.as_slice();
        for col in b.as_mut_slice().chunks_exact_mut(n.max(1)) {
            let skip = col
                .iter()
                .all(|x| x.is_finite() && !(*x == 0.0 && x.is_sign_negative()));
            solve_column(t, n, col, skip);
        }
        true
    }
}

/// `icamax` of nalgebra on a column: the first entry whose magnitude exceeds all before it,
/// from `|x₀|` (a NaN first stays): the first largest magnitude after `x₀` where it exceeds
/// `|x₀|` (found chunk by chunk, `partition::abs_max`).
fn icamax(x: &[f64]) -> usize {
    let (max, at) = abs_max(&x[1..], 1);
    if max > x[0].abs() {
        at
    } else {
        0
    }
}

/// `L U x = b` for one column `b` of length `n` on the packed factors `t` (column-major,
/// finite, no zero on `U`'s diagonal): nalgebra's steps `b_j ← (−c) t_ji · 1 + 1 · b_j`, the
/// same value as `b_j + (−c) t_ji` (the products by 1 are exact, the sum commutes); the steps
/// with `c = ±0` skipped if `skip` (module docs).
fn solve_column(t: &[f64], n: usize, b: &mut [f64], skip: bool) {
    for i in 0..n.saturating_sub(1) {
        // nalgebra divides by the unit diagonal: `b_i / 1` is `b_i`.
        let c = b[i];
        if skip && c == 0.0 {
            continue;
        }
        let a = -c;
        for (y, &x) in b[i + 1..].iter_mut().zip(&t[i * n + i + 1..(i + 1) * n]) {
            *y += a * x;
        }
    }
    for i in (0..n).rev() {
        let c = b[i] / t[i * n + i];
        b[i] = c;
        if skip && c == 0.0 {
            continue;
        }
        let a = -c;
        for (y, &x) in b[..i].iter_mut().zip(&t[i * n..i * n + i]) {
            *y += a * x;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::DVector;

    /// Sparse random matrices (most entries zero, the rest of widely spread magnitudes), with
    /// row swaps, zero columns, a singular one, non-finite and `−0` entries: the packed factors,
    /// the permutation and the solves (of a dense right side, and of sparse ones with and
    /// without `−0` and a NaN) equal nalgebra's `LU` bit for bit.
    #[test]
    fn factors_and_solves_are_nalgebras_bit_for_bit() {
        let mut lcg = crate::lcg::Lcg::new(2024);
        let mut r = || lcg.unit();
        let bits = |m: &DMatrix<f64>| m.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        let mut cases = Vec::new();
        for (n, fill) in [
            (1, 1.0),
            (3, 0.5),
            (12, 0.2),
            (40, 0.08),
            (60, 0.05),
            (150, 0.02),
        ] {
            for _ in 0..4 {
                let a = DMatrix::from_fn(n, n, |i, j| {
                    if i == j || r() < fill {
                        (r() * 2.0 - 1.0) * 10f64.powi((r() * 8.0) as i32 - 4)
                    } else {
                        0.0
                    }
                });
                cases.push(a);
            }
        }
        let mut zero_column = cases[9].clone();
        zero_column.column_mut(3).fill(0.0);
        let mut infinite = cases[10].clone();
        infinite[(5, 2)] = f64::INFINITY;
        let mut signed = cases[11].clone();
        signed[(4, 7)] = -0.0;
        signed[(0, 1)] = -0.0;
        let rectangular = DMatrix::from_fn(9, 6, |i, j| {
            if (i + j) % 3 == 0 {
                1.0 + i as f64
            } else {
                0.0
            }
        });
        let wide = rectangular.transpose();
        cases.extend([zero_column, infinite, signed, rectangular, wide]);
        for (c, a) in cases.iter().enumerate() {
            let theirs = a.clone().lu();
            let ours = DenseLu::new(a.clone());
            assert_eq!(bits(theirs.lu_internal()), bits(ours.packed()), "case {c}");
            if a.is_square() {
                let b = DVector::from_fn(a.nrows(), |i, _| (i as f64).sin() + 0.5);
                let (mut x, mut y) = (b.clone(), b);
                let solved = theirs.solve_mut(&mut x);
                assert_eq!(solved, ours.solve_mut(&mut y), "case {c}");
                if solved {
                    let v = |v: &DVector<f64>| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                    assert_eq!(v(&x), v(&y), "case {c}");
                }
                // Sparse right sides, as `Φ_v`'s columns: zero steps skipped where a column
                // has no `−0` (the first four columns), solved step by step where it has.
                let n = a.nrows();
                let mut b = DMatrix::from_fn(n, 6, |i, j| {
                    if (i * 7 + j * 3) % 5 == 0 {
                        (i as f64 + 1.0).ln() - j as f64
                    } else {
                        0.0
                    }
                });
                b[(n - 1, 4)] = -0.0;
                b[(0, 5)] = -0.0;
                b[(n / 2, 5)] = f64::NAN;
                let (mut x, mut y) = (b.clone(), b);
                let solved = theirs.solve_mut(&mut x);
                assert_eq!(solved, ours.solve_mut(&mut y), "case {c}");
                if solved {
                    // Bit for bit where nalgebra's columns are finite (the NaN spreads).
                    let col = |m: &DMatrix<f64>, j: usize| {
                        let v = m.column(j);
                        let finite = v.iter().all(|v| v.is_finite());
                        let key = |v: &f64| {
                            if finite {
                                v.to_bits()
                            } else {
                                v.is_nan() as u64
                            }
                        };
                        v.iter().map(key).collect::<Vec<_>>()
                    };
                    for j in 0..6 {
                        assert_eq!(col(&x, j), col(&y, j), "case {c}, column {j}");
                    }
                }
            }
            let mut e = DMatrix::<f64>::identity(a.nrows(), a.nrows());
            let mut f = e.clone();
            theirs.p().permute_rows(&mut e);
            ours.p().permute_rows(&mut f);
            assert_eq!(bits(&e), bits(&f), "case {c}: permutation");
        }
    }
}
