//! Symmetric eigendecomposition `A = V Λ Vᵀ`, guarded.
//!
//! nalgebra's `SymmetricEigen` can return an orthonormal `V` whose columns are paired with the
//! wrong eigenvalues (dimforge/nalgebra#1109; seen here on a 21 × 21 `JᵀJ`). Every eigenvalue
//! is therefore recomputed as the Rayleigh quotient `λ_i = v_iᵀ A v_i`, and the residual
//! `‖A V − V Λ‖` is checked (each `A v_i` formed once, for both); if it is still large the cyclic Jacobi method, slower but
//! unconditionally convergent, is used instead. A matrix with non-finite entries gets NaN
//! eigenvalues (the caller's tests then fail) rather than an endless iteration; the singular
//! value decomposition is guarded the same way (module `svd`).
//!
//! ## References
//! - G. H. Golub, C. F. Van Loan, *Matrix Computations*, 4th ed. (2013), §8.5 (Jacobi).

use nalgebra::{DMatrix, DVector};

/// Eigenvalues (ascending) and matching orthonormal eigenvectors (columns) of a symmetric `a`.
pub(crate) fn symmetric_eigen(a: &DMatrix<f64>) -> (DVector<f64>, DMatrix<f64>) {
    let n = a.nrows();
    if a.iter().any(|x| !x.is_finite()) {
        return (DVector::from_element(n, f64::NAN), DMatrix::identity(n, n));
    }
    // Bounded iterations: nalgebra's `new` iterates without limit.
    let guarded = nalgebra::SymmetricEigen::try_new(a.clone(), f64::EPSILON, 10_000)
        .and_then(|e| Some((rayleigh(a, &e.eigenvectors)?, e.eigenvectors)));
    let (vals, vecs) = guarded.unwrap_or_else(|| jacobi(a));
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&i, &j| vals[i].total_cmp(&vals[j]));
    let sorted_vals = DVector::from_fn(n, |i, _| vals[order[i]]);
    let sorted_vecs = DMatrix::from_fn(n, n, |r, c| vecs[(r, order[c])]);
    (sorted_vals, sorted_vecs)
}

/// The Rayleigh quotients `λ_i = v_iᵀ A v_i` of the columns of `vecs` if they are eigenvectors
/// of `a` (`‖A v_i − λ_i v_i‖∞ ≤ 10⁻⁹ ‖A‖_max`, each `A v_i` formed once) and orthonormal
/// (`VᵀV = I` to `10⁻⁹`); `None` otherwise.
fn rayleigh(a: &DMatrix<f64>, vecs: &DMatrix<f64>) -> Option<DVector<f64>> {
    let n = a.nrows();
    let scale = a.amax().max(f64::MIN_POSITIVE);
    let mut vals = DVector::zeros(n);
    let mut av = DVector::zeros(n);
    for i in 0..n {
        a.mul_to(&vecs.column(i), &mut av);
        let v = vecs.column(i);
        vals[i] = v.dot(&av);
        for r in 0..n {
            let x = (av[r] - v[r] * vals[i]).abs();
            // A NaN residual fails too.
            if x.is_nan() || x > 1e-9 * scale {
                return None;
            }
        }
    }
    // Orthonormal: n eigenpairs, none repeated, so the λ_i are the whole spectrum.
    let vtv = vecs.tr_mul(vecs);
    for i in 0..n {
        for j in 0..n {
            let id = if i == j { 1.0 } else { 0.0 };
            let x = (vtv[(i, j)] - id).abs();
            if x.is_nan() || x > 1e-9 {
                return None;
            }
        }
    }
    Some(vals)
}

