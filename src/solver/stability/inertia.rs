//! The stability verdict from the inertia of the shifted KKT matrix, without eigenvalues.
//!
//! With `Ŵ` the scaled Lagrangian Hessian, `Â` the scaled Jacobian of the partition's
//! independent rows (`m` of them, full row rank) and `Z = [−Â_u⁻¹ Â_v; I]` the null-space
//! basis whose independent block is the identity, the reduced Hessian is `Ĥ = Zᵀ Ŵ Z` and
//! `Zᵀ E_v Z = I` (`E_v` the selector of the independent coordinates). So the KKT matrix
//! shifted on the independent coordinates only,
//!
//! ```text
//! K(σ) = [ Ŵ − σ E_v   Âᵀ ]      In(K(σ)) = In(Zᵀ (Ŵ − σ E_v) Z) + (m, m, 0)
//!        [ Â           0  ],                = In(Ĥ − σ I) + (m, m, 0)
//! ```
//!
//! (Sylvester's law of inertia with Haynsworth's additivity over the constraint block): the
//! number of negative pivots of its LDLᵀ minus `m` is exactly the number of eigenvalues of `Ĥ`
//! below `σ`. The verdict of [`Stability`](crate::solver::Stability) with tolerance `t = 10⁻¹⁰ max(λ_max, 1)`
//! (`λ_max` estimated by a few Lanczos steps on `Ĥ`, never above `|λ|max`: module `largest`,
//! as on the Lanczos path) then needs one or two factorizations:
//!
//! - `#{λ < t} = 0`: **stable** (every eigenvalue above the tolerance);
//! - else `#{λ < −t} > 0`: **unstable**;
//! - else **neutral** (the lowest eigenvalue within `±t`).
//!
//! This is the definition the eigenvalue path applies to the lowest eigenvalue
//! (`λ_min > t`, `λ_min < −t`, otherwise neutral), with the count exact instead of found by
//! Lanczos. The `Φ_qᵀ D R D Φ_q` added to `W` before factoring (`System::factor_kkt`) vanishes
//! on `Z` and changes nothing here. An LDLᵀ without pivoting may be inaccurate (a tiny pivot
//! before the rows that would cure it): each factorization is accepted only when a probe solve
//! with it reaches a backward error of `10⁻¹⁰` (as for the Lanczos path's inertia count);
//! otherwise, or with a zero pivot (LU fall-back, no inertia), there is no inertia verdict and
//! the caller computes the eigenvalues instead.
//!
//! ## References
//! - E. V. Haynsworth, "Determination of the inertia of a partitioned Hermitian matrix",
//!   *Linear Algebra Appl.* 1 (1968) 73–81.
//! - N. I. M. Gould, "On practical conditions for the existence and uniqueness of solutions
//!   to the general equality quadratic programming problem", *Math. Program.* 32 (1985).

use super::largest::largest_eigenvalue;
use crate::solver::partition::Partition;
use crate::solver::report::Verdict;
use crate::solver::sparse::kkt::Factored;
use crate::solver::system::{Eval, System};
use nalgebra::DVector;

/// A verdict by inertia: the verdict, its tolerance `t = 10⁻¹⁰ max(λ_max, 1)`, and the
/// estimate `λ_max` it came from (module `largest`) (the spectrum at the same point, if it is wanted after
/// all, takes it instead of iterating again: `spectrum::spectrum_knowing`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct ByInertia {
    pub(crate) verdict: Verdict,
    pub(crate) tolerance: f64,
    pub(crate) largest: f64,
}

/// The verdict from the KKT inertia at a feasible `q` of the sparse or tree path; `None`
/// when the shifted LDLᵀ cannot be trusted (module doc).
pub(crate) fn inertia_verdict(
    sys: &mut System,
    q: &DVector<f64>,
    part: &Partition,
    eval: &Eval,
) -> Option<ByInertia> {
    let largest = largest_at(sys, q, part, eval);
    inertia_verdict_knowing(sys, q, part, largest, false)
}

/// The first half of [`inertia_verdict`], the only one that reads `eval` (its factors of
/// `Φ_u`): `W` (augmented, as the KKT matrix takes it) into the block Hessian and `λ_max`
/// of `Ĥ` (module `largest`). A caller that owns `eval` may free it before the second half
/// ([`inertia_verdict_knowing`]), whose KKT matrix then reuses its memory (`verify`).
pub(crate) fn largest_at(sys: &mut System, q: &DVector<f64>, part: &Partition, eval: &Eval) -> f64 {
    sys.kkt_blocks(q, part, eval);
    largest_eigenvalue(sys, part, eval)
}

/// The second half of [`inertia_verdict`], from `λ_max` = `largest` ([`largest_at`] at the
/// same point, the block Hessian it left unchanged). With `free_blocks` the block Hessian is
/// freed once the KKT matrix is assembled from it, before the first factorization, whose
/// factors then reuse its memory (fewer fresh pages: `verify`, whose system assembles
/// nothing after its verdict; a later assembly builds the blocks again).
pub(crate) fn inertia_verdict_knowing(
    sys: &mut System,
    q: &DVector<f64>,
    part: &Partition,
    largest: f64,
    free_blocks: bool,
) -> Option<ByInertia> {
    // The KKT matrix of those blocks; only its shifted factorizations are needed (the
    // unshifted one is singular where the pose is neutral).
    if !sys.assemble_kkt_of_blocks(q, part) {
        return None;
    }
    if free_blocks {
        sys.work.hess = Default::default();
    }
    let tol = 1e-10 * largest.max(1.0);
    if !tol.is_finite() {
        return None;
    }
    let judged = |verdict| {
        Some(ByInertia {
            verdict,
            tolerance: tol,
            largest,
        })
    };
    if eigenvalues_below(sys, part, tol)? == 0 {
        return judged(Verdict::Stable);
    }
    if eigenvalues_below(sys, part, -tol)? > 0 {
        judged(Verdict::Unstable)
    } else {
        judged(Verdict::Neutral)
    }
}

/// The number of eigenvalues of the reduced Hessian below `sigma`, from the KKT matrix last
/// assembled by `System::factor_kkt`, shifted by `−sigma` on the independent coordinates;
/// `None` if its LDLᵀ fails or does not solve accurately.
pub(crate) fn eigenvalues_below(sys: &mut System, part: &Partition, sigma: f64) -> Option<usize> {
    let kkt = sys.work.kkt.as_mut()?;
    kkt.shift_independent(&part.independent, sigma);
    let Factored::Ldlt { negative } = kkt.factor(0.0) else {
        return None;
    };
    let n = kkt.coordinates();
    let mut probe = vec![0.0; n + kkt.rows()];
    for &c in &part.independent {
        probe[c] = 1.0;
    }
    if !kkt.solve(&mut probe, 1e-13) {
        return None;
    }
    negative.checked_sub(kkt.rows())
}

#[cfg(test)]
mod tests;
