//! Tests of the full-pivoting partition against a permuted-index reference.

use super::*;

#[test]
fn detects_rank_and_redundant_row() {
    // Row 2 = row 0 + row 1.
    let j = DMatrix::from_row_slice(
        3,
        4,
        &[1.0, 2.0, 0.0, 0.0, 0.0, 1.0, 3.0, 0.0, 1.0, 3.0, 3.0, 0.0],
    );
    let p = partition(&j, &[1.0; 3], &[1.0; 4]);
    assert_eq!(p.dependent.len(), 2);
    assert_eq!(p.redundant.len(), 1);
    assert_eq!(p.independent.len(), 2);
    assert!(p.independent.contains(&3));
}

#[test]
fn full_pivot_picks_largest() {
    let j = DMatrix::from_row_slice(1, 3, &[0.1, -5.0, 2.0]);
    let p = partition(&j, &[1.0; 1], &[1.0; 3]);
    assert_eq!(p.dependent, vec![1]);
    assert_eq!(p.independent, vec![0, 2]);
}

/// The permuted-index formulation this module used before the in-place swaps and the
/// fused pivot search (kept as the reference the faster one must equal exactly).
fn reference(jac: &DMatrix<f64>, row_scale: &[f64], scale: &[f64]) -> Partition {
    let (m, n) = jac.shape();
    let mut a = jac.clone();
    for j in 0..n {
        a.column_mut(j).scale_mut(scale[j]);
    }
    for i in 0..m {
        a.row_mut(i).scale_mut(row_scale[i]);
    }
    let mut row_perm: Vec<usize> = (0..m).collect();
    let mut col_perm: Vec<usize> = (0..n).collect();
    let amax = amax(a.as_slice());
    let mut rank = 0;
    for k in 0..m.min(n) {
        let mut best = (k, k, 0.0);
        for jj in k..n {
            let c = col_perm[jj];
            for ii in k..m {
                let v = a[(row_perm[ii], c)].abs();
                if v > best.2 * (1.0 + 1e-9) {
                    best = (ii, jj, v);
                }
            }
        }
        if best.2 <= RANK_TOLERANCE * amax || best.2 == 0.0 {
            break;
        }
        row_perm.swap(k, best.0);
        col_perm.swap(k, best.1);
        let (pr, pc) = (row_perm[k], col_perm[k]);
        let piv = a[(pr, pc)];
        for ii in k + 1..m {
            let r = row_perm[ii];
            let f = a[(r, pc)] / piv;
            if f != 0.0 {
                for jj in k..n {
                    let c = col_perm[jj];
                    a[(r, c)] -= f * a[(pr, c)];
                }
            }
        }
        rank = k + 1;
    }
    Partition::of_pivots(&row_perm, &col_perm, rank)
}

/// The partition of `j` (row and column scales `rows`, `cols`) is the reference's: the
/// same dependent columns and rows in pivot order, independent columns, redundant rows.
fn same_pivots(j: &DMatrix<f64>, rows: &[f64], cols: &[f64], trial: usize) {
    let (a, b) = (partition(j, rows, cols), reference(j, rows, cols));
    assert_eq!(a.dependent, b.dependent, "trial {trial}");
    assert_eq!(a.independent, b.independent, "trial {trial}");
    assert_eq!(a.rows, b.rows, "trial {trial}");
    assert_eq!(a.redundant, b.redundant, "trial {trial}");
}

