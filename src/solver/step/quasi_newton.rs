//! The inverse-Hessian approximation `B ≈ Ĥ⁻¹` of BFGS and DFP in the current independent
//! coordinates, updated from a step `s` and the change `y` of the reduced gradient:
//! - BFGS: `B ← (I − ρ s yᵀ) B (I − ρ y sᵀ) + ρ s sᵀ`, `ρ = 1 / yᵀs`;
//! - DFP: `B ← B + s sᵀ / yᵀs − B y yᵀ B / yᵀ B y`.
//!
//! The first update rescales the identity to `(yᵀs / yᵀy) I` (Nocedal & Wright eq. 6.20); an
//! update with `yᵀs ≤ 0` (no positive curvature along `s`) is skipped.
//!
//! ## References
//! - J. Nocedal, S. J. Wright, *Numerical Optimization*, 2nd ed., Springer (2006), §6.1.
//! - R. Fletcher, M. J. D. Powell, A rapidly convergent descent method for minimization,
//!   *Computer Journal* 6 (1963) 163–168.

use crate::solver::options::Method;
use nalgebra::{DMatrix, DVector};

/// The inverse-Hessian approximation of BFGS / DFP in the current independent coordinates.
pub(crate) struct QuasiNewton {
    pub(crate) binv: DMatrix<f64>,
    /// No update yet: the first one rescales the identity (Nocedal & Wright eq. 6.20).
    pub(crate) fresh: bool,
}

impl QuasiNewton {
    /// The identity for BFGS / DFP; empty for Newton, which has no use for it (a dense
    /// `dof × dof` matrix would dominate time and memory on large models).
    pub(crate) fn new(dof: usize, method: Method) -> Self {
        let dim = if method == Method::Newton { 0 } else { dof };
        QuasiNewton {
            binv: DMatrix::identity(dim, dim),
            fresh: true,
        }
    }

    /// Updates `B` from the step `s` and the gradient change `y` (module docs).
    pub(crate) fn update(&mut self, method: Method, s: &DVector<f64>, y: &DVector<f64>) {
        quasi_newton_update(method, &mut self.binv, s, y, self.fresh);
        self.fresh = false;
    }
}

fn quasi_newton_update(
    method: Method,
    b: &mut DMatrix<f64>,
    s: &DVector<f64>,
    y: &DVector<f64>,
    first: bool,
) {
    let ys = y.dot(s);
    if ys <= 1e-14 * s.norm() * y.norm() || ys <= 0.0 {
        return;
    }
    if first {
        let n = b.nrows();
        *b = DMatrix::identity(n, n) * (ys / y.dot(y));
    }
    match method {
        Method::Bfgs => {
            let rho = 1.0 / ys;
            let by = &*b * y;
            let yby = y.dot(&by);
            // (I − ρ s yᵀ) B (I − ρ y sᵀ) + ρ s sᵀ, expanded.
            *b += (s * s.transpose()) * (rho * rho * yby + rho)
                - (&by * s.transpose() + s * by.transpose()) * rho;
        }
        Method::Dfp => {
            let by = &*b * y;
            let yby = y.dot(&by);
            *b += s * s.transpose() / ys - &by * by.transpose() / yby;
        }
        Method::Newton => {}
    }
}
