//! The singular value decomposition `A = U Σ Vᵀ` (thin: `k = min(m, n)` columns of `U` and
//! rows of `Vᵀ`, `σ₁ ≥ … ≥ σ_k ≥ 0`), guarded.
//!
//! nalgebra's `SVD` can return wrong singular values when vectors are asked for
//! (dimforge/nalgebra#1172, open: the all-ones `3 × 5` matrix gets `σ₁ = 4.54` for
//! `√15 = 3.87`, with orthonormal `U` and `V`; here most rank-deficient inputs of a few rows,
//! tall or wide, reconstruct with errors of the order of `‖A‖` itself). Its result is
//! therefore checked by identities that hold for every matrix, with whichever vectors were
//! computed (`W` = `U` with `B = AᵀU`, or `W` = `V` with `B = A V`; `b_i` the columns of `B`):
//!
//! ```text
//! σ₁ ≥ … ≥ σ_k ≥ 0,   WᵀW = I,   A = U Bᵀ  or  A = B Vᵀ,
//! ‖b_i‖ = σ_i,   |b_iᵀ b_j| ≤ τ ‖A‖_F max(‖b_i‖, ‖b_j‖)  (i ≠ j)
//! ```
//!
//! the orthonormality to `10⁻⁹`, the others to `τ ‖A‖_F` with `τ = 10⁻¹¹` (a backward-stable
//! SVD meets them to `k ε`). They make every `σ_i` exact to `O(k τ) ‖A‖_F`: with `W`
//! orthonormal, `A`'s singular values are within `‖A − U Bᵀ‖₂` (`‖A − B Vᵀ‖₂`) of `B`'s, and
//! `BᵀB = diag(‖b_i‖²) + E` with `|E_ij| ≤ τ ‖A‖_F max(‖b_i‖, ‖b_j‖)` moves `‖b_i‖` by
//! `O(√k τ ‖A‖_F)`, a zero one included (the perturbation of a small eigenvalue of `BᵀB` is
//! second order in `E`). The callers decide ranks at `10⁻⁹ – 10⁻¹²` of `σ₁`, so the checks
//! are on the scale of `A`, not of `A`'s squares: identities on squares (`Σ σ_i² = ‖A‖_F²`,
//! `BᵀB = Σ²` to `10⁻⁹ ‖A‖_F²`, this module's first guard) let a zero singular value be
//! reported as `3·10⁻⁵ ‖A‖_F`, or a `10⁻⁵ ‖A‖_F` one as zero, and a rank be miscounted
//! (test `square_scale_identities_miss_a_wrong_rank`). A result that fails
//! is replaced by the one-sided Jacobi method (Hestenes): the columns of `A V` (of `Aᵀ` for
//! a wide `A`) are rotated pairwise until orthogonal, `V` accumulating the rotations; then
//! `σ_i = ‖(A V)_i‖` and `u_i = (A V)_i / σ_i` (a pair counts as orthogonal when
//! `|x_pᵀ x_q| ≤ √m ε ‖x_p‖ ‖x_q‖`, as in LAPACK's `dgesvj`), the columns of a zero `σ_i` completed to an
//! orthonormal `U`. Slower than bidiagonalization, unconditionally convergent and accurate
//! to a few units of rounding in `σ_i / σ₁` (Demmel and Veselić). A matrix with a non-finite
//! entry or one beyond `10¹⁵⁰` (whose squares overflow) gets `None`, as does a Jacobi sweep
//! limit reached: nalgebra's `svd` panics on NaN and iterates without end on infinite
//! entries, so no matrix reaches it unchecked. A matrix with no rows or no columns (on which
//! nalgebra's `svd` panics) gets `k = 0`: no singular values, `U` `m × 0`, `Vᵀ` `0 × n`.
//!
//! ## References
//! - J. Demmel, K. Veselić, "Jacobi's method is more accurate than QR", SIAM J. Matrix Anal.
//!   Appl. 13 (1992) 1204–1245.
//! - G. H. Golub, C. F. Van Loan, *Matrix Computations*, 4th ed. (2013), §8.6.3.

