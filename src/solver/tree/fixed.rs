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
