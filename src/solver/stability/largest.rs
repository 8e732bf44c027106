//! The scale of the stability verdict's tolerance `t = 10⁻¹⁰ max(λ̃, 1)`: an estimate `λ̃` of
//! the largest eigenvalue magnitude of the reduced Hessian `Ĥ` by a few Lanczos steps where
//! the spectrum is not computed exactly.
//!
//! From `v₁` (a fixed, nearly uniform unit vector), `k` steps of the Lanczos recurrence on `Ĥ`
//! (products `Ĥ x` through the factors of `Φ_u` and `W`; full reorthogonalization, the basis
//! being a dozen vectors at most) give the tridiagonal `T_k = V_kᵀ Ĥ V_k` with orthonormal
//! `V_k` and the residual `Ĥ V_k − V_k T_k = β_k v_{k+1} e_kᵀ`. With `θ` the Ritz value of
//! `T_k` of largest magnitude and `s` its unit eigenvector:
//!
//! ```text
//! λ̃ = |θ| ≤ |λ|max                       (Ritz values lie in [λ_min, λ_max]: Courant–Fischer)
//! some eigenvalue λ of Ĥ has |λ − θ| ≤ r,  r = β_k |s_k|   (Kahan–Parlett residual bound)
//! ```
//!
//! The steps stop at the first `k` with `r ≤ 0.1 |θ|` (or at 12, or an invariant subspace):
//! `λ̃` is then within 10 % of an eigenvalue of `Ĥ` and never above `|λ|max`. Lanczos
//! converges to the ends of the spectrum first. Measured against 80 steps (`|λ|max` to 10⁻⁴):
//! chains of 1,000 and 10,000 links (top eigenvalues a dense cluster) 5 products and
//! `λ̃ = 0.91 |λ|max`, the 1,000-rung ladder 4 and 0.93 (the former 12 steps of power
//! iteration, `‖Ĥ x₁₁‖` with `x₁₁ = Ĥ¹¹ v₁ / ‖Ĥ¹¹ v₁‖`, a lower bound too: 0.94 – 0.96). A tolerance needs no more: it separates eigenvalues resolved by the
//! factors (`10⁻¹² … 10⁻¹⁰ |λ|max`, `Spectrum::tolerance`) from rounding, and a factor of
//! 0.9 in `λ̃` moves it by as much.
//!
//! ## References
//! - B. N. Parlett, *The Symmetric Eigenvalue Problem*, SIAM (1998), §4.5 (residual bound),
//!   §12.4 (Kaniel–Paige convergence of the extreme Ritz values).

use super::eigen::symmetric_eigen;
use crate::solver::partition::Partition;
use crate::solver::system::{Eval, System};
use nalgebra::{DMatrix, DVector};

/// Lanczos steps at most.
const STEPS: usize = 12;
/// The relative residual `r / |θ|` at which the steps stop.
const RESOLVED: f64 = 0.1;

/// `λ̃`, the estimate of `|λ|max` of `Ĥ` at the point of `eval` with the `W` of the last block
/// assembly (module doc): at most [`STEPS`] products `Ĥ x`, fewer once resolved.
pub(crate) fn largest_eigenvalue(sys: &System, part: &Partition, eval: &Eval) -> f64 {
    largest_magnitude(part.independent.len(), |x| sys.reduced_apply(part, eval, x))
}

/// `λ̃` of the symmetric operator `apply` on `dof` coordinates (module doc). A non-finite
/// product gives a non-finite `λ̃` (the caller has no tolerance then).
pub(crate) fn largest_magnitude(dof: usize, apply: impl Fn(&DVector<f64>) -> DVector<f64>) -> f64 {
    lanczos_largest(dof, apply, STEPS, RESOLVED)
}