/// The in-place, fused elimination picks exactly the pivots of the reference (same rank,
/// same order of dependent columns and rows) on random matrices with ties, zero columns,
/// redundant rows and scaling.
#[test]
fn equals_the_permuted_index_reference() {
    let mut lcg = crate::lcg::Lcg::new(12345);
    let mut next = || lcg.unit();
    for trial in 0..2000 {
        let m = 1 + trial % 17;
        let n = 1 + (trial * 7) % 23;
        let mut j = DMatrix::from_fn(m, n, |_, _| {
            let x = next();
            // Many exact zeros and repeated magnitudes (pivot ties).
            if x < 0.3 {
                0.0
            } else if x < 0.5 {
                1.0
            } else if x < 0.6 {
                // Near-ties within the 1e-9 tie factor, and just outside it.
                1.0 + (x - 0.5) * 3e-8
            } else {
                (x - 0.75) * 4.0
            }
        });
        if m > 2 {
            // A redundant row.
            let r = j.row(0) * 2.0 - j.row(1);
            j.set_row(m - 1, &r);
        }
        let rows: Vec<f64> = (0..m).map(|_| 0.5 + next()).collect();
        let cols: Vec<f64> = (0..n)
            .map(|_| if next() < 0.5 { 1.0 } else { 0.3 })
            .collect();
        same_pivots(&j, &rows, &cols, trial);
    }
}

/// The same on larger sparse matrices shaped like a robot's `Φ_q` (a band of a few
/// nonzeros a row, blocks of 7 columns, exact ties, redundant rows): the elimination's
/// changed-row lists, the maxima kept in their rows and the search's skipped columns pick
/// the reference's pivots in every trial.
#[test]
fn equals_the_reference_on_sparse_jacobian_shapes() {
    let mut lcg = crate::lcg::Lcg::new(2026);
    let mut next = || lcg.unit();
    for trial in 0..300 {
        let bodies = 2 + trial % 13;
        let n = 7 * bodies;
        let m = 6 * bodies - trial % 3;
        let mut j = DMatrix::zeros(m, n);
        for r in 0..m {
            // A row on its body and the one before it, a few entries each.
            let b = (r / 6).min(bodies - 1);
            for body in [b.saturating_sub(1), b] {
                for c in 0..7 {
                    let x = next();
                    if x < 0.45 {
                        j[(r, 7 * body + c)] = if x < 0.15 {
                            1.0
                        } else if x < 0.2 {
                            -1.0
                        } else {
                            (x - 0.3) * 3.0
                        };
                    }
                }
            }
        }
        if m > 4 && trial % 4 == 0 {
            let r = j.row(1) * 0.5 + j.row(3);
            j.set_row(m - 2, &r);
        }
        let rows: Vec<f64> = (0..m)
            .map(|_| if next() < 0.5 { 1.0 } else { 2.0 })
            .collect();
        let cols: Vec<f64> = (0..n).map(|c| if c % 7 < 3 { 0.5 } else { 1.0 }).collect();
        same_pivots(&j, &rows, &cols, trial);
    }
}

/// The slice `amax` equals nalgebra's `DMatrix::amax` bit for bit (eight lanes where no entry
/// is a NaN, nalgebra's order where one is), and `abs_max` the plain scan (the first entry
/// above all before it, NaN passed over), on lengths around the chunks' with ties, zeros,
/// infinities and NaNs.
#[test]
fn amax_and_abs_max_equal_the_plain_scans() {
    let mut lcg = crate::lcg::Lcg::new(77);
    let mut next = || lcg.unit();
    for trial in 0..3000 {
        let len = trial % 37;
        let x: Vec<f64> = (0..len)
            .map(|_| {
                let u = next();
                match (u * 20.0) as usize {
                    0 if trial % 5 == 0 => f64::NAN,
                    1 if trial % 7 == 0 => f64::INFINITY,
                    2..=5 => 0.0,
                    6 => -0.0,
                    7..=9 => -2.5,
                    10..=11 => 2.5,
                    _ => (u - 0.6) * 8.0,
                }
            })
            .collect();
        let theirs = DMatrix::from_column_slice(len.max(1), (len > 0) as usize, &x).amax();
        assert_eq!(amax(&x).to_bits(), theirs.to_bits(), "trial {trial}: {x:?}");
        let (mut mx, mut at) = (0.0_f64, 3);
        for (i, v) in x.iter().enumerate() {
            if v.abs() > mx {
                (mx, at) = (v.abs(), 3 + i);
            }
        }
        let (a, b) = abs_max(&x, 3);
        assert_eq!((a.to_bits(), b), (mx.to_bits(), at), "trial {trial}: {x:?}");
    }
}
