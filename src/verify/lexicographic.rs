//! The least-squares choice among the multipliers of dependent rows (module `held`): `z`
//! minimizing `‖a + A z‖₂`, then among those minimizers `‖b + B z‖₂`, then `‖z‖₂`, by the SVD
//! of `A` (its null space `N`) and then of `B N`.

use nalgebra::{DMatrix, DVector};

/// `z` minimizing `‖a + A z‖₂`, then among those minimizers `‖b + B z‖₂` (then `‖z‖₂`).
pub(super) fn lexicographic(
    a_mat: &DMatrix<f64>,
    a: &DVector<f64>,
    b_mat: &DMatrix<f64>,
    b: &DVector<f64>,
) -> DVector<f64> {
    let d = a_mat.ncols();
    // Stage 1: z₁ = −A⁺ a, and a basis N of the null space of A.
    let (z1, null) = if a_mat.nrows() == 0 {
        (DVector::zeros(d), DMatrix::identity(d, d))
    } else {
        let Some(svd) = crate::solver::svd::svd(a_mat.clone(), true, true) else {
            return DVector::from_element(d, f64::NAN);
        };
        let top = svd.singular_values.max();
        let eps = 1e-10 * top.max(1e-300);
        let z1 = svd.solve(&(-a), eps).unwrap_or_else(|_| DVector::zeros(d));
        // Rows of Vᵀ beyond the rank span the null space (all of them when d > rows).
        let v_t = svd.v_t.clone().unwrap_or_else(|| DMatrix::zeros(0, d));
        let rank = svd.singular_values.iter().filter(|&&s| s > eps).count();
        let full = DMatrix::<f64>::identity(d, d);
        // Complete the basis: N = I − V_r V_rᵀ, orthonormalized by its own SVD.
        let v_r = v_t.rows(0, rank).transpose();
        let proj = &full - &v_r * v_r.transpose();
        let Some(psvd) = crate::solver::svd::svd(proj, true, false) else {
            return DVector::from_element(d, f64::NAN);
        };
        let u = psvd.u.unwrap_or_else(|| DMatrix::zeros(d, 0));
        let cols: Vec<usize> = (0..psvd.singular_values.len())
            .filter(|&k| psvd.singular_values[k] > 0.5)
            .collect();
        let null = DMatrix::from_fn(d, cols.len(), |r, c| u[(r, cols[c])]);
        (z1, null)
    };
    if null.ncols() == 0 || b_mat.nrows() == 0 {
        return z1;
    }
    // Stage 2: y minimizing ‖b + B z₁ + B N y‖.
    let bn = b_mat * &null;
    let rhs = -(b + b_mat * &z1);
    let Some(svd) = crate::solver::svd::svd(bn, true, true) else {
        return DVector::from_element(null.ncols(), f64::NAN) * 0.0 + z1;
    };
    let eps = 1e-10 * svd.singular_values.max().max(1e-300);
    let y = svd
        .solve(&rhs, eps)
        .unwrap_or_else(|_| DVector::zeros(null.ncols()));
    z1 + null * y
}
