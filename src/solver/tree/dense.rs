//! Small dense kernels on row-major blocks (`a[i · d + j]`, `d ≤ 14` on the tree, any `d` for
//! a border): symmetric `A = L D Lᵀ` without pivoting (its negative pivots count the negative
//! eigenvalues: Sylvester's law of inertia) and `P A = L U` with partial pivoting, in place,
//! with their solves. No allocation.
//!
//! A chain's and a ladder's block sizes (`d` = 8, 13, 14, 27) factor and solve by the
//! unrolled kernels of module `fixed`: the same operations on each entry in the same order
//! (the same results to the last bit; `dense_tests` checks them against the general loops
//! below); so do the products of the solves and the residual (`x −= X y`, `out −= Cᵀ y`),
//! the LU of `Φ_u`'s blocks (`d` = 6, 7, 13, 14, 21) and a chain's Schur update of a parent's
//! block, which writes only the lower triangle that [`ldlt`] reads.

use super::fixed;

/// `A = L D Lᵀ` in place (`L` unit lower below the diagonal, `D` on it) of the symmetric `d × d`
/// block `a` (its lower triangle read; the upper one is scratch: `Lᵀ` for the sizes of
/// module `fixed`); the number of negative pivots, or `None` on a zero or non-finite pivot.
pub(crate) fn ldlt(a: &mut [f64], d: usize) -> Option<usize> {
    match d {
        13 => fixed::ldlt::<13>(a),
        14 => fixed::ldlt::<14>(a),
        8 => fixed::ldlt::<8>(a),
        27 => fixed::ldlt::<27>(a),
        _ => ldlt_any(a, d),
    }
}

fn ldlt_any(a: &mut [f64], d: usize) -> Option<usize> {
    if d <= 64 {
        ldlt_with(a, d, &mut [0.0; 64])
    } else {
        ldlt_with(a, d, &mut vec![0.0; d])
    }
}

/// [`ldlt`] with the scratch `v` (at least `d` long).
#[inline(always)]
fn ldlt_with(a: &mut [f64], d: usize, v: &mut [f64]) -> Option<usize> {
    let (a, v) = (&mut a[..d * d], &mut v[..d]);
    let mut negative = 0;
    for j in 0..d {
        for k in 0..j {
            v[k] = a[j * d + k] * a[k * d + k];
        }
        let mut djj = a[j * d + j];
        for k in 0..j {
            djj -= a[j * d + k] * v[k];
        }
        if !djj.is_finite() || djj == 0.0 {
            return None;
        }
        a[j * d + j] = djj;
        negative += usize::from(djj < 0.0);
        for i in j + 1..d {
            let mut s = a[i * d + j];
            for k in 0..j {
                s -= a[i * d + k] * v[k];
            }
            a[i * d + j] = s / djj;
        }
    }
    Some(negative)
}

/// `x ← A⁻¹ x` for the factors of [`ldlt`]; `x` is `d × w` row-major (`w` right sides).
pub(crate) fn ldlt_solve(f: &[f64], d: usize, x: &mut [f64], w: usize) {
    // Constant sizes of a chain's and a ladder's blocks (module `fixed`).
    match (d, w) {
        (13, 1) => fixed::ldlt_solve::<13, 1>(f, x),
        (13, 7) => fixed::ldlt_solve::<13, 7>(f, x),
        (14, 1) => fixed::ldlt_solve::<14, 1>(f, x),
        (14, 7) => fixed::ldlt_solve::<14, 7>(f, x),
        (8, 1) => fixed::ldlt_solve::<8, 1>(f, x),
        (8, 7) => fixed::ldlt_solve::<8, 7>(f, x),
        // A ladder's super-nodes of the KKT matrix (module `merge`).
        (27, 1) => fixed::ldlt_solve::<27, 1>(f, x),
        (27, 7) => fixed::ldlt_solve::<27, 7>(f, x),
        (14, 18) => fixed::ldlt_solve::<14, 18>(f, x),
        _ => ldlt_solve_impl(f, d, x, w),
    }
}

#[inline(always)]
fn ldlt_solve_impl(f: &[f64], d: usize, x: &mut [f64], w: usize) {
    let (f, x) = (&f[..d * d], &mut x[..d * w]);
    for i in 0..d {
        for k in 0..i {
            let l = f[i * d + k];
            if l != 0.0 {
                for c in 0..w {
                    x[i * w + c] -= l * x[k * w + c];
                }
            }
        }
    }
    for i in 0..d {
        let p = 1.0 / f[i * d + i];
        for c in 0..w {
            x[i * w + c] *= p;
        }
    }
    for i in (0..d).rev() {
        for k in i + 1..d {
            let l = f[k * d + i];
            if l != 0.0 {
                for c in 0..w {
                    x[i * w + c] -= l * x[k * w + c];
                }
            }
        }
    }
}

