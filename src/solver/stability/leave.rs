//! Leaving a saddle that only the critical cone shows (without `--allow-unstable`).
//!
//! The minimizer leaves a stationary point whose curvature is negative on the tangent space of
//! the rows it holds. On the critical cone (module `cone`) a point can be unstable although that
//! space is not: the descent lets go of a stop or contact touching without force. There the
//! cone's minimizing face gives a unit direction `d` (signed into the cone, `a_w · d ≥ 0` for
//! every weak row `w`) with `dᵀ H d = λ < −t`, so along the tangent step `s d`
//!
//! ```text
//! V(s) = V(0) + s g·d + ½ λ s² + O(s³),     g·d ≈ 0 at the balanced point,
//! ```
//!
//! falls. The point is moved by the largest `s` (at most [`LEAVE_STEP`] in any coordinate,
//! halved until the energy falls) and corrected onto the rows carrying a force; the weak rows
//! that `d` opens (`a_w · d > 0`) are released, and the active-set search goes on from there,
//! at most [`MAX_LEAVES`] times in a solve. pybullet_data's Spirit 40 hanging from its fixed
//! base had stopped with its four lower legs balanced straight up against their knee stops
//! (`converged`, V = −2.687314 J, verdict `unstable`, exit 0); it now hangs them down
//! (−2.871693 J, stable, 26 iterations, four leaves).

use super::cone::{
    both_stops_held, judged_hessian, minimum_with_direction, strong_system, weak_rows,
    CONE_TOLERANCE, MAX_WEAK,
};
use super::spectrum::EXACT_UP_TO;
use crate::constraints::unilateral::Active;
use crate::model::Model;
use crate::solver::report::{Report, Verdict};
use crate::solver::system::Backend;
use crate::solver::Options;
use crate::State;
use nalgebra::DVector;

/// Times a converged point the critical cone judges unstable is left in one solve.
pub(crate) const MAX_LEAVES: usize = 16;

/// Whether the active-set search that ended at `report` should leave its point
/// ([`leave`]): converged, judged `unstable` with rows touching without force, the leave
/// allowed and not yet done [`MAX_LEAVES`] times.
pub(crate) fn should_leave(
    report: &Report,
    options: &Options,
    weak: &[Active],
    done: usize,
) -> bool {
    report.converged()
        && !options.allow_unstable
        && !weak.is_empty()
        && done < MAX_LEAVES
        && report
            .stability
            .as_ref()
            .is_some_and(|s| s.verdict == Verdict::Unstable)
}

/// The largest change of a coordinate [`leave`] starts with (Euler parameters and scaled
/// positions; about 6° of a body's turn).
const LEAVE_STEP: f64 = 0.05;

/// A balanced point that the critical cone judges unstable, left (without
/// `--allow-unstable`): the cone's direction of negative curvature `d` (signed into it), taken
/// as a tangent step of at most [`LEAVE_STEP`] in any coordinate, corrected onto the strong
/// rows, and halved until the energy falls; with the weak inequalities that `d` opens
/// (`a_w · d > 0`), which are to be released. `None` where the cone is not unstable, has no
/// direction at hand, or no halving lowers the energy. The minimizer leaves saddles whose
/// negative curvature lies in the held rows' tangent space; this is the one that needs a stop
/// or contact touching without force let go (pybullet_data's Spirit 40 hanging, its lower
/// legs balanced upright against their knee stops).
pub(crate) fn leave(
    model: &Model,
    state: &State,
    strong: &[Active],
    weak: &[Active],
    backend: Backend,
    options: &Options,
) -> Option<(DVector<f64>, Vec<Active>)> {
    let (held, weak) = both_stops_held(strong, weak);
    let (strong, weak) = (held.as_slice(), weak.as_slice());
    if weak.is_empty() || weak.len() > MAX_WEAK {
        return None;
    }
    let q = &state.q;
    let (mut sys, part) = strong_system(model, state, strong, backend);
    let dof = part.independent.len();
    if dof == 0 || dof > EXACT_UP_TO {
        return None;
    }
    let eval = sys.evaluate(q, &part)?;
    let (h, vals, tol) = judged_hessian(&mut sys, q, &part, &eval);
    if vals[0] > tol {
        return None;
    }
    let rows = weak_rows(model, state, &sys, &part, &eval, weak)?;
    let (lowest, d) = minimum_with_direction(&h, &rows, tol);
    let d = d.filter(|_| lowest < -tol)?;
    let opened: Vec<Active> = weak
        .iter()
        .zip(&rows)
        .filter(|(_, a)| a.row(0).dot(&d.transpose()) > CONE_TOLERANCE * a.row(0).norm())
        .map(|(w, _)| *w)
        .collect();
    if opened.is_empty() {
        return None;
    }
    let dq = sys.tangent_step(&part, &eval, &d);
    let mut s = LEAVE_STEP / dq.amax().max(f64::MIN_POSITIVE);
    for _ in 0..10 {
        let mut qc = sys.problem.retraction.point(q, &(&dq * s), 1.0);
        let corrected = sys.correct_from(
            &mut qc,
            &part,
            options.constraint_tolerance,
            options.max_corrector_iterations,
            Some(&eval.factors),
        );
        if corrected.is_ok() {
            if let Some(ec) = sys.evaluate(&qc, &part) {
                if ec.merit < eval.merit {
                    return Some((qc, opened));
                }
            }
        }
        s *= 0.5;
    }
    None
}