use nalgebra::{DMatrix, DVector, Dyn, SVD};

/// Tolerance of the orthonormality of nalgebra's `U` and `V` (module docs).
const CHECK: f64 = 1e-9;

/// Tolerance, relative to `‖A‖_F`, of the identities on the scale of `A` itself (module docs):
/// a backward-stable SVD meets them to `k ε`, a few hundred times below.
const TIGHT: f64 = 1e-11;

/// Largest number of Jacobi sweeps.
const SWEEPS: usize = 100;

/// The thin SVD of `m` with `U` if `compute_u` and `Vᵀ` if `compute_v`, singular values in
/// descending order; `None` for a non-finite or huge entry or a failed iteration. With neither
/// factor asked for, `V` is computed and checked, then dropped.
pub(crate) fn svd(m: DMatrix<f64>, compute_u: bool, compute_v: bool) -> Option<SVD<f64, Dyn, Dyn>> {
    // Entries beyond 1e150 square to overflow inside the bidiagonalization.
    if m.iter().any(|x| !(x.is_finite() && x.abs() <= 1e150)) {
        return None;
    }
    // nalgebra's `SVD` panics on a matrix with no rows or no columns: `k = 0`.
    if m.is_empty() {
        let (r, c) = m.shape();
        return Some(SVD {
            u: compute_u.then(|| DMatrix::zeros(r, 0)),
            v_t: compute_v.then(|| DMatrix::zeros(0, c)),
            singular_values: DVector::zeros(0),
        });
    }
    // Neither factor asked for: `V` is computed all the same, for the check.
    let checked = SVD::try_new(
        m.clone(),
        compute_u,
        compute_v || !compute_u,
        f64::EPSILON,
        10_000,
    )
    .filter(|s| holds(&m, s))
    .map(|mut s| {
        if !compute_v {
            s.v_t = None;
        }
        s
    });
    checked.or_else(|| {
        let mut s = jacobi(&m)?;
        if !compute_u {
            s.u = None;
        }
        if !compute_v {
            s.v_t = None;
        }
        Some(s)
    })
}

/// Whether `s` is a decomposition of `a` by the identities of the module docs.
fn holds(a: &DMatrix<f64>, s: &SVD<f64, Dyn, Dyn>) -> bool {
    let sv = &s.singular_values;
    if sv.iter().any(|x| !x.is_finite() || *x < 0.0) || (1..sv.len()).any(|i| sv[i - 1] < sv[i]) {
        return false;
    }
    let tol = TIGHT * a.norm().max(f64::MIN_POSITIVE);
    // `w` (U or V, `k` orthonormal columns) and `b = Aᵀ U` or `A V`: `A = U Bᵀ` or `B Vᵀ` to
    // `tol`, and `b`'s columns orthogonal with `‖b_i‖ = σ_i`.
    let images = |w: &DMatrix<f64>, b: &DMatrix<f64>, residual: DMatrix<f64>| {
        let k = sv.len();
        if w.ncols() != k || b.ncols() != k || residual.amax() > tol {
            return false;
        }
        let wtw = w.tr_mul(w);
        let btb = b.tr_mul(b);
        let norms: Vec<f64> = (0..k).map(|i| b.column(i).norm()).collect();
        (0..k).all(|i| {
            (norms[i] - sv[i]).abs() <= tol
                && (0..k).all(|j| {
                    let id = if i == j { 1.0 } else { 0.0 };
                    (wtw[(i, j)] - id).abs() <= CHECK
                        && (i == j || btb[(i, j)].abs() <= tol * norms[i].max(norms[j]))
                })
        })
    };
    if let Some(u) = &s.u {
        let b = a.tr_mul(u);
        let residual = a - u * b.transpose();
        if !images(u, &b, residual) {
            return false;
        }
    }
    if let Some(v_t) = &s.v_t {
        let b = a * v_t.transpose();
        let residual = a - &b * v_t;
        if !images(&v_t.transpose(), &b, residual) {
            return false;
        }
    }
    true
}

