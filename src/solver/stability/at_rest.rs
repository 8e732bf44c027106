//! The curvature the minimizer needs at a point, and no more.
//!
//! The dense Newton direction uses the whole spectrum of `Ĥ`, and a small spectrum is exact
//! and cheap (module `spectrum`): those are computed as before. At a stationary point with many
//! degrees of freedom (Lanczos path) the minimizer only needs to know whether the point is a
//! saddle or a maximum it must leave: the inertia of the shifted KKT matrix answers that
//! (module `inertia`: `#{λ < −t}`, `t = 10⁻¹⁰ max(λ_max, 1)`) with one or two LDLᵀ
//! factorizations, and Lanczos runs only where it says `unstable` (its eigenvector of the
//! negative eigenvalue is the way out) or where it cannot be trusted. The verdict found on the
//! way is the rest's stability verdict (module `verdict`) unless eigenvalues are asked for.

use super::inertia::inertia_verdict;
use super::spectrum::{exact, spectrum, Spectrum};
use crate::solver::partition::Partition;
use crate::solver::report::Verdict;
use crate::solver::system::{Eval, System};
use nalgebra::DVector;

/// The spectrum the minimizer uses at `q` (dof > 0): exact where it is cheap; on the Lanczos
/// path the inertia verdict first (stored in `verdict`), and the Lanczos spectrum only when
/// that verdict is `unstable` and the minimizer is to leave (`allow_unstable` false), or
/// when the inertia cannot be trusted.
pub(crate) fn for_minimizer(
    sys: &mut System,
    q: &DVector<f64>,
    part: &Partition,
    eval: &Eval,
    allow_unstable: bool,
    verdict: &mut Option<(Verdict, f64)>,
) -> Option<Spectrum> {
    *verdict = None;
    if exact(sys.backend, part.independent.len()) {
        return Some(spectrum(sys, q, part, eval));
    }
    match inertia_verdict(sys, q, part, eval) {
        Some(found) => {
            *verdict = Some(found);
            (found.0 == Verdict::Unstable && !allow_unstable).then(|| spectrum(sys, q, part, eval))
        }
        None => Some(spectrum(sys, q, part, eval)),
    }
}
