//! The search path of the line search: a tangent step `δq` followed as rigid motions along the
//! spanning tree (a retraction onto the tree joints), not as a straight line in the Cartesian
//! coordinates.
//!
//! Each body's tangent `(ẋ_b, ṗ_b)` is a twist: the origin's velocity `ẋ_b` and the angular
//! velocity `ω_b = 2 vec(ṗ_b ⊗ p_b*) / (p_bᵀ p_b)`. Relative to its tree parent `a` (the world
//! for a root) the body moves with `ω_r = ω_b − ω_a` and, at its origin, `w = ẋ_b − ẋ_a −
//! ω_a × (x_b − x_a)`. The point at `α` moves every body rigidly, parents first:
//!
//! `T_b(α) = M_b(α) T_b`,  `M_b(α) = M_a(α) E_b(α)`,
//! `E_b(α): y ↦ x_b + R(α ω_r)(y − x_b) + V(α ω_r) α w`
//!
//! (`R(φ)` the rotation by `|φ|` about `φ`, `V(φ) = I + (1 − cos θ)/θ² φ̃ + (θ − sin θ)/θ³ φ̃²`,
//! `θ = |φ|`: the screw motion of the relative twist). The path leaves `q` along `δq`, so the
//! line search's slope `∇fᵀd` is unchanged. A tangent satisfies the linearized joint rows, so
//! a revolute joint's relative twist is a rotation about its axis line and a prismatic
//! joint's a translation along it: `E_b` is then exactly the joint's motion from `θ` to
//! `θ + α θ̇`, and every tree joint of one motion subgroup (revolute, continuous, prismatic,
//! cylindrical, screw, spherical, planar, floating) holds along the whole path, together with
//! rows linear in the joint coordinates (stops, locks, mimics). Loop-closing joints, contacts
//! and universal, distance and point-on-line tree joints are left to the corrector, as on the
//! straight line.
//!
//! Why: the partition takes Cartesian coordinates of bodies as independent. A rotation about a
//! joint far from such a body moves it on a circle, and a straight step in them leaves the
//! circle by `α²|δv|²/2r`: the corrector puts the difference into the stiff directions (the
//! arm stretches), the step costs energy the reduced Hessian does not predict, and a
//! near-neutral rotation (SO-101's base yaw, a hip yaw under a hanging leg) advanced by about
//! 0.01 rad per iteration for hundreds of iterations.

use crate::math::{compose, rotation, skew};
use crate::model::Model;
use nalgebra::{DVector, Matrix3, Vector3, Vector4};

/// The spanning tree as the retraction walks it.
#[derive(Clone, Debug)]
pub(crate) struct Retraction {
    /// `(body, tree parent)`, every body once, a parent before its children (`None`: the
    /// world, for a body that no tree joint moves or one jointed to the world).
    order: Vec<(usize, Option<usize>)>,
    /// The body each joint moves relative to its tree parent (`None`: a loop-closing or merged
    /// joint, or a second tree joint onto a body already moved), indexed by joint.
    moves: Vec<Option<usize>>,
}

/// The rigid displacement `y ↦ A(r) y + t` of the world that a body has undergone: `r`, `t`
/// and `A(r)`.
type Moved = (Vector4<f64>, Vector3<f64>, Matrix3<f64>);

impl Retraction {
    /// The walk of `model`'s spanning tree.
    pub(crate) fn new(model: &Model) -> Self {
        let n = model.bodies.len();
        let mut parent: Vec<Option<usize>> = vec![None; n];
        let mut children: Vec<Vec<usize>> = vec![Vec::new(); n];
        let mut moved = vec![false; n];
        let mut moves = vec![None; model.joints.len()];
        for (i, j) in model
            .joints
            .iter()
            .enumerate()
            .filter(|(_, j)| j.tree && !j.merged)
        {
            let Some(c) = j.bodies[1] else { continue };
            if std::mem::replace(&mut moved[c.0], true) {
                continue;
            }
            moves[i] = Some(c.0);
            parent[c.0] = j.bodies[0].map(|b| b.0);
            if let Some(p) = j.bodies[0] {
                children[p.0].push(c.0);
            }
        }
        let mut order = Vec::with_capacity(n);
        let mut seen = vec![false; n];
        let mut stack: Vec<usize> = (0..n).rev().filter(|&b| parent[b].is_none()).collect();
        while let Some(b) = stack.pop() {
            if std::mem::replace(&mut seen[b], true) {
                continue;
            }
            order.push((b, parent[b]));
            stack.extend(children[b].iter().rev());
        }
        // Not reached from a root (a cycle of tree edges cannot be built): its own twist.
        order.extend((0..n).filter(|&b| !seen[b]).map(|b| (b, None)));
        Retraction { order, moves }
    }

    /// The body that tree joint `joint` moves along the path (`None` for a loop-closing joint).
    pub(crate) fn body_of(&self, joint: usize) -> Option<usize> {
        self.moves.get(joint).copied().flatten()
    }

    /// Every body's tree parent (`None`: the world, or no tree joint moves it).
    pub(crate) fn parents(&self) -> Vec<Option<usize>> {
        let mut parents = vec![None; self.order.len()];
        for &(b, a) in &self.order {
            parents[b] = a;
        }
        parents
    }

    /// The largest rotation rate of a body relative to its tree parent, `max_b |ω_b − ω_a|`
    /// (for a revolute joint its rate `|θ̇|`): the step measured in joint coordinates.
    pub(crate) fn joint_rotation(&self, q: &DVector<f64>, dq: &DVector<f64>) -> f64 {
        // Each body's angular velocity once (a parent's is read by each of its children).
        let w: Vec<Vector3<f64>> = (0..self.order.len())
            .map(|b| angular_velocity(q, dq, b))
            .collect();
        self.order
            .iter()
            .map(|&(b, a)| match a {
                Some(a) => (w[b] - w[a]).norm(),
                None => w[b].norm(),
            })
            .fold(0.0, f64::max)
    }

