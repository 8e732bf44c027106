//! The dense Newton step along the search path with the escape from maxima and saddles
//! (module `newton`): where the path keeps every row (module `path_hessian`), `Ĥ + C` is the
//! energy's Hessian in the joint coordinates, and near a stationary point (`‖s‖∞ < 0.1 max_step`)
//! every direction of negative curvature `v_i` is stepped along by at least
//! `t_i = max_step / ‖v_i‖∞`.
//!
//! A direction is escaped along only where the energy along the path does fall: the trial
//! point `R(q, t_i v_i)` (the capped step along `v_i` alone, module `retraction`) must lower
//! `V` by at least half the quadratic model's decrease `−(t_i v_iᵀ∇f + ½ λ_i t_i²)` and cross
//! no inactive stop or contact of the round's guard; else the other sign is tried, and if
//! neither qualifies the direction keeps its magnitude step. Near-neutral directions that are
//! slightly negative on the way (human, iCub: `λ` at 10⁻⁵ … 10⁻¹⁰ of the largest) fail the
//! energy test and are left alone (escaping them took human 36 → 44 iterations). On a maximum the slope is at rounding level and says nothing about the side to
//! fall to; the stop test does: a finger pointing up with 0.2 rad before its back stop and
//! 1.6 rad before its front one falls forward (the Allegro hands of example-robot-data rest
//! where they did, 0.06 and 0.12 J lower than on their back stops).
//!
//! In the round after a release of several stops decided by the step (the guard's `falling`,
//! module `inequality::release_trial`) the escape is looked for at every iterate, not only
//! near a stationary point (module `newton`).

use crate::forces::potential;
use crate::solver::inequality::active_set::Guard;
use crate::solver::options::Options;
use crate::solver::partition::Partition;
use crate::solver::stability::spectrum::Spectrum;
use crate::solver::step::newton::{newton_step_within, NEAR_STATIONARY};
use crate::solver::step::path_hessian::along_path;
use crate::solver::step::step_cap::cap_step;
use crate::solver::system::{Eval, System};
use nalgebra::DVector;

/// The Newton step `d` along the path at `q`, `e` the exact spectrum of `Ĥ` there (module
/// docs), whether it escaped along a direction of negative curvature, and the spectrum of
/// `Ĥ + C` it was taken with (module `path_hessian`; the valley watch reads it, module
/// `valley`).
pub(crate) fn escape_step(
    sys: &mut System,
    q: &DVector<f64>,
    part: &Partition,
    eval: &Eval,
    e: &Spectrum,
    guard: Option<&Guard>,
    options: &Options,
) -> (DVector<f64>, bool, Spectrum) {
    escape_along(
        sys,
        q,
        part,
        eval,
        along_path(sys, q, part, eval, e),
        guard,
        options,
    )
}

/// [`escape_step`] with the spectrum `path` of `Ĥ + C` at hand (module `path_cholesky`, where
/// `Ĥ + C` was summed from `Ĥ` itself): the step, whether it escaped, and `path`.
pub(crate) fn escape_along(
    sys: &mut System,
    q: &DVector<f64>,
    part: &Partition,
    eval: &Eval,
    path: Spectrum,
    guard: Option<&Guard>,
    options: &Options,
) -> (DVector<f64>, bool, Spectrum) {
    let e = &path;
    // Near a stationary point; anywhere after a release decided by the step (module docs).
    let near = if guard.is_some_and(|g| g.falling) {
        f64::INFINITY
    } else {
        NEAR_STATIONARY
    };
    let (mut d, candidates) = newton_step_within(e, &eval.grad_v, Some(options.max_step), near);
    let mut escaped = false;
    for &(i, t, newton) in &candidates {
        let v = e.vectors.column(i).into_owned();
        let (lambda, slope) = (e.values[i], v.dot(&eval.grad_v));
        // The energy along the path falls by at least half the model's decrease, and no
        // inactive inequality is crossed.
        let falls = |sys: &mut System, t: f64| {
            let step = cap_step(sys, part, eval, q, &v * t, options);
            let trial = sys.problem.retraction.point(q, &step.dq, 1.0);
            if guard.is_some_and(|g| g.violated(sys, &trial)) {
                return false;
            }
            let s = step.d.dot(&v);
            let model = slope * s + 0.5 * lambda * s * s;
            let mut grad = DVector::zeros(q.len());
            let m = sys.problem.model;
            potential(m, &sys.problem.cons.branches, &trial, &mut grad, None)
                .is_some_and(|v| v.total - eval.energy.total <= 0.5 * model)
        };
        let chosen = [t, -t].into_iter().find(|&t| falls(sys, t));
        d += &v * (chosen.unwrap_or(newton) - t);
        escaped |= chosen.is_some();
    }
    (d, escaped, path)
}
