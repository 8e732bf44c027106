//! The step limit of the minimizer (stage 4 of module `minimize`): the tangent step
//! `δq = Z d` of a reduced step `d` is shortened, with `d`, so that every body's Euler
//! parameters change by at most `max_step` and its origin by at most `10 max_step ℓ`,
//! `ℓ = max(L, extent)`: `L` the characteristic length, the extent the diagonal of the
//! bounding box of the body origins.
//!
//! With the projected stop search (`StopSearch::Projected`, module `inequality::bend`) the
//! rotations of a model with joint stops are limited in joint coordinates instead: every
//! body's rotation relative to its tree parent, `|ω_b − ω_a|` (a revolute joint's `|θ̇|`), by
//! `JOINT_STEP · max_step` rad (0.9 rad at the default `max_step`), and every body's Euler
//! parameters by `JOINT_STEP · max_step` as well (three times the per-body limit: in a long
//! chain small joint rotations add up along it, and the per-joint limit alone let the
//! 1,000-link chain with ±π limits take steps its linear model did not describe:
//! `max_iterations` against 7 iterations). Measured on the hanging corpus of example-robot-data
//! (`--load-steps 1`): 0.3, 0.6, 0.9, 1.2 and 1.8 rad took 1,455, 994, 839, 857 and 993
//! iterations, the per-body limit 922 (docs/method.md, "Meeting several stops in one step").

use crate::solver::options::{Options, StopSearch};
use crate::solver::partition::Partition;
use crate::solver::system::{Eval, System};
use nalgebra::DVector;

/// The per-joint rotation limit of the projected stop search, in units of `max_step` (module
/// docs).
const JOINT_STEP: f64 = 3.0;

/// The step of one iteration after the cap: reduced `d`, tangent `δq = Z d`, whether the cap
/// shortened it, and the length `ℓ` it was capped with.
pub(crate) struct Step {
    pub(crate) d: DVector<f64>,
    pub(crate) dq: DVector<f64>,
    pub(crate) capped: bool,
    pub(crate) length: f64,
}

/// The tangent step `δq = Z d`, with `d` and `δq` shortened so that every body's
/// Euler parameters change by at most `max_step` (about 2·max_step rad of rotation) and its
/// origin by at most 10·max_step lengths `ℓ`, `ℓ` the larger of the characteristic length and
/// the extent of the mechanism (the diagonal of the bounding box of the body origins): in a
/// long chain, small joint rotations move the far links by about the chain's length, and a
/// cap in link lengths would make the iteration count grow with N.
pub(crate) fn cap_step(
    sys: &System,
    part: &Partition,
    eval: &Eval,
    q: &DVector<f64>,
    mut d: DVector<f64>,
    options: &Options,
) -> Step {
    let mut dq = sys.tangent_step(part, eval, &d);
    let l = sys.problem.model.length_scale.max(extent(q));
    let (mut rot, mut pos) = (0.0f64, 0.0f64);
    for (i, x) in dq.iter().enumerate() {
        if i % 7 < 3 {
            pos = pos.max(x.abs() / l);
        } else {
            rot = rot.max(x.abs());
        }
    }
    if options.stop_search == StopSearch::Projected && has_stops(sys, options) {
        // Per joint `JOINT_STEP · max_step` rad, per body `JOINT_STEP` times its limit.
        rot = (sys.problem.retraction.joint_rotation(q, &dq) / JOINT_STEP).max(rot / JOINT_STEP);
    }
    let factor =
        (options.max_step / rot.max(1e-300)).min(10.0 * options.max_step / pos.max(1e-300));
    let capped = factor < 1.0;
    if capped {
        d *= factor;
        dq *= factor;
    }
    Step {
        d,
        dq,
        capped,
        length: l,
    }
}

/// Whether the model has joint stops that the solve enforces (the projected stop search
/// changes nothing on a model without them).
fn has_stops(sys: &System, options: &Options) -> bool {
    options.contact().enforces_limits()
        && sys
            .problem
            .model
            .joints
            .iter()
            .any(|j| !j.merged && j.kind.has_limits() && j.limits.is_some())
}

/// The diagonal of the bounding box of the body origins.
fn extent(q: &DVector<f64>) -> f64 {
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for b in 0..q.len() / 7 {
        for k in 0..3 {
            lo[k] = lo[k].min(q[7 * b + k]);
            hi[k] = hi[k].max(q[7 * b + k]);
        }
    }
    (0..3)
        .map(|k| (hi[k] - lo[k]).max(0.0).powi(2))
        .sum::<f64>()
        .sqrt()
}
