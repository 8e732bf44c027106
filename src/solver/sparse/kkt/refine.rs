//! Solves with the KKT factors: one triangular solve pair (LDLᵀ, or LU after a fall-back),
//! then iterative refinement `x ← x + K⁻¹ (b − K x)` with the stored upper triangle, until the
//! normwise backward error `ω = ‖b − K x‖∞ / (‖K‖∞ ‖x‖∞ + ‖b‖∞)` reaches its target.

use super::{Factored, Kkt};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::solvers::SolveCore;
use faer::sparse::linalg::cholesky::LdltRef;
use faer::{Conj, MatMut, Par};

/// Buffers reused by every [`Kkt::solve`].
#[derive(Default)]
pub(super) struct SolveScratch {
    pub(super) stack: Option<MemBuffer>,
    /// The solution in permuted order.
    pub(super) x: Vec<f64>,
    pub(super) b: Vec<f64>,
    pub(super) r: Vec<f64>,
}

impl Kkt {
    fn solve_once(&self, x: &mut [f64], stack: &mut Option<MemBuffer>) {
        let len = x.len();
        let m = MatMut::from_column_major_slice_mut(x, len, 1);
        match (self.kind, &self.lu, &self.ldlt, stack) {
            (Factored::Ldlt { .. }, _, Some(sym), Some(buf)) => {
                LdltRef::new(sym, &self.ldlt_values).solve_in_place_with_conj(
                    Conj::No,
                    m,
                    Par::Seq,
                    MemStack::new(buf),
                );
            }
            (Factored::Lu, Some(lu), _, _) => lu.solve_in_place_with_conj(Conj::No, m),
            _ => x.iter_mut().for_each(|v| *v = f64::NAN),
        }
    }

    /// Solves with the last factors in place (`rhs` of length `n + rows`), with iterative
    /// refinement (`x += K⁻¹ (b − K x)`, which recovers the digits lost to the pivot order)
    /// until the normwise backward error `ω = ‖b − K x‖∞ / (‖K‖∞ ‖x‖∞ + ‖b‖∞)` is below
    /// `target` (at most three steps); `false` if singular or if `ω` stays above 10⁻¹⁰.
    pub(crate) fn solve(&self, rhs: &mut [f64], target: f64) -> bool {
        let mut scratch = self.solve_scratch.borrow_mut();
        let SolveScratch { stack, x, b, r } = &mut *scratch;
        // Into the permuted order of the stored matrix.
        b.clear();
        b.extend(self.perm.iter().map(|&o| rhs[o]));
        x.clear();
        x.extend_from_slice(b);
        let bnorm = b.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        self.solve_once(x, stack);
        let sym = self.pattern.symbolic();
        let (ptr, idx) = (sym.col_ptr(), sym.row_idx());
        let knorm = self.knorm;
        let mut omega = f64::INFINITY;
        for _ in 0..3 {
            r.clear();
            r.extend_from_slice(b);
            // r −= K x from the upper triangle: column c gives `K[i, c] x[c]` to rows `i` and,
            // by symmetry, `Σ_i K[i, c] x[i]` to row `c` (the diagonal, the column's last
            // entry when present, only once).
            for c in 0..x.len() {
                let (a, b) = (ptr[c] as usize, ptr[c + 1] as usize);
                let xc = x[c];
                let mut sum = 0.0;
                for k in a..b {
                    let (i, v) = (idx[k] as usize, self.values[k]);
                    r[i] -= v * xc;
                    sum += v * x[i];
                }
                if b > a && idx[b - 1] as usize == c {
                    sum -= self.values[b - 1] * xc;
                }
                r[c] -= sum;
            }
            let rnorm = r.iter().fold(0.0f64, |a, v| a.max(v.abs()));
            let xnorm = x.iter().fold(0.0f64, |a, v| a.max(v.abs()));
            omega = rnorm / (knorm * xnorm + bnorm).max(f64::MIN_POSITIVE);
            if !omega.is_finite() || omega <= target {
                break;
            }
            self.solve_once(r, stack);
            for (x, d) in x.iter_mut().zip(r.iter()) {
                *x += d;
            }
        }
        for (k, &o) in self.perm.iter().enumerate() {
            rhs[o] = x[k];
        }
        rhs.iter().all(|x| x.is_finite()) && omega <= 1e-10
    }
}