    /// The point at `alpha` along the tangent `dq` from `q` (module docs).
    pub(crate) fn point(&self, q: &DVector<f64>, dq: &DVector<f64>, alpha: f64) -> DVector<f64> {
        self.bent_point(q, dq, alpha, &[])
    }

    /// [`Retraction::point`] with the relative motion of each body `b` of `caps` (`(b, α_b)`)
    /// stopped at `min(α, α_b)`: its tree joint goes from `θ` to `θ + min(α, α_b) θ̇` (the
    /// projected path of a joint stop, module `inequality::bend`); its children move on.
    pub(crate) fn bent_point(
        &self,
        q: &DVector<f64>,
        dq: &DVector<f64>,
        alpha: f64,
        caps: &[(usize, f64)],
    ) -> DVector<f64> {
        let mut out = q.clone();
        // Each body's displacement with its rotation matrix, and its angular velocity, formed
        // once and read by its children (the same numbers as forming them again).
        let identity = (Vector4::new(1.0, 0.0, 0.0, 0.0), Vector3::zeros());
        let identity: Moved = (identity.0, identity.1, rotation(&identity.0));
        let n = q.len() / 7;
        let mut moved = vec![identity; n];
        let mut omega = vec![Vector3::zeros(); n];
        for &(b, a) in &self.order {
            let xb = position(q, b);
            let wb = angular_velocity(q, dq, b);
            omega[b] = wb;
            let (wr, w, (ra, ta, rot_a)) = match a {
                Some(a) => {
                    let wa = omega[a];
                    let va = position(dq, a) + wa.cross(&(xb - position(q, a)));
                    (wb - wa, position(dq, b) - va, moved[a])
                }
                None => (wb, position(dq, b), identity),
            };
            let ab = caps
                .iter()
                .filter(|c| c.0 == b)
                .fold(alpha, |a, c| a.min(c.1));
            let (re, shift) = screw(&(wr * ab), &(w * ab));
            // E_b(y) = x_b + A(r_e)(y − x_b) + shift, M_b = M_a ∘ E_b.
            let te = xb - rotation(&re) * xb + shift;
            let rb = compose(&ra, &re);
            let tb = rot_a * te + ta;
            let rot_b = rotation(&rb);
            moved[b] = (rb, tb, rot_b);
            let i = 7 * b;
            let xn = rot_b * xb + tb;
            let pn = compose(&rb, &Vector4::new(q[i + 3], q[i + 4], q[i + 5], q[i + 6]));
            out.fixed_rows_mut::<3>(i).copy_from(&xn);
            out.fixed_rows_mut::<4>(i + 3).copy_from(&pn);
        }
        out
    }
}

/// The change of the scaled independent coordinates `v̂ = S⁻¹ v` from `q` to `qt` (the path is
/// not a straight line in them): the step a quasi-Newton update was taken over.
pub(crate) fn independent_change(
    independent: &[usize],
    columns: &[f64],
    q: &DVector<f64>,
    qt: &DVector<f64>,
) -> DVector<f64> {
    DVector::from_iterator(
        independent.len(),
        independent.iter().map(|&c| (qt[c] - q[c]) / columns[c]),
    )
}

/// The origin of body `b` in `q` (or its velocity in a tangent).
fn position(q: &DVector<f64>, b: usize) -> Vector3<f64> {
    q.fixed_rows::<3>(7 * b).into_owned()
}

/// The world angular velocity of body `b` for the tangent `dq` at `q`:
/// `ω = 2 (e0 ė − ė0 e + e × ė) / (pᵀp)`.
pub(crate) fn angular_velocity(q: &DVector<f64>, dq: &DVector<f64>, b: usize) -> Vector3<f64> {
    let i = 7 * b;
    let (e0, de0) = (q[i + 3], dq[i + 3]);
    let e = Vector3::new(q[i + 4], q[i + 5], q[i + 6]);
    let de = Vector3::new(dq[i + 4], dq[i + 5], dq[i + 6]);
    let norm2 = (e0 * e0 + e.norm_squared()).max(f64::MIN_POSITIVE);
    2.0 * (e0 * de - de0 * e + e.cross(&de)) / norm2
}

/// The screw motion of the twist `(φ, u)` (rotation vector, velocity at the reference point):
/// the Euler parameters of `R(φ)` and the shift `V(φ) u` of the reference point.
fn screw(phi: &Vector3<f64>, u: &Vector3<f64>) -> (Vector4<f64>, Vector3<f64>) {
    let theta = phi.norm();
    // cos(θ/2), sin(θ/2)/θ, (1 − cos θ)/θ², (θ − sin θ)/θ³; series below 10⁻⁴ rad.
    let (c, s, c1, c2) = if theta < 1e-4 {
        let t2 = theta * theta;
        (
            1.0 - t2 / 8.0,
            0.5 - t2 / 48.0,
            0.5 - t2 / 24.0,
            1.0 / 6.0 - t2 / 120.0,
        )
    } else {
        (
            (0.5 * theta).cos(),
            (0.5 * theta).sin() / theta,
            (1.0 - theta.cos()) / (theta * theta),
            (theta - theta.sin()) / (theta * theta * theta),
        )
    };
    let r = Vector4::new(c, s * phi.x, s * phi.y, s * phi.z);
    let k = skew(phi);
    (r, (Matrix3::identity() + k * c1 + k * k * c2) * u)
}

#[cfg(test)]
#[path = "retraction_tests.rs"]
pub(crate) mod tests;
