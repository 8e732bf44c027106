//! Poses along a mode shape, for animating it about a rest pose.
//!
//! A mode `m` (joint-coordinate changes, as in [`Stability::modes`](super::Stability)) is
//! followed over one period of `frames` poses with joint values
//!
//! `θ_k = θ* + a sin(2π k / frames) · m`,
//!
//! each placed by forward kinematics and then closed by the corrector (`Φ(q_k) = 0`), so loops
//! stay closed while the mode moves. A pose whose constraints cannot be closed ends the
//! animation there.

use crate::model::Model;
use crate::state::{JointValues, State};

/// The poses of one period of the mode `mode` about `rest`, with amplitude `amplitude` (in
/// the mode's units: the largest joint change of a mode is 1, so 0.15 moves the most moving
/// joint by 0.15 rad or 0.15 m). Fewer than `frames` poses are returned if a pose cannot be
/// assembled.
pub fn mode_animation(
    model: &Model,
    rest: &State,
    mode: &super::Mode,
    frames: usize,
    amplitude: f64,
) -> Vec<State> {
    let rest_values: JointValues = rest.joint_values(model).into_iter().collect();
    let locks = super::lock_values(model);
    let mut poses = Vec::with_capacity(frames);
    for k in 0..frames {
        let a = amplitude * (k as f64 / frames as f64 * std::f64::consts::TAU).sin();
        let mut values = rest_values.clone();
        for (name, d) in mode {
            if let Some(v) = values.get_mut(name) {
                for (x, dx) in v.iter_mut().zip(d) {
                    *x += a * dx;
                }
            }
        }
        let mut s = State::from_joint_values(model, &values);
        match super::assemble_only(model, s.q.clone(), &mut s.branches, &locks) {
            Ok(q) => s.q = q,
            Err(_) => break,
        }
        poses.push(s);
    }
    poses
}
