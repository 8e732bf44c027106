//! Joint reactions from the Lagrange multipliers.
//!
//! The constraint force on body `j` is `Q = Σ_k μ_k ∂Φ_k/∂q_jᵀ` over the rows of the joint
//! (and of locks on it); `Q = [F; Q_p]` is a force `F` through the body origin and a body-frame
//! torque `n' = ½ G(p) Q_p` (`G = [−e, −ẽ + e0 I]`, which also removes the component along `p`).
//! The torque about the joint origin `P` is `n_P = A n' + (r − r_P) × F`. Rows found redundant
//! carry no multiplier, so for over-constrained models this is one admissible distribution (with
//! stops and contacts, the one of module `distribution`).

use super::report::Reaction;
use super::system::System;
use crate::constraints::{joint, BlockKind};
use crate::jet::pair_of;
use crate::math::{rotation, skew};
use nalgebra::{DVector, Matrix3x4, Vector3, Vector4};

/// The reactions from the multipliers `mu` of every row of `sys` (zero on redundant rows).
pub(crate) fn reactions(
    sys: &System,
    q: &DVector<f64>,
    mu: &DVector<f64>,
) -> Vec<(String, Reaction)> {
    let model = sys.problem.model;
    let mut out = Vec::new();
    let mut rows_buf = Vec::new();
    // The joint and lock blocks of each joint (one pass: `O(N)`, not joints × blocks).
    let mut by_joint = vec![Vec::new(); model.joints.len()];
    for block in &sys.problem.cons.blocks {
        match &block.kind {
            BlockKind::Joint(id) | BlockKind::Lock { joint: id, .. } => by_joint[id.0].push(block),
            _ => {}
        }
    }
    for (ji, j) in model.joints.iter().enumerate() {
        let pair = pair_of(&j.bodies, q, false);
        let mut g = crate::jet::LVec::zeros();
        let mut any = false;
        for block in &by_joint[ji] {
            match &block.kind {
                BlockKind::Joint(id) if id.0 == ji => {
                    joint::rows(
                        j,
                        &pair,
                        sys.problem.cons.branches.get(*id, 0),
                        &mut rows_buf,
                    );
                    for (k, s) in rows_buf.iter().enumerate() {
                        g += s.g * mu[block.first + k];
                    }
                    any = true;
                }
                BlockKind::Lock { joint: id, dof, .. } if id.0 == ji => {
                    if let Some(s) = crate::kinematics::coordinate(j, &pair, *dof, 0.0) {
                        g += s.g * mu[block.first];
                        any = true;
                    }
                }
                _ => {}
            }
        }
        if !any {
            continue;
        }
        // Side carrying a body: the child if it moves, else the parent (reaction negated).
        let (k, sign) = if j.bodies[1].is_some() {
            (1, 1.0)
        } else {
            (0, -1.0)
        };
        let f = Vector3::new(g[7 * k], g[7 * k + 1], g[7 * k + 2]) * sign;
        let qp = Vector4::new(g[7 * k + 3], g[7 * k + 4], g[7 * k + 5], g[7 * k + 6]) * sign;
        let p = pair.p[k] / pair.p[k].norm();
        let e = Vector3::new(p[1], p[2], p[3]);
        let mut gm = Matrix3x4::zeros();
        gm.set_column(0, &(-e));
        gm.fixed_view_mut::<3, 3>(0, 1)
            .copy_from(&(-skew(&e) + nalgebra::Matrix3::identity() * p[0]));
        let n_body = 0.5 * gm * qp;
        let a = rotation(&p);
        let r_p = pair.r[1] + rotation(&pair.p[1]) * j.body_from_joint[1].translation.vector;
        let torque = a * n_body + (pair.r[k] - r_p).cross(&f);
        let rj = rotation(&pair.p[0]) * j.body_from_joint[0].rotation.to_rotation_matrix().matrix();
        let fj = rj.transpose() * f;
        let tj = rj.transpose() * torque;
        out.push((
            j.name.clone(),
            Reaction {
                force_world: f.into(),
                torque_world: torque.into(),
                force_joint: fj.into(),
                torque_joint: tj.into(),
            },
        ));
    }
    out
}
