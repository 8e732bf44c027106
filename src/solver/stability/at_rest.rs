//! The curvature the minimizer needs at a point, and no more.
//!
//! The dense Newton direction uses the whole spectrum of `Ĥ`, and a small spectrum is exact
//! and cheap (module `spectrum`): those are computed as before (the dense path, and up to
//! `spectrum::LISTED_UP_TO` degrees of freedom on the sparse and tree paths, where the Newton
//! step forms `Ĥ` anyway; on a small tree away from a stationary point the minimizer asks
//! for `Ĥ` formed and not decomposed instead, module `step::path_cholesky`). Above, at a stationary point the minimizer only needs to know
//! whether the point is a saddle or a maximum it must leave: the inertia of the shifted KKT
//! matrix answers that (module `inertia`: `#{λ < −t}`, `t = 10⁻¹⁰ max(λ_max, 1)`) with one or
//! two LDLᵀ factorizations, and the spectrum (exact up to `spectrum::EXACT_UP_TO`, Lanczos
//! above) is computed only where it says `unstable` (its eigenvector of the negative
//! eigenvalue is the way out) or where it cannot be trusted. The verdict found on the way is
//! the rest's stability verdict (module `verdict`) unless eigenvalues are asked for.

use super::inertia::{inertia_verdict, ByInertia};
use super::spectrum::{listed, spectrum, spectrum_knowing, Spectrum};
use crate::solver::partition::Partition;
use crate::solver::report::Verdict;
use crate::solver::system::{Eval, System};
use nalgebra::DVector;

/// The spectrum the minimizer uses at `q` (dof > 0): exact where it is listed (dense path,
/// few degrees of freedom); else the inertia verdict first (stored in `verdict`), and the
/// spectrum only when that verdict is `unstable` and the minimizer is to leave
/// (`allow_unstable` false), or when the inertia cannot be trusted. The spectrum after an
/// inertia verdict takes its `λ_max` (the same estimate at the same point: module `largest`).
pub(crate) fn for_minimizer(
    sys: &mut System,
    q: &DVector<f64>,
    part: &Partition,
    eval: &Eval,
    allow_unstable: bool,
    verdict: &mut Option<ByInertia>,
) -> Option<Spectrum> {
    *verdict = None;
    if listed(sys.backend, part.independent.len()) {
        return Some(spectrum(sys, q, part, eval));
    }
    match inertia_verdict(sys, q, part, eval) {
        Some(found) => {
            *verdict = Some(found);
            (found.verdict == Verdict::Unstable && !allow_unstable)
                .then(|| spectrum_knowing(sys, q, part, eval, Some(found.largest)))
        }
        None => Some(spectrum(sys, q, part, eval)),
    }
}