/// The one-sided Jacobi SVD of `a` (module docs), both factors computed.
fn jacobi(a: &DMatrix<f64>) -> Option<SVD<f64, Dyn, Dyn>> {
    let (m, n) = a.shape();
    if m < n {
        // Aᵀ = V Σ Uᵀ.
        let t = jacobi(&a.transpose())?;
        return Some(SVD {
            u: t.v_t.map(|v_t| v_t.transpose()),
            v_t: t.u.map(|u| u.transpose()),
            singular_values: t.singular_values,
        });
    }
    // m ≥ n: the columns of g = A V made orthogonal.
    let mut g = a.clone();
    let mut v = DMatrix::<f64>::identity(n, n);
    // Columns orthogonal to rounding (LAPACK's dgesvj: √m ε; a pair below it is left).
    let orthogonal = (m as f64).sqrt() * f64::EPSILON;
    // Columns below 10⁻² ε ‖A‖_F are zero to rounding: left alone (their `u` completed).
    let negligible = (1e-2 * f64::EPSILON).powi(2) * a.norm_squared();
    let mut converged = n < 2;
    for _ in 0..SWEEPS {
        if converged {
            break;
        }
        converged = true;
        for p in 0..n {
            for q in p + 1..n {
                let alpha = g.column(p).norm_squared();
                let beta = g.column(q).norm_squared();
                let gamma = g.column(p).dot(&g.column(q));
                if alpha <= negligible
                    || beta <= negligible
                    || gamma.abs() <= orthogonal * alpha.sqrt() * beta.sqrt()
                {
                    continue;
                }
                let zeta = (beta - alpha) / (2.0 * gamma);
                let t = zeta.signum() / (zeta.abs() + 1.0f64.hypot(zeta));
                let c = 1.0 / (1.0 + t * t).sqrt();
                let s = c * t;
                if s == 0.0 {
                    continue; // a rotation below rounding
                }
                converged = false;
                rotate(&mut g, p, q, c, s);
                rotate(&mut v, p, q, c, s);
            }
        }
    }
    if !converged {
        return None;
    }
    // Columns by descending norm.
    let norms: Vec<f64> = (0..n).map(|j| g.column(j).norm()).collect();
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&i, &j| norms[j].total_cmp(&norms[i]));
    let top = norms.iter().fold(0.0f64, |x, &y| x.max(y));
    let mut u = DMatrix::<f64>::zeros(m, n);
    let mut singular_values = DVector::<f64>::zeros(n);
    let mut filled = Vec::with_capacity(n);
    for (k, &j) in order.iter().enumerate() {
        if norms[j] > 0.0 && norms[j] > f64::EPSILON * top * n as f64 {
            u.set_column(k, &(g.column(j) / norms[j]));
            singular_values[k] = norms[j];
            filled.push(k);
        }
    }
    complete(&mut u, &filled);
    let v_t = DMatrix::from_fn(n, n, |k, c| v[(c, order[k])]);
    Some(SVD {
        u: Some(u),
        v_t: Some(v_t),
        singular_values,
    })
}

/// Columns `p`, `q` of `x` rotated: `(x_p, x_q) ← (c x_p − s x_q, s x_p + c x_q)`.
fn rotate(x: &mut DMatrix<f64>, p: usize, q: usize, c: f64, s: f64) {
    for r in 0..x.nrows() {
        let (xp, xq) = (x[(r, p)], x[(r, q)]);
        x[(r, p)] = c * xp - s * xq;
        x[(r, q)] = s * xp + c * xq;
    }
}

