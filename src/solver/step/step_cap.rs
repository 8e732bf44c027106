//! The step limit of the minimizer (stage 4 of module `minimize`): the tangent step
//! `δq = Z d` of a reduced step `d` is shortened, with `d`, so that every body's Euler
//! parameters change by at most `max_step` and its origin by at most `10 max_step ℓ`,
//! `ℓ = max(L, extent)`: `L` the characteristic length, the extent the diagonal of the
//! bounding box of the body origins.

use crate::solver::options::Options;
use crate::solver::partition::Partition;
use crate::solver::system::{Eval, System};
use nalgebra::DVector;

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
