//! The rate of a function of the bodies' poses along a tree joint's coordinate, from the
//! function's gradient: `t_kᵀ g` with `t_k = ∂q/∂θ_k` the joint's motion (every body below the
//! joint turning about its axis or sliding along it, rigidly).
//!
//! A body's gradient `g = (g_x, g_p)` at the pose `(x, p)`, `p = (e₀, e)`, acts as the wrench
//!
//! `F = g_x`,   `M = x × g_x + ½ (e₀ g_e − g₀ e + e × g_e)`
//!
//! about the world origin: a world angular velocity `ω` moves `p` by `ṗ = ½ (0, ω) ⊗ p`, so
//! `ṗ · g_p = ω · ½ (e₀ g_e − g₀ e + e × g_e)`, and `x` by `ω × (x − c)` about a point `c`. A
//! joint of world axis `ω` through `c` then gives, summed over the bodies it moves,
//!
//! `t_kᵀ g = ω · (M − c × F)` (turning),   `t_kᵀ g = ω · F` (sliding).
//!
//! Wrenches add, so a subtree's sum serves every joint above it (one pass leaves to root).

use crate::model::{Joint, JointKind};
use nalgebra::{DVector, Vector3, Vector4};

/// A revolute, continuous or prismatic joint's axis `ω` and origin `c` in the world, from its
/// parent's pose: the joint frame `world_from_parent · parent_from_J`, its z axis and origin.
#[derive(Clone, Copy, Debug)]
pub(crate) struct JointAxis {
    w: Vector3<f64>,
    c: Vector3<f64>,
    slide: bool,
}

impl JointAxis {
    /// The axis of `joint` at `q`, `None` for a joint of another kind.
    pub(crate) fn at(joint: &Joint, q: &DVector<f64>) -> Option<Self> {
        let slide = match joint.kind {
            JointKind::Revolute | JointKind::Continuous => false,
            JointKind::Prismatic => true,
            _ => return None,
        };
        let parent_from_j = &joint.body_from_joint[0];
        let z = parent_from_j.rotation * Vector3::z();
        let o = parent_from_j.translation.vector;
        let (w, c) = match joint.bodies[0] {
            Some(p) => {
                let (x, p) = pose(q, p.index());
                let r = crate::math::rotation(&p);
                (r * z, x + r * o)
            }
            None => (z, o),
        };
        Some(JointAxis { w, c, slide })
    }

    /// `t_kᵀ g` for a gradient whose wrench about the world origin is `(f, m)` ([`wrench`]).
    pub(crate) fn rate(&self, f: &Vector3<f64>, m: &Vector3<f64>) -> f64 {
        if self.slide {
            self.w.dot(f)
        } else {
            self.w.dot(&(m - self.c.cross(f)))
        }
    }
}

/// The position and Euler parameters of body `b` in `q`.
fn pose(q: &DVector<f64>, b: usize) -> (Vector3<f64>, Vector4<f64>) {
    (
        q.fixed_rows::<3>(7 * b).into_owned(),
        q.fixed_rows::<4>(7 * b + 3).into_owned(),
    )
}

/// The wrench `(F, M)` about the world origin of body `b`'s gradient `g` (its seven entries:
/// `g_x`, then `g_p`) at its pose in `q` (module docs).
pub(crate) fn wrench(q: &DVector<f64>, b: usize, g: &[f64]) -> (Vector3<f64>, Vector3<f64>) {
    let (x, p) = pose(q, b);
    let gx = Vector3::new(g[0], g[1], g[2]);
    let e = Vector3::new(p[1], p[2], p[3]);
    let ge = Vector3::new(g[4], g[5], g[6]);
    let m = x.cross(&gx) + 0.5 * (ge * p[0] - e * g[3] + e.cross(&ge));
    (gx, m)
}