/// `P A = L U` in place with partial pivoting (`piv[k]`: the row swapped into `k`); `false` on
/// a zero or non-finite pivot.
pub(crate) fn lu(a: &mut [f64], d: usize, piv: &mut [u16]) -> bool {
    match d {
        6 => fixed::lu::<6>(a, piv),
        7 => fixed::lu::<7>(a, piv),
        13 => fixed::lu::<13>(a, piv),
        14 => fixed::lu::<14>(a, piv),
        21 => fixed::lu::<21>(a, piv),
        _ => lu_impl(a, d, piv),
    }
}

#[inline(always)]
fn lu_impl(a: &mut [f64], d: usize, piv: &mut [u16]) -> bool {
    let (a, piv) = (&mut a[..d * d], &mut piv[..d]);
    for k in 0..d {
        let mut p = k;
        let mut best = a[k * d + k].abs();
        for i in k + 1..d {
            let v = a[i * d + k].abs();
            if v > best {
                best = v;
                p = i;
            }
        }
        piv[k] = p as u16;
        if !best.is_finite() || best == 0.0 {
            return false;
        }
        if p != k {
            for c in 0..d {
                a.swap(k * d + c, p * d + c);
            }
        }
        let inv = 1.0 / a[k * d + k];
        for i in k + 1..d {
            let l = a[i * d + k] * inv;
            a[i * d + k] = l;
            if l != 0.0 {
                for c in k + 1..d {
                    a[i * d + c] -= l * a[k * d + c];
                }
            }
        }
    }
    true
}

/// `x ← A⁻¹ x` for the factors of [`lu`]; `x` is `d × w` row-major.
pub(crate) fn lu_solve(f: &[f64], piv: &[u16], d: usize, x: &mut [f64], w: usize) {
    match (d, w) {
        (6, 1) => lu_solve_impl(f, piv, 6, x, 1),
        (7, 1) => lu_solve_impl(f, piv, 7, x, 1),
        (13, 1) => lu_solve_impl(f, piv, 13, x, 1),
        (13, 7) => lu_solve_impl(f, piv, 13, x, 7),
        // A ladder's super-nodes of `Φ_u` (module `merge`): the model's, the self-check's.
        (14, 1) => lu_solve_impl(f, piv, 14, x, 1),
        (21, 1) => lu_solve_impl(f, piv, 21, x, 1),
        // A body's block of `Φ_u` against all columns of `Φ_v` (the null-space basis of a
        // small tree, `TreeLu::solve_columns`).
        (6, _) => lu_solve_impl(f, piv, 6, x, w),
        (7, _) => lu_solve_impl(f, piv, 7, x, w),
        _ => lu_solve_impl(f, piv, d, x, w),
    }
}

#[inline(always)]
fn lu_solve_impl(f: &[f64], piv: &[u16], d: usize, x: &mut [f64], w: usize) {
    let (f, piv, x) = (&f[..d * d], &piv[..d], &mut x[..d * w]);
    for k in 0..d {
        let p = piv[k] as usize;
        if p != k {
            for c in 0..w {
                x.swap(k * w + c, p * w + c);
            }
        }
    }
    for i in 0..d {
        for k in 0..i {
            let l = f[i * d + k];
            if l != 0.0 {
                for c in 0..w {
                    x[i * w + c] -= l * x[k * w + c];
                }
            }
        }
    }
    for i in (0..d).rev() {
        for k in i + 1..d {
            let u = f[i * d + k];
            if u != 0.0 {
                for c in 0..w {
                    x[i * w + c] -= u * x[k * w + c];
                }
            }
        }
        let p = 1.0 / f[i * d + i];
        for c in 0..w {
            x[i * w + c] *= p;
        }
    }
}

/// `x ← A⁻ᵀ x` for the factors of [`lu`] (one right side): `Uᵀ y = x`, `Lᵀ z = y`, `x = Pᵀ z`.
pub(crate) fn lu_solve_transpose(f: &[f64], piv: &[u16], d: usize, x: &mut [f64]) {
    match d {
        6 => lu_solve_transpose_impl(f, piv, 6, x),
        7 => lu_solve_transpose_impl(f, piv, 7, x),
        14 => lu_solve_transpose_impl(f, piv, 14, x),
        21 => lu_solve_transpose_impl(f, piv, 21, x),
        _ => lu_solve_transpose_impl(f, piv, d, x),
    }
}