/// The columns of `u` not in `filled` (zero) replaced by unit vectors orthogonal to the others
/// (Gram–Schmidt on the coordinate axes, twice for orthogonality to rounding).
fn complete(u: &mut DMatrix<f64>, filled: &[usize]) {
    let (m, k) = u.shape();
    let mut done: Vec<usize> = filled.to_vec();
    let mut axis = 0;
    for col in (0..k).filter(|c| !filled.contains(c)) {
        while axis < m {
            let mut x = DVector::<f64>::zeros(m);
            x[axis] = 1.0;
            axis += 1;
            for _ in 0..2 {
                for &d in &done {
                    let proj = u.column(d).dot(&x);
                    x -= u.column(d) * proj;
                }
            }
            let norm = x.norm();
            if norm > 0.5 {
                u.set_column(col, &(x / norm));
                done.push(col);
                break;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `‖A − U Σ Vᵀ‖_max / ‖A‖_max` and the orthonormality defects of `U` and `V`.
    fn errors(a: &DMatrix<f64>, s: &SVD<f64, Dyn, Dyn>) -> (f64, f64, f64) {
        let (u, v_t) = (s.u.as_ref().unwrap(), s.v_t.as_ref().unwrap());
        let rec = u * DMatrix::from_diagonal(&s.singular_values) * v_t;
        let k = s.singular_values.len();
        let eye = DMatrix::<f64>::identity(k, k);
        (
            (rec - a).amax() / a.amax().max(f64::MIN_POSITIVE),
            (u.tr_mul(u) - &eye).amax(),
            (v_t * v_t.transpose() - &eye).amax(),
        )
    }

    /// Matrices on which nalgebra 0.33's SVD fails (rank deficient, tall and wide) and others.
    fn cases() -> Vec<DMatrix<f64>> {
        let mut lcg = crate::lcg::Lcg::new(7);
        let mut out = vec![
            DMatrix::from_element(3, 5, 1.0),
            DMatrix::from_element(5, 3, 1.0),
            DMatrix::from_row_slice(3, 3, &[1.0, 2.0, 2.0, 2.0, -1.0, -1.0, 2.0, 1.0, -1.0]),
            DMatrix::zeros(2, 4),
            DMatrix::from_row_slice(1, 1, &[-3.0]),
        ];
        for (r, c) in [(3, 5), (5, 3), (2, 7), (3, 6), (6, 6), (1, 4), (4, 1)] {
            for rank in [1, 2, r.min(c)] {
                let a = DMatrix::from_fn(r, rank, |_, _| lcg.unit() - 0.5);
                let b = DMatrix::from_fn(rank, c, |_, _| lcg.unit() - 0.5);
                out.push(a * b);
            }
        }
        out
    }

    #[test]
    fn decomposes_what_nalgebra_gets_wrong() {
        let mut wrong = 0;
        for a in cases() {
            if let Some(s) = SVD::try_new(a.clone(), true, true, f64::EPSILON, 10_000) {
                wrong += usize::from(errors(&a, &s).0 > 1e-6);
            }
            let s = svd(a.clone(), true, true).unwrap();
            let (rec, ou, ov) = errors(&a, &s);
            assert!(
                rec < 1e-12 && ou < 1e-12 && ov < 1e-12,
                "{a}: {rec:e} {ou:e} {ov:e}"
            );
            let sv = &s.singular_values;
            assert!(
                (1..sv.len()).all(|i| sv[i - 1] >= sv[i] && sv[i] >= 0.0),
                "{sv}"
            );
            // The all-ones m × n matrix has the one singular value √(m n).
            if a.iter().all(|&x| x == 1.0) {
                assert!((sv[0] - ((a.nrows() * a.ncols()) as f64).sqrt()).abs() < 1e-12);
                assert!(sv.iter().skip(1).all(|&x| x < 1e-12));
            }
        }
        // The guard is needed: nalgebra's own result is wrong on some of these.
        assert!(wrong > 0);
    }

    /// Results wrong on the scale the callers decide ranks at, which identities on squares
    /// (`Σ σ_i² = ‖A‖_F²`, `BᵀB = Σ²`, `WᵀW = I`, each to `10⁻⁹ ‖A‖_F²`) all accept: a zero
    /// singular value reported as `2·10⁻⁵` (rank 2 for a rank-1 matrix at the callers'
    /// `10⁻¹⁰` thresholds), and a `10⁻⁵` one reported as zero with `V` missing its direction
    /// (rank 1 for rank 2). The checks on the scale of `A` refuse both, with either factor.
    #[test]
    fn square_scale_identities_miss_a_wrong_rank() {
        let squares = |a: &DMatrix<f64>, s: &SVD<f64, Dyn, Dyn>| {
            let sv = &s.singular_values;
            let tol = 1e-9 * a.norm_squared();
            let gram = |w: &DMatrix<f64>, b: &DMatrix<f64>| {
                let k = sv.len();
                let (wtw, btb) = (w.tr_mul(w), b.tr_mul(b));
                (wtw - DMatrix::<f64>::identity(k, k)).amax() <= 1e-9
                    && (btb - DMatrix::from_diagonal(&sv.map(|x| x * x))).amax() <= tol
            };
            (sv.norm_squared() - a.norm_squared()).abs() <= tol
                && s.u.as_ref().is_none_or(|u| gram(u, &a.tr_mul(u)))
                && s.v_t
                    .as_ref()
                    .is_none_or(|v_t| gram(&v_t.transpose(), &(a * v_t.transpose())))
        };
        let too_many = (
            DMatrix::from_row_slice(2, 2, &[1.0, 0.0, 0.0, 0.0]),
            SVD {
                u: Some(DMatrix::identity(2, 2)),
                v_t: Some(DMatrix::identity(2, 2)),
                singular_values: DVector::from_vec(vec![1.0, 2e-5]),
            },
        );
        let too_few = (
            DMatrix::from_row_slice(2, 3, &[1.0, 0.0, 0.0, 0.0, 1e-5, 0.0]),
            SVD {
                u: Some(DMatrix::identity(2, 2)),
                v_t: Some(DMatrix::from_row_slice(
                    2,
                    3,
                    &[1.0, 0.0, 0.0, 0.0, 0.0, 1.0],
                )),
                singular_values: DVector::from_vec(vec![1.0, 0.0]),
            },
        );
        for (a, s) in [too_many, too_few] {
            let true_rank = svd(a.clone(), false, false)
                .unwrap()
                .singular_values
                .iter()
                .filter(|&&x| x > 1e-10)
                .count();
            let claimed = s.singular_values.iter().filter(|&&x| x > 1e-10).count();
            assert_ne!(true_rank, claimed, "{a}");
            for (cu, cv) in [(true, true), (true, false), (false, true)] {
                let mut one = s.clone();
                one.u = one.u.filter(|_| cu);
                one.v_t = one.v_t.filter(|_| cv);
                assert!(squares(&a, &one), "{a}: {cu} {cv}");
                // `U` alone cannot see the `V` missing `e₂` of `too_few`: its `σ₂ = ‖Aᵀu₂‖`
                // does.
                assert!(!holds(&a, &one), "{a}: {cu} {cv}");
            }
        }
    }

    /// Every result the guard returns meets its own identities, nalgebra's or Jacobi's, on
    /// rank-deficient, wide, tall, badly scaled and exactly singular inputs.
    #[test]
    fn what_is_returned_meets_the_identities() {
        let mut lcg = crate::lcg::Lcg::new(21);
        let mut all = cases();
        for (r, c) in [(3, 8), (8, 3), (7, 7), (12, 4)] {
            // Columns scaled from 1e-9 to 1e9 and rows from 1 to 1e-18.
            all.push(DMatrix::from_fn(r, c, |i, j| {
                (lcg.unit() - 0.5)
                    * 10f64.powi(3 * (j as i32 % 7) - 9)
                    * 10f64.powi(-6 * (i as i32 % 4))
            }));
        }
        for a in all {
            let s = svd(a.clone(), true, true).unwrap();
            assert!(holds(&a, &s), "{a}");
            let j = jacobi(&a).unwrap();
            assert!(holds(&a, &j), "{a}");
        }
    }

    #[test]
    fn one_factor_asked_for_is_checked_too() {
        for a in cases() {
            let full = svd(a.clone(), true, true).unwrap();
            for (cu, cv) in [(true, false), (false, true)] {
                let s = svd(a.clone(), cu, cv).unwrap();
                assert_eq!((s.u.is_some(), s.v_t.is_some()), (cu, cv));
                let d = (&s.singular_values - &full.singular_values).amax();
                assert!(d < 1e-12 * a.amax().max(1.0), "{a}: {d:e}");
            }
        }
    }

    #[test]
    fn jacobi_agrees_with_nalgebra_where_nalgebra_is_right() {
        let mut lcg = crate::lcg::Lcg::new(11);
        for (r, c) in [(4, 4), (6, 3), (3, 6), (8, 5)] {
            let a = DMatrix::from_fn(r, c, |_, _| lcg.unit() - 0.5);
            let ours = jacobi(&a).unwrap();
            let theirs = SVD::try_new(a.clone(), true, true, f64::EPSILON, 10_000).unwrap();
            assert!(holds(&a, &theirs));
            let d = (&ours.singular_values - &theirs.singular_values).amax();
            assert!(d < 1e-12, "{d:e}");
            let (rec, ou, ov) = errors(&a, &ours);
            assert!(rec < 1e-13 && ou < 1e-13 && ov < 1e-13);
        }
    }

    /// Shapes with no rows or no columns, and the zero matrix: no singular values (or zeros),
    /// no panic.
    #[test]
    fn empty_and_zero_shapes() {
        for (r, c) in [(0, 3), (3, 0), (0, 0), (1, 1), (2, 5)] {
            let a = DMatrix::<f64>::zeros(r, c);
            for (cu, cv) in [(true, true), (true, false), (false, true), (false, false)] {
                let s = svd(a.clone(), cu, cv).unwrap();
                assert_eq!(s.singular_values.len(), r.min(c));
                assert!(s.singular_values.iter().all(|&x| x == 0.0));
                assert!(holds(&a, &s));
            }
        }
    }

    #[test]
    fn refuses_non_finite_and_huge_entries() {
        for x in [f64::NAN, f64::INFINITY, 1e200] {
            let mut a = DMatrix::from_element(2, 3, 1.0);
            a[(1, 2)] = x;
            assert!(svd(a, true, true).is_none());
        }
    }

    #[test]
    fn projections_converge() {
        // `I − V Vᵀ` (module `verify::lexicographic`'s null-space basis): eigenvalues 0 and 1.
        let mut lcg = crate::lcg::Lcg::new(5);
        for (d, r) in [(5, 2), (8, 3), (12, 5), (3, 1)] {
            let b = DMatrix::from_fn(d, r, |_, _| lcg.unit() - 0.5);
            let q = b.qr().q();
            let p = DMatrix::<f64>::identity(d, d) - &q * q.transpose();
            let s = jacobi(&p).unwrap();
            let (rec, ou, ov) = errors(&p, &s);
            assert!(rec < 1e-12 && ou < 1e-12 && ov < 1e-12, "{d} {r}");
            assert!(svd(p, true, false).is_some());
        }
    }

    #[test]
    fn entries_far_below_the_others_converge() {
        // verify's multiplier choice on a ladder at rest: unit entries beside 1e-18 and
        // 1e-33 ones (rounding of zero components), whose products underflow.
        let mut lcg = crate::lcg::Lcg::new(9);
        for tiny in [1e-18, 1e-33, 1e-160, 1e-300] {
            let a = DMatrix::from_fn(6, 10, |r, c| match (r + 2 * c) % 5 {
                0 => 1.0,
                1 => -1.0,
                2 => tiny * (lcg.unit() - 0.5),
                _ => 0.0,
            });
            let s = svd(a.clone(), true, true).unwrap();
            let (rec, ou, ov) = errors(&a, &s);
            assert!(
                rec < 1e-12 && ou < 1e-12 && ov < 1e-12,
                "{tiny:e}: {rec:e} {ou:e} {ov:e}"
            );
        }
    }
}