/// Cyclic Jacobi rotations until the off-diagonal part is negligible.
fn jacobi(a: &DMatrix<f64>) -> (DVector<f64>, DMatrix<f64>) {
    let n = a.nrows();
    let mut m = a.clone();
    let mut v = DMatrix::identity(n, n);
    let total = a.norm().max(f64::MIN_POSITIVE);
    for _ in 0..100 {
        let mut off = 0.0;
        for p in 0..n {
            for q in p + 1..n {
                off += m[(p, q)] * m[(p, q)];
            }
        }
        if off.sqrt() <= 1e-15 * total {
            break;
        }
        for p in 0..n {
            for q in p + 1..n {
                let apq = m[(p, q)];
                if apq == 0.0 {
                    continue;
                }
                let theta = (m[(q, q)] - m[(p, p)]) / (2.0 * apq);
                let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
                let t = if theta == 0.0 { 1.0 } else { t };
                let c = 1.0 / (t * t + 1.0).sqrt();
                let s = t * c;
                for k in 0..n {
                    let (mkp, mkq) = (m[(k, p)], m[(k, q)]);
                    m[(k, p)] = c * mkp - s * mkq;
                    m[(k, q)] = s * mkp + c * mkq;
                }
                for k in 0..n {
                    let (mpk, mqk) = (m[(p, k)], m[(q, k)]);
                    m[(p, k)] = c * mpk - s * mqk;
                    m[(q, k)] = s * mpk + c * mqk;
                }
                for k in 0..n {
                    let (vkp, vkq) = (v[(k, p)], v[(k, q)]);
                    v[(k, p)] = c * vkp - s * vkq;
                    v[(k, q)] = s * vkp + c * vkq;
                }
            }
        }
    }
    (m.diagonal(), v)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check(a: &DMatrix<f64>) {
        let (vals, vecs) = symmetric_eigen(a);
        let r = (a * &vecs - &vecs * DMatrix::from_diagonal(&vals)).amax();
        assert!(r <= 1e-9 * a.amax(), "residual {r}");
        for i in 1..vals.len() {
            assert!(vals[i - 1] <= vals[i]);
        }
    }

    /// The 4 × 4 matrix of dimforge/nalgebra#1109, where `SymmetricEigen` pairs eigenvectors
    /// with the wrong eigenvalues.
    #[test]
    fn nalgebra_issue_1109_matrix() {
        let a = DMatrix::from_row_slice(
            4,
            4,
            &[
                -19884.07, -10.07188, 11.277279, -188560.63, -10.07188, 12.518197, 1.3770627,
                -102.97504, 11.277279, 1.3770627, 14.587362, 113.26099, -188560.63, -102.97504,
                113.26099, -1788112.3,
            ],
        );
        check(&a);
    }

    /// `diag(1, 2, 3)` with `e₁` listed twice in place of `e₂`: every residual is zero (the
    /// first guard, residuals alone, took it, and the spectrum `{1, 1, 3}`), but `V` is not
    /// orthonormal.
    #[test]
    fn a_repeated_eigenpair_is_refused() {
        let a = DMatrix::from_diagonal(&DVector::from_vec(vec![1.0, 2.0, 3.0]));
        let v = DMatrix::from_row_slice(3, 3, &[1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0]);
        let vals = DVector::from_vec(vec![1.0, 1.0, 3.0]);
        assert_eq!((&a * &v - &v * DMatrix::from_diagonal(&vals)).amax(), 0.0);
        assert!(rayleigh(&a, &v).is_none());
        assert_eq!(rayleigh(&a, &DMatrix::identity(3, 3)), Some(a.diagonal()));
        check(&a);
    }

    /// Rank-deficient `JᵀJ` (wide and tall `J`, all-ones, columns scaled from `10⁻⁹` to `10⁹`,
    /// entries of `10⁻¹⁸` beside 1): the result meets both identities (nalgebra's after its
    /// check, or Jacobi's) and its eigenvalues sum to the trace.
    #[test]
    fn rank_deficient_and_badly_scaled_gram_matrices() {
        let mut lcg = crate::lcg::Lcg::new(17);
        for (m, n) in [(1, 4), (3, 5), (5, 3), (2, 9), (9, 9), (4, 12)] {
            for kind in 0..4 {
                let j = DMatrix::from_fn(m, n, |r, c| match kind {
                    0 => 1.0,
                    1 => (lcg.unit() - 0.5) * 10f64.powi(3 * (c as i32 % 7) - 9),
                    2 if (r + c) % 3 == 0 => 1e-18 * (lcg.unit() - 0.5),
                    _ => lcg.unit() - 0.5,
                });
                let a = j.tr_mul(&j);
                check(&a);
                let (vals, vecs) = symmetric_eigen(&a);
                assert!(rayleigh(&a, &vecs).is_some(), "{m} × {n}, kind {kind}");
                assert!((vals.sum() - a.trace()).abs() <= 1e-12 * a.amax() * n as f64);
            }
        }
    }

    #[test]
    fn jacobi_agrees_on_random_matrices() {
        let mut lcg = crate::lcg::Lcg::new(3);
        for n in [1, 2, 5, 12] {
            let b = DMatrix::from_fn(n, n, |_, _| lcg.unit() - 0.5);
            let a = &b + b.transpose();
            check(&a);
            let (vals, vecs) = jacobi(&a);
            assert!((&a * &vecs - &vecs * DMatrix::from_diagonal(&vals)).amax() < 1e-10);
        }
    }
}