/// [`largest_magnitude`] with at most `steps` products, stopping at `r ≤ resolved |θ|`.
fn lanczos_largest(
    dof: usize,
    apply: impl Fn(&DVector<f64>) -> DVector<f64>,
    steps: usize,
    resolved: f64,
) -> f64 {
    if dof == 0 {
        return 0.0;
    }
    let mut v = DVector::from_fn(dof, |i, _| 1.0 + 0.1 * ((i * 7919 % 101) as f64 / 101.0));
    v /= v.norm();
    let mut basis = vec![v];
    let (mut alpha, mut beta) = (Vec::with_capacity(steps), Vec::with_capacity(steps));
    for k in 0..steps.min(dof) {
        let mut w = apply(&basis[k]);
        let a = w.dot(&basis[k]);
        if !a.is_finite() {
            return a.abs();
        }
        alpha.push(a);
        orthogonalize_twice(&mut w, &basis);
        let b = w.norm();
        beta.push(b);
        let (theta, r) = extreme_ritz(&alpha, &beta);
        if !theta.is_finite() || r <= resolved * theta.abs() || k + 1 == steps.min(dof) {
            return theta.abs();
        }
        basis.push(w / b);
    }
    unreachable!("the loop returns at its last step")
}

/// Full reorthogonalization of `w` against the Lanczos `basis`, twice, for an orthonormal basis
/// to rounding (Kahan's "twice is enough"): `w ← w − Σ_b (w · b) b`, basis vector by basis
/// vector.
pub(super) fn orthogonalize_twice(w: &mut DVector<f64>, basis: &[DVector<f64>]) {
    for _ in 0..2 {
        for b in basis {
            let c = w.dot(b);
            w.axpy(-c, b, 1.0);
        }
    }
}

/// The Lanczos tridiagonal `T_k`: diagonal `alpha`, off-diagonal `beta` (its first `k − 1`).
pub(super) fn tridiagonal(alpha: &[f64], beta: &[f64]) -> DMatrix<f64> {
    let k = alpha.len();
    DMatrix::from_fn(k, k, |i, j| {
        if i == j {
            alpha[i]
        } else if i + 1 == j || j + 1 == i {
            beta[i.min(j)]
        } else {
            0.0
        }
    })
}

/// The Ritz value of largest magnitude of the Lanczos tridiagonal `T_k` (diagonal `alpha`,
/// off-diagonal `beta`, `beta[k−1]` the residual's norm) and its residual bound
/// `r = β_k |s_k|`.
fn extreme_ritz(alpha: &[f64], beta: &[f64]) -> (f64, f64) {
    let k = alpha.len();
    let t = tridiagonal(alpha, beta);
    let (theta, s) = symmetric_eigen(&t);
    // Ascending: the largest magnitude is at one end.
    let i = if theta[k - 1].abs() >= theta[0].abs() {
        k - 1
    } else {
        0
    };
    (theta[i], (beta[k - 1] * s[(k - 1, i)]).abs())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// On a diagonal matrix with a dense top cluster (as the chains' stiff modes), `λ̃` is
    /// never above `|λ|max`, within 10 % of an eigenvalue, takes fewer than 12 products, and
    /// the negative end counts when it is the larger.
    #[test]
    fn a_lower_bound_within_the_residual() {
        let n = 400;
        for sign in [1.0, -1.0] {
            let d = DVector::from_fn(n, |i, _| {
                let x = i as f64 / n as f64;
                if i == 7 {
                    sign * 1e8
                } else {
                    1.0 + 9e7 * x * x
                }
            });
            let products = std::cell::Cell::new(0);
            let l = largest_magnitude(n, |x| {
                products.set(products.get() + 1);
                d.component_mul(x)
            });
            let top = d.amax();
            assert!(l <= top * (1.0 + 1e-12), "{l} above {top}");
            let nearest = d
                .iter()
                .map(|e| (e.abs() - l).abs())
                .fold(f64::MAX, f64::min);
            assert!(nearest <= RESOLVED * l, "{l}: no eigenvalue within 10 %");
            assert!(l >= 0.5 * top, "{l} far below {top}");
            assert!(products.get() < STEPS, "{} products", products.get());
        }
        // One coordinate: exact; zero: zero; non-finite: non-finite.
        let one = largest_magnitude(1, |x| x * -3.0);
        assert_eq!(one, 3.0);
        assert_eq!(largest_magnitude(5, |x| x * 0.0), 0.0);
        assert!(!largest_magnitude(5, |x| x * f64::NAN).is_finite());
    }
}
