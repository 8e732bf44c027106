//! The block kernels of module `dense` at the constant sizes of a chain's blocks (a body's
//! 13 or 14 unknowns, its 7 coordinates, its 6 × 6 block of `Φ_u`), on fixed-size arrays:
//! the same operations in the same order as the general loops (the same results to the last
//! bit), with every index known to be in range at compile time, so that the loops carry no
//! bounds checks and unroll.

/// The leading `R × C` row-major block of `a` as an array of rows.
#[inline(always)]
fn rows<const R: usize, const C: usize>(a: &[f64]) -> &[[f64; C]; R] {
    let (rows, _) = a[..R * C].as_chunks::<C>();
    rows.try_into().expect("R rows of C entries")
}

/// [`rows`], mutable.
#[inline(always)]
fn rows_mut<const R: usize, const C: usize>(a: &mut [f64]) -> &mut [[f64; C]; R] {
    let (rows, _) = a[..R * C].as_chunks_mut::<C>();
    rows.try_into().expect("R rows of C entries")
}

/// `dense::ldlt` of a `D × D` block.
#[inline(always)]
pub(super) fn ldlt<const D: usize>(a: &mut [f64]) -> Option<usize> {
    let a = rows_mut::<D, D>(a);
    let mut v = [0.0; D];
    let mut negative = 0;
    for j in 0..D {
        for k in 0..j {
            v[k] = a[j][k] * a[k][k];
        }
        let mut djj = a[j][j];
        for k in 0..j {
            djj -= a[j][k] * v[k];
        }
        if !djj.is_finite() || djj == 0.0 {
            return None;
        }
        a[j][j] = djj;
        negative += usize::from(djj < 0.0);
        for i in j + 1..D {
            let mut s = a[i][j];
            for k in 0..j {
                s -= a[i][k] * v[k];
            }
            a[i][j] = s / djj;
        }
    }
    Some(negative)
}

/// `dense::ldlt_solve` of a `D × D` factor with `W` right sides (row by row, as
/// `dense::ldlt_solve_rows`).
#[inline(always)]
pub(super) fn ldlt_solve<const D: usize, const W: usize>(f: &[f64], x: &mut [f64]) {
    let f = rows::<D, D>(f);
    let x = rows_mut::<D, W>(x);
    for i in 0..D {
        let mut acc = x[i];
        for k in 0..i {
            let l = f[i][k];
            if l != 0.0 {
                for c in 0..W {
                    acc[c] -= l * x[k][c];
                }
            }
        }
        x[i] = acc;
    }
    for i in (0..D).rev() {
        let mut acc = x[i];
        let p = 1.0 / f[i][i];
        for a in acc.iter_mut() {
            *a *= p;
        }
        for k in i + 1..D {
            let l = f[k][i];
            if l != 0.0 {
                for c in 0..W {
                    acc[c] -= l * x[k][c];
                }
            }
        }
        x[i] = acc;
    }
}

/// `dense::lu` of a `D × D` block.
#[inline(always)]
pub(super) fn lu<const D: usize>(a: &mut [f64], piv: &mut [u16]) -> bool {
    let a = rows_mut::<D, D>(a);
    let piv: &mut [u16; D] = (&mut piv[..D]).try_into().expect("D pivots");
    for k in 0..D {
        let mut p = k;
        let mut best = a[k][k].abs();
        for (i, row) in a.iter().enumerate().skip(k + 1) {
            let v = row[k].abs();
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
            a.swap(k, p);
        }
        let inv = 1.0 / a[k][k];
        let pivot_row = a[k];
        for row in a.iter_mut().skip(k + 1) {
            let l = row[k] * inv;
            row[k] = l;
            if l != 0.0 {
                for c in k + 1..D {
                    row[c] -= l * pivot_row[c];
                }
            }
        }
    }
    true
}

/// `dense::lu_solve` of a `D × D` factor with one right side.
#[inline(always)]
pub(super) fn lu_solve1<const D: usize>(f: &[f64], piv: &[u16], x: &mut [f64]) {
    let f = rows::<D, D>(f);
    let piv: &[u16; D] = piv[..D].try_into().expect("D pivots");
    let x: &mut [f64; D] = (&mut x[..D]).try_into().expect("D entries");
    for k in 0..D {
        let p = piv[k] as usize;
        if p != k {
            x.swap(k, p);
        }
    }
    for i in 0..D {
        for k in 0..i {
            let l = f[i][k];
            if l != 0.0 {
                x[i] -= l * x[k];
            }
        }
    }
    for i in (0..D).rev() {
        for k in i + 1..D {
            let u = f[i][k];
            if u != 0.0 {
                x[i] -= u * x[k];
            }
        }
        x[i] *= 1.0 / f[i][i];
    }
}

/// `dense::lu_solve_transpose` of a `D × D` factor.
#[inline(always)]
pub(super) fn lu_solve_transpose<const D: usize>(f: &[f64], piv: &[u16], x: &mut [f64]) {
    let f = rows::<D, D>(f);
    let piv: &[u16; D] = piv[..D].try_into().expect("D pivots");
    let x: &mut [f64; D] = (&mut x[..D]).try_into().expect("D entries");
    for i in 0..D {
        let mut s = x[i];
        for k in 0..i {
            s -= f[k][i] * x[k];
        }
        x[i] = s / f[i][i];
    }
    for i in (0..D).rev() {
        let mut s = x[i];
        for k in i + 1..D {
            s -= f[k][i] * x[k];
        }
        x[i] = s;
    }
    for k in (0..D).rev() {
        let p = piv[k] as usize;
        if p != k {
            x.swap(k, p);
        }
    }
}

/// `dense::sub_tr_mul` (`out −= Cᵀ y`) for a `D × W` coupling.
#[inline(always)]
pub(super) fn sub_tr_mul<const D: usize, const W: usize>(c: &[f64], y: &[f64], out: &mut [f64]) {
    let c = rows::<D, W>(c);
    let y: &[f64; D] = y[..D].try_into().expect("D entries");
    let out: &mut [f64; W] = (&mut out[..W]).try_into().expect("W entries");
    for k in 0..D {
        let yk = y[k];
        for b in 0..W {
            out[b] -= c[k][b] * yk;
        }
    }
}

/// `dense::sub_mul` (`x −= X y`) for a `D × W` matrix.
#[inline(always)]
pub(super) fn sub_mul<const D: usize, const W: usize>(xm: &[f64], y: &[f64], x: &mut [f64]) {
    let xm = rows::<D, W>(xm);
    let y: &[f64; W] = y[..W].try_into().expect("W entries");
    let x: &mut [f64; D] = (&mut x[..D]).try_into().expect("D entries");
    for a in 0..D {
        let mut sum = 0.0;
        for b in 0..W {
            sum += xm[a][b] * y[b];
        }
        x[a] -= sum;
    }
}

/// `dense::sub_tr_mul_block` (`P −= Cᵀ X` into the leading `W × W` block of the `DP × DP`
/// parent block).
#[inline(always)]
pub(super) fn sub_tr_mul_block<const D: usize, const W: usize, const DP: usize>(
    c: &[f64],
    x: &[f64],
    p: &mut [f64],
) {
    let c = rows::<D, W>(c);
    let x = rows::<D, W>(x);
    let p = rows_mut::<DP, DP>(p);
    for k in 0..D {
        for a in 0..W {
            let cka = c[k][a];
            if cka != 0.0 {
                for b in 0..W {
                    p[a][b] -= cka * x[k][b];
                }
            }
        }
    }
}
