//! The block LDLᵀ and its solves for the block sizes of a chain and a ladder (`D` ≤ 27),
//! unrolled at compile time: the step of column `j` (and the row `i` of a solve) is a function
//! of the constants `D` and `J`, so that every loop has a known length, runs without bounds
//! checks and, across the rows of a column, on pairs of entries.
//!
//! The operations are those of module `dense`'s loops, on each entry in the same order:
//!
//! ```text
//! v_k = L_jk D_k,   D_j = A_jj − Σ_{k<j} L_jk v_k,   L_ij = (A_ij − Σ_{k<j} L_ik v_k) / D_j
//! y_i = x_i − Σ_{k<i} L_ik y_k,   x_i = y_i · (1 / D_i) − Σ_{k>i} L_ki x_k
//! ```
//!
//! (sums term by term in increasing `k`, a solve's terms with `L = 0` skipped), so the results
//! are theirs to the last bit. Column `j` of `L` is also stored as row `j` above the diagonal:
//! the later columns read it there as a row (`L_ik` for all `i > j` at once).
//!
//! The same treatment for the other block kernels of the tree, each keeping what it
//! accumulates in registers: LU with partial pivoting (step `K` of the elimination a function
//! of `D` and `K`), the Schur update `P −= Cᵀ X` on a parent's lower triangle (one row of `P`
//! at a time), and the products `x −= X y`, `out −= Cᵀ y` of the solves.

/// `A = L D Lᵀ` in place (see `dense::ldlt`; the upper triangle is left holding `Lᵀ`).
#[inline(never)]
pub(super) fn ldlt<const D: usize>(a: &mut [f64]) -> Option<usize> {
    const { assert!(D <= 27) };
    let a = a.get_mut(..D * D)?;
    let (mut v, mut diag) = ([0.0; D], [0.0; D]);
    let mut negative = 0;
    macro_rules! columns {
        ($($j:literal)*) => {
            $(
                if $j < D {
                    negative += usize::from(column::<D, $j>(a, &mut v, &mut diag)?);
                }
            )*
        };
    }
    columns!(0 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18 19 20 21 22 23 24 25 26);
    Some(negative)
}

/// Column `J` of [`ldlt`] on the `D × D` row-major `a`: its pivot `D_J` (whether negative;
/// `None` if zero or not finite) and `L_iJ` for `i > J`, with `v` and `diag` (the pivots so
/// far) as scratch.
#[inline(always)]
fn column<const D: usize, const J: usize>(
    a: &mut [f64],
    v: &mut [f64; D],
    diag: &mut [f64; D],
) -> Option<bool> {
    let (done, rest) = a.split_at_mut(J * D);
    let (row, below) = rest.split_at_mut(D);
    for k in 0..J {
        v[k] = row[k] * diag[k];
    }
    let mut djj = row[J];
    for k in 0..J {
        djj -= row[k] * v[k];
    }
    if !djj.is_finite() || djj == 0.0 {
        return None;
    }
    row[J] = djj;
    diag[J] = djj;
    let mut s = [0.0; D];
    for i in J + 1..D {
        s[i] = below[(i - J - 1) * D + J];
    }
    for k in 0..J {
        let (vk, lk) = (v[k], &done[k * D..k * D + D]);
        for i in J + 1..D {
            s[i] -= lk[i] * vk;
        }
    }
    for i in J + 1..D {
        let l = s[i] / djj;
        below[(i - J - 1) * D + J] = l;
        row[i] = l;
    }
    Some(djj < 0.0)
}

/// `x ← A⁻¹ x` for the factors of [`ldlt`] (or `dense::ldlt`'s: the lower triangle is read);
/// `x` is `D × W` row-major, each row finished in registers.
#[inline(never)]
pub(super) fn ldlt_solve<const D: usize, const W: usize>(f: &[f64], x: &mut [f64]) {
    const { assert!(D <= 27) };
    let (f, x) = (&f[..D * D], &mut x[..D * W]);
    macro_rules! each_row {
        ($step:ident: $($i:literal)*) => {
            $(
                if $i < D {
                    $step::<D, W, $i>(f, x);
                }
            )*
        };
    }
    each_row!(forward: 0 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18 19 20 21 22 23 24 25 26);
    each_row!(backward: 26 25 24 23 22 21 20 19 18 17 16 15 14 13 12 11 10 9 8 7 6 5 4 3 2 1 0);
}

/// Row `I` of `L y = x` (`f` is `D × D`, `x` is `D × W`, both row-major).
#[inline(always)]
fn forward<const D: usize, const W: usize, const I: usize>(f: &[f64], x: &mut [f64]) {
    let (done, rest) = x.split_at_mut(I * W);
    let mut acc = [0.0; W];
    acc.copy_from_slice(&rest[..W]);
    for k in 0..I {
        let l = f[I * D + k];
        if l != 0.0 {
            for c in 0..W {
                acc[c] -= l * done[k * W + c];
            }
        }
    }
    rest[..W].copy_from_slice(&acc);
}