#[inline(always)]
fn lu_solve_transpose_impl(f: &[f64], piv: &[u16], d: usize, x: &mut [f64]) {
    let (f, piv, x) = (&f[..d * d], &piv[..d], &mut x[..d]);
    for i in 0..d {
        let mut s = x[i];
        for k in 0..i {
            s -= f[k * d + i] * x[k];
        }
        x[i] = s / f[i * d + i];
    }
    for i in (0..d).rev() {
        let mut s = x[i];
        for k in i + 1..d {
            s -= f[k * d + i] * x[k];
        }
        x[i] = s;
    }
    for k in (0..d).rev() {
        let p = piv[k] as usize;
        if p != k {
            x.swap(k, p);
        }
    }
}

/// `out −= Cᵀ y` for a `d × w` row-major `C`.
pub(crate) fn sub_tr_mul(c: &[f64], y: &[f64], out: &mut [f64], d: usize, w: usize) {
    match (d, w) {
        (13, 7) => fixed::sub_tr_mul::<13, 7>(c, y, out),
        (14, 7) => fixed::sub_tr_mul::<14, 7>(c, y, out),
        (14, 18) => fixed::sub_tr_mul::<14, 18>(c, y, out),
        (27, 7) => fixed::sub_tr_mul::<27, 7>(c, y, out),
        _ => sub_tr_mul_impl(c, y, out, d, w),
    }
}

#[inline(always)]
fn sub_tr_mul_impl(c: &[f64], y: &[f64], out: &mut [f64], d: usize, w: usize) {
    let (c, y, out) = (&c[..d * w], &y[..d], &mut out[..w]);
    for k in 0..d {
        let yk = y[k];
        for b in 0..w {
            out[b] -= c[k * w + b] * yk;
        }
    }
}

/// `x −= X y` for a `d × w` row-major `X`.
pub(crate) fn sub_mul(xm: &[f64], y: &[f64], x: &mut [f64], d: usize, w: usize) {
    match (d, w) {
        (13, 7) => fixed::sub_mul::<13, 7>(xm, y, x),
        (14, 7) => fixed::sub_mul::<14, 7>(xm, y, x),
        (13, 13) => fixed::sub_mul::<13, 13>(xm, y, x),
        (14, 14) => fixed::sub_mul::<14, 14>(xm, y, x),
        (14, 18) => fixed::sub_mul::<14, 18>(xm, y, x),
        (27, 7) => fixed::sub_mul::<27, 7>(xm, y, x),
        (27, 27) => fixed::sub_mul::<27, 27>(xm, y, x),
        _ => sub_mul_impl(xm, y, x, d, w),
    }
}

#[inline(always)]
fn sub_mul_impl(xm: &[f64], y: &[f64], x: &mut [f64], d: usize, w: usize) {
    let (xm, y, x) = (&xm[..d * w], &y[..w], &mut x[..d]);
    for a in 0..d {
        let mut sum = 0.0;
        for b in 0..w {
            sum += xm[a * w + b] * y[b];
        }
        x[a] -= sum;
    }
}

/// `p −= Cᵀ X` into the leading `w × w` block of the `dp × dp` row-major `p`, for `d × w`
/// row-major `C` and `X` (the Schur update of a parent's block); with `lower`, into its lower
/// triangle only (what [`ldlt`] reads).
pub(crate) fn sub_tr_mul_block(
    c: &[f64],
    x: &[f64],
    p: &mut [f64],
    (d, w, dp): (usize, usize, usize),
    lower: bool,
) {
    if lower {
        // A chain's sizes (module `fixed`; a ladder's measured slower that way).
        match (d, w, dp) {
            (13, 7, 13) => return fixed::sub_tr_mul_lower::<13, 7, 13>(c, x, p),
            (14, 7, 14) => return fixed::sub_tr_mul_lower::<14, 7, 14>(c, x, p),
            _ => {}
        }
    }
    match (d, w, dp) {
        (13, 7, 13) => sub_tr_mul_block_impl(c, x, p, (13, 7, 13), lower),
        (14, 7, 14) => sub_tr_mul_block_impl(c, x, p, (14, 7, 14), lower),
        (14, 18, 27) => sub_tr_mul_block_impl(c, x, p, (14, 18, 27), lower),
        (27, 7, 14) => sub_tr_mul_block_impl(c, x, p, (27, 7, 14), lower),
        _ => sub_tr_mul_block_impl(c, x, p, (d, w, dp), lower),
    }
}

#[inline(always)]
fn sub_tr_mul_block_impl(
    c: &[f64],
    x: &[f64],
    p: &mut [f64],
    (d, w, dp): (usize, usize, usize),
    lower: bool,
) {
    let (c, x, p) = (&c[..d * w], &x[..d * w], &mut p[..dp * dp]);
    for k in 0..d {
        for a in 0..w {
            let cka = c[k * w + a];
            if cka != 0.0 {
                for b in 0..if lower { a + 1 } else { w } {
                    p[a * dp + b] -= cka * x[k * w + b];
                }
            }
        }
    }
}

#[cfg(test)]
#[path = "dense_tests.rs"]
mod tests;
