//! `m += aᵀ b` for the path curvature's per-edge sums (module `path_hessian`: `a` the edge's
//! `a_i`, `b` its `K_l (ω_j, w_j)`, both `3 × dof`), skipping the pairs of columns whose
//! product is a zero that cannot change `m`.

use nalgebra::DMatrix;

/// `m += aᵀ b` (`a`, `b`: `3 × dof`; `m` without `−0` entries), nalgebra's
/// `m.gemm_tr(1.0, a, b, 1.0)` to the last bit, over the columns `b_j` that are not zero and
/// the range of columns `a_i` from the first to the last that is not zero. On a tree a column
/// of `Z` moves the bodies on one side of its joint only, so an edge's twists are zero for the
/// columns whose motion does not reach it (a chain of 20: about a third of the `dof²` pairs are left).
///
/// `gemm_tr` sets `m_ij = 1·(a_i · b_j) + 1·m_ij` (here `m_ij + a_i · b_j`: the same sum) with the three-term dot
/// `(a_0 b_0 + a_1 b_1) + a_2 b_2`. Where `a_i` or `b_j` is zero (`±0` entries) and the other
/// finite, the dot is `±0`, and `m_ij + ±0 = m_ij` (a sum is `−0` only when both terms are).
/// Where an entry of `a` or `b` is not finite, nothing is skipped.
pub(super) fn add_tr_product(
    m: &mut DMatrix<f64>,
    a: &nalgebra::Matrix3xX<f64>,
    b: &nalgebra::Matrix3xX<f64>,
) {
    let (a_s, b_s) = (a.as_slice(), b.as_slice());
    if !a_s.iter().chain(b_s).all(|v| v.is_finite()) {
        m.gemm_tr(1.0, a, b, 1.0);
        return;
    }
    let zero = |x: &[f64]| x.iter().all(|&v| v == 0.0);
    let Some(first) = a_s.chunks_exact(3).position(|c| !zero(c)) else {
        return;
    };
    let last = a_s.chunks_exact(3).rposition(|c| !zero(c)).unwrap_or(first);
    let rows = &a_s[3 * first..3 * last + 3];
    let dof = m.nrows();
    for (bj, mj) in b_s
        .chunks_exact(3)
        .zip(m.as_mut_slice().chunks_exact_mut(dof))
    {
        if zero(bj) {
            continue;
        }
        for (ai, mij) in rows.chunks_exact(3).zip(&mut mj[first..=last]) {
            let dot = ai[0] * bj[0] + ai[1] * bj[1] + ai[2] * bj[2];
            *mij += dot;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The product over the nonzero columns equals nalgebra's `gemm_tr` bit for bit, on
    /// columns with zeros of both signs, partly zero columns, `−0` products and a non-finite
    /// entry.
    #[test]
    fn tr_product_skipping_zero_columns_changes_no_bit() {
        let dof = 9;
        let mut lcg = crate::lcg::Lcg::new(7);
        let mut r = || lcg.signed();
        for trial in 0..4 {
            let mut a = nalgebra::Matrix3xX::from_fn(dof, |_, _| r());
            let mut b = nalgebra::Matrix3xX::from_fn(dof, |_, _| r());
            for j in [0, 3, 4] {
                a.column_mut(j).copy_from_slice(&[0.0, -0.0, 0.0]);
            }
            for j in [1, 4, 8] {
                b.column_mut(j).copy_from_slice(&[-0.0, -0.0, -0.0]);
            }
            // Partly zero columns and a product that is `−0`.
            a[(1, 5)] = 0.0;
            b[(0, 2)] = -0.0;
            a[(2, 6)] = -0.0;
            b[(2, 6)] = 0.0;
            if trial == 3 {
                b[(1, 7)] = f64::INFINITY;
            }
            let mut plain =
                DMatrix::from_fn(dof, dof, |i, j| if (i + j) % 3 == 0 { 0.0 } else { r() });
            let mut skipped = plain.clone();
            for _ in 0..2 {
                plain.gemm_tr(1.0, &a, &b, 1.0);
                add_tr_product(&mut skipped, &a, &b);
            }
            for (x, y) in plain.iter().zip(skipped.iter()) {
                assert!(
                    x.to_bits() == y.to_bits() || (x.is_nan() && y.is_nan()),
                    "trial {trial}: {x:e} against {y:e}"
                );
            }
            assert!(
                plain.iter().any(|&v| v == 0.0),
                "the test meets zero entries"
            );
        }
    }
}