/// Row `I` of `D Lᵀ x = y` (rows after `I` finished).
#[inline(always)]
fn backward<const D: usize, const W: usize, const I: usize>(f: &[f64], x: &mut [f64]) {
    let (head, later) = x.split_at_mut(I * W + W);
    let mut acc = [0.0; W];
    acc.copy_from_slice(&head[I * W..]);
    let p = 1.0 / f[I * D + I];
    for a in acc.iter_mut() {
        *a *= p;
    }
    for k in I + 1..D {
        let l = f[k * D + I];
        if l != 0.0 {
            for c in 0..W {
                acc[c] -= l * later[(k - I - 1) * W + c];
            }
        }
    }
    head[I * W..].copy_from_slice(&acc);
}

/// `P −= Cᵀ X` on the lower triangle of the leading `W × W` block of the `DP × DP` row-major
/// `p`, for `D × W` row-major `C` and `X` (see `dense::sub_tr_mul_block`): row `A` of `P` is
/// held in registers while the `D` rows of `C` and `X` pass, each entry updated in increasing
/// `k` with the terms of `C_kA = 0` skipped, as in the general loop.
#[inline(never)]
pub(super) fn sub_tr_mul_lower<const D: usize, const W: usize, const DP: usize>(
    c: &[f64],
    x: &[f64],
    p: &mut [f64],
) {
    const { assert!(W <= 18 && W <= DP) };
    let (c, x, p) = (&c[..D * W], &x[..D * W], &mut p[..DP * DP]);
    macro_rules! each_row {
        ($($a:literal)*) => {
            $(
                if $a < W {
                    lower_row::<D, W, DP, $a>(c, x, p);
                }
            )*
        };
    }
    each_row!(0 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17);
}

/// Row `A` of [`sub_tr_mul_lower`] (its entries `0..=A`).
#[inline(always)]
fn lower_row<const D: usize, const W: usize, const DP: usize, const A: usize>(
    c: &[f64],
    x: &[f64],
    p: &mut [f64],
) {
    let row = &mut p[A * DP..A * DP + A + 1];
    let mut acc = [0.0; W];
    acc[..=A].copy_from_slice(row);
    for k in 0..D {
        let cka = c[k * W + A];
        if cka != 0.0 {
            let xk = &x[k * W..k * W + A + 1];
            for b in 0..=A {
                acc[b] -= cka * xk[b];
            }
        }
    }
    row.copy_from_slice(&acc[..=A]);
}

/// `x −= X y` for a `D × W` row-major `X` (see `dense::sub_mul`): `y` held in registers, each
/// row's sum from zero in increasing column order.
#[inline(never)]
pub(super) fn sub_mul<const D: usize, const W: usize>(xm: &[f64], y: &[f64], x: &mut [f64]) {
    let (xm, x) = (&xm[..D * W], &mut x[..D]);
    let mut yw = [0.0; W];
    yw.copy_from_slice(&y[..W]);
    for a in 0..D {
        let row = &xm[a * W..a * W + W];
        let mut sum = 0.0;
        for b in 0..W {
            sum += row[b] * yw[b];
        }
        x[a] -= sum;
    }
}

/// `out −= Cᵀ y` for a `D × W` row-major `C` (see `dense::sub_tr_mul`): `out` held in
/// registers, each entry updated in increasing `k`.
#[inline(never)]
pub(super) fn sub_tr_mul<const D: usize, const W: usize>(c: &[f64], y: &[f64], out: &mut [f64]) {
    let (c, y) = (&c[..D * W], &y[..D]);
    let mut acc = [0.0; W];
    acc.copy_from_slice(&out[..W]);
    for k in 0..D {
        let (yk, ck) = (y[k], &c[k * W..k * W + W]);
        for b in 0..W {
            acc[b] -= ck[b] * yk;
        }
    }
    out[..W].copy_from_slice(&acc);
}

/// `P A = L U` in place with partial pivoting (see `dense::lu`), step `K` of the elimination
/// a function of the constants `D` and `K`; `false` on a zero or non-finite pivot.
#[inline(never)]
pub(super) fn lu<const D: usize>(a: &mut [f64], piv: &mut [u16]) -> bool {
    const { assert!(D <= 21) };
    let (a, piv) = (&mut a[..D * D], &mut piv[..D]);
    macro_rules! steps {
        ($($k:literal)*) => {
            $(
                if $k < D && !lu_step::<D, $k>(a, piv) {
                    return false;
                }
            )*
        };
    }
    steps!(0 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18 19 20);
    true
}

/// Step `K` of [`lu`]: the pivot in column `K`, the rows swapped, the rows below eliminated
/// (the terms of a zero multiplier skipped).
#[inline(always)]
fn lu_step<const D: usize, const K: usize>(a: &mut [f64], piv: &mut [u16]) -> bool {
    let mut p = K;
    let mut best = a[K * D + K].abs();
    for i in K + 1..D {
        let v = a[i * D + K].abs();
        if v > best {
            best = v;
            p = i;
        }
    }
    piv[K] = p as u16;
    if !best.is_finite() || best == 0.0 {
        return false;
    }
    let (top, below) = a.split_at_mut((K + 1) * D);
    let row = &mut top[K * D..];
    if p != K {
        row.swap_with_slice(&mut below[(p - K - 1) * D..(p - K) * D]);
    }
    let inv = 1.0 / row[K];
    for r in below.chunks_exact_mut(D) {
        let l = r[K] * inv;
        r[K] = l;
        if l != 0.0 {
            for c in K + 1..D {
                r[c] -= l * row[c];
            }
        }
    }
    true
}
