//! The block kernels: the sizes unrolled by module `fixed` against the general loops (the same
//! operations in the same order: bit for bit), and what they compute against nalgebra.
use super::*;
use nalgebra::{DMatrix, DVector};

/// A pseudo-random `r × c` matrix in `[−1, 1)`.
fn sample(r: usize, c: usize, seed: u64) -> DMatrix<f64> {
    let mut lcg = crate::lcg::Lcg::new(seed);
    let mut next = || lcg.signed();
    DMatrix::from_fn(r, c, |_, _| next())
}

fn row_major(m: &DMatrix<f64>) -> Vec<f64> {
    m.transpose().as_slice().to_vec()
}

fn same_bits(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

/// A symmetric `d × d` KKT-like block: indefinite and nonsingular, with a zero trailing block
/// and a zero below the first pivot (so zeros in `L`, whose terms the solves skip), and the
/// upper triangle differing from the lower in its last bit (as after a Schur update of the
/// lower triangle): only the lower one may be read.
fn kkt_block(d: usize, seed: u64) -> Vec<f64> {
    let b = sample(d, d, seed);
    let mut a = &b + b.transpose() + DMatrix::identity(d, d) * 3.0;
    for i in d.div_ceil(2)..d {
        for j in d.div_ceil(2)..d {
            a[(i, j)] = 0.0;
        }
    }
    if d > 2 {
        a[(d - 1, 0)] = 0.0;
    }
    for i in 0..d {
        for j in 0..i {
            a[(j, i)] = f64::from_bits(a[(i, j)].to_bits() ^ 1);
        }
    }
    row_major(&a)
}

/// Right sides with a zero row and signed zeros.
fn right_sides(d: usize, w: usize, seed: u64) -> Vec<f64> {
    let mut x = row_major(&sample(d, w, seed));
    x[..w].iter_mut().for_each(|v| *v = 0.0);
    for i in (0..d).step_by(2) {
        x[i * w + w - 1] = -0.0;
    }
    x
}

#[test]
fn unrolled_ldlt_and_solves_are_the_general_loops_bit_for_bit() {
    for (d, ws) in [(8, [1, 7]), (13, [1, 7]), (14, [7, 18]), (27, [1, 7])] {
        let a = kkt_block(d, d as u64);
        let (mut f, mut g) = (a.clone(), a);
        let negative = ldlt(&mut f, d).expect("nonsingular");
        assert_eq!(Some(negative), ldlt_any(&mut g, d), "d {d}");
        assert!(negative > 0, "d {d}: indefinite");
        for i in 0..d {
            for j in 0..=i {
                assert_eq!(
                    f[i * d + j].to_bits(),
                    g[i * d + j].to_bits(),
                    "d {d} ({i}, {j})"
                );
            }
        }
        assert!(f[(d - 1) * d] == 0.0, "d {d}: a zero in L");
        for w in ws {
            let x0 = right_sides(d, w, 5 + d as u64);
            let (mut x, mut y) = (x0.clone(), x0);
            ldlt_solve(&f, d, &mut x, w);
            ldlt_solve_impl(&g, d, &mut y, w);
            assert!(same_bits(&x, &y), "d {d} w {w}");
        }
    }
}

#[test]
fn ldlt_solves_and_counts_negative_eigenvalues() {
    for d in [1, 6, 13, 27, 70] {
        let b = sample(d, d, d as u64);
        let a = &b + b.transpose();
        let mut f = row_major(&a);
        let negative = ldlt(&mut f, d).expect("nonsingular");
        let (eig, _) = crate::solver::eigen::symmetric_eigen(&a);
        assert_eq!(negative, eig.iter().filter(|&&x| x < 0.0).count());
        let x0 = DVector::from_fn(d, |i, _| (i as f64 + 1.0).sin());
        let mut x = (&a * &x0).as_slice().to_vec();
        ldlt_solve(&f, d, &mut x, 1);
        for i in 0..d {
            assert!((x[i] - x0[i]).abs() < 1e-8, "d {d}: {} vs {}", x[i], x0[i]);
        }
    }
}

#[test]
fn lu_solves_both_ways() {
    for d in [1, 6, 13, 20] {
        let a = sample(d, d, 7 + d as u64);
        let mut f = row_major(&a);
        let mut piv = vec![0u16; d];
        assert!(lu(&mut f, d, &mut piv));
        let x0 = DVector::from_fn(d, |i, _| (i as f64 + 2.0).cos());
        // Two right sides at once: x0 and 2 x0.
        let ax = &a * &x0;
        let mut x: Vec<f64> = (0..d).flat_map(|i| [ax[i], 2.0 * ax[i]]).collect();
        lu_solve(&f, &piv, d, &mut x, 2);
        let mut t = (a.transpose() * &x0).as_slice().to_vec();
        lu_solve_transpose(&f, &piv, d, &mut t);
        for i in 0..d {
            assert!((x[2 * i] - x0[i]).abs() < 1e-9);
            assert!((x[2 * i + 1] - 2.0 * x0[i]).abs() < 1e-9);
            assert!((t[i] - x0[i]).abs() < 1e-9);
        }
    }
}

/// The Schur update of the lower triangle is the full update's there, bit for bit, and leaves
/// the rest of the parent's block as it was; the full update is `p − Cᵀ X` to rounding.
#[test]
fn lower_schur_update_is_the_full_ones_lower_triangle() {
    for (d, w, dp) in [
        (13, 7, 13),
        (14, 7, 14),
        (14, 18, 27),
        (27, 7, 14),
        (9, 5, 11),
    ] {
        let mut c = right_sides(d, w, 1 + d as u64);
        c[w + 1] = 0.0;
        let x = row_major(&sample(d, w, 2 + w as u64));
        let p0 = row_major(&sample(dp, dp, 3));
        let (mut full, mut lower) = (p0.clone(), p0.clone());
        sub_tr_mul_block(&c, &x, &mut full, (d, w, dp), false);
        sub_tr_mul_block(&c, &x, &mut lower, (d, w, dp), true);
        let (cm, xm) = (
            DMatrix::from_row_slice(d, w, &c),
            DMatrix::from_row_slice(d, w, &x),
        );
        let product = cm.transpose() * xm;
        for a in 0..dp {
            for b in 0..dp {
                let at = a * dp + b;
                if a < w && b < w {
                    let expect = p0[at] - product[(a, b)];
                    assert!((full[at] - expect).abs() < 1e-12, "({d}, {w}) ({a}, {b})");
                } else {
                    assert_eq!(full[at].to_bits(), p0[at].to_bits());
                }
                let want = if b <= a { full[at] } else { p0[at] };
                assert_eq!(lower[at].to_bits(), want.to_bits(), "({d}, {w}) ({a}, {b})");
            }
        }
    }
}

/// The unrolled products (`x −= X y`, `out −= Cᵀ y`) and LU are the general loops bit for bit
/// (a zero multiplier, whose terms LU skips, and signed zeros included).
#[test]
fn unrolled_products_and_lu_are_the_general_loops_bit_for_bit() {
    for (d, w) in [
        (13, 7),
        (14, 7),
        (13, 13),
        (14, 14),
        (14, 18),
        (27, 7),
        (27, 27),
    ] {
        let xm = right_sides(d, w, 11 + d as u64);
        let (y, x0) = (right_sides(w, 1, 12), right_sides(d, 1, 13));
        let (mut x, mut g) = (x0.clone(), x0.clone());
        sub_mul(&xm, &y, &mut x, d, w);
        sub_mul_impl(&xm, &y, &mut g, d, w);
        assert!(same_bits(&x, &g), "sub_mul ({d}, {w})");
        let (mut out, mut h) = (y.clone(), y.clone());
        sub_tr_mul(&xm, &x0, &mut out, d, w);
        sub_tr_mul_impl(&xm, &x0, &mut h, d, w);
        assert!(same_bits(&out, &h), "sub_tr_mul ({d}, {w})");
    }
    for d in [6, 7, 13, 14, 21] {
        let mut a = row_major(&sample(d, d, 21 + d as u64));
        // Column 1 zero below the diagonal (zero multipliers where the first step leaves
        // them zero) and a signed zero.
        for i in 2..d {
            a[i * d + 1] = 0.0;
        }
        a[1] = -0.0;
        let (mut f, mut g) = (a.clone(), a);
        let (mut pf, mut pg) = (vec![0u16; d], vec![0u16; d]);
        assert!(lu(&mut f, d, &mut pf), "d {d}");
        assert!(lu_impl(&mut g, d, &mut pg), "d {d}");
        assert_eq!(pf, pg, "d {d}");
        assert!(same_bits(&f, &g), "lu d {d}");
    }
}

/// The unrolled row sums of `|K|` are the general loop's bit for bit, and they are the sums.
#[test]
fn unrolled_row_sums_are_the_general_loops_bit_for_bit() {
    use super::super::norm::{add_node, node_any};
    for (d, w) in [
        (13, 7),
        (13, 0),
        (14, 7),
        (14, 0),
        (8, 7),
        (27, 7),
        (14, 18),
        (27, 0),
    ] {
        let blk = kkt_block(d, 31 + d as u64);
        let c = right_sides(d, w.max(1), 32);
        let (own0, up0) = (
            row_major(&sample(d, 1, 33)),
            row_major(&sample(w.max(1), 1, 34)),
        );
        let (mut own, mut up) = (own0.clone(), up0.clone());
        let (mut own_g, mut up_g) = (own0.clone(), up0.clone());
        add_node(&blk, &c, &mut own, &mut up[..w], (d, w));
        node_any(&blk, &c, &mut own_g, &mut up_g[..w], (d, w));
        assert!(
            same_bits(&own, &own_g) && same_bits(&up, &up_g),
            "({d}, {w})"
        );
        for a in 0..d {
            let want = own0[a]
                + (0..d).map(|b| blk[a * d + b].abs()).sum::<f64>()
                + (0..w).map(|b| c[a * w + b].abs()).sum::<f64>();
            assert!((own[a] - want).abs() < 1e-12, "({d}, {w}) row {a}");
        }
        for b in 0..w {
            let want = up0[b] + (0..d).map(|a| c[a * w + b].abs()).sum::<f64>();
            assert!((up[b] - want).abs() < 1e-12, "({d}, {w}) column {b}");
        }
    }
}
