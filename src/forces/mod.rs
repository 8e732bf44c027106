//! Potential energy `V(q)` and its derivatives; the generalized force is `g = −V_qᵀ`.
//!
//! `V = V_gravity + V_springs + V_joint_springs − W_loads − W_efforts` with
//! - gravity `−Σ_i m_i gᵀ (r_i + A_i c_i)` (zero at the world origin),
//! - translational springs `∫₀^{L−L₀} F(δ) dδ`, `L = ‖r_Pj − r_Pi‖`,
//! - joint springs `∫₀^{θ−θ_ref} F(δ) dδ` with `θ` the unwrapped joint angle (module
//!   [`crate::kinematics`]: never wrapped into (−π, π]),
//! - dead loads `W = fᵀ r_P`, joint efforts `W = τ θ`.

pub(crate) mod finite;
pub(crate) mod law;
mod stacked;

use crate::jet::{closed, pair_of, scatter, Pair, Scalar};
use crate::kinematics::{coordinate, Branches};
use crate::model::{BodyId, Model, SpringMode};
use nalgebra::{DVector, Matrix3};

/// Potential energy split by source \[J\].
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct Energy {
    /// Total `V` \[J\].
    pub total: f64,
    /// Gravity \[J\].
    pub gravity: f64,
    /// Translational springs \[J\].
    pub springs: f64,
    /// Joint springs \[J\].
    pub joint_springs: f64,
    /// Minus the work of dead loads and joint efforts \[J\].
    pub loads: f64,
    /// `Σ |V_k|` over the individual terms: the scale of the rounding error of `total`.
    #[serde(skip)]
    pub(crate) magnitude: f64,
}

/// The joint coordinate `dof` read on the branch `reference`: a revolute angle in closed form
/// ([`closed::revolute_angle`]), any other by the generic jets of
/// [`crate::kinematics::coordinate`].
fn joint_coordinate(
    joint: &crate::model::Joint,
    pair: &Pair,
    dof: usize,
    reference: f64,
) -> Option<Scalar> {
    use crate::model::JointKind;
    match (joint.kind, dof) {
        (JointKind::Revolute | JointKind::Continuous, 0) => Some(crate::kinematics::on_branch(
            closed::revolute_angle(joint, pair),
            reference,
        )),
        _ => coordinate(joint, pair, dof, reference),
    }
}

/// Evaluates `V(q)` with joint angles read on `branches` (unwrapped: a spring wound by several
/// turns stores the energy of all of them); adds `V_q` to `grad` and, when given, `V_qq` to
/// `hess`. Returns `None` where `V` is undefined (a force table with `extrapolate="error"` left
/// its range).
pub(crate) fn potential(
    model: &Model,
    branches: &Branches,
    q: &DVector<f64>,
    grad: &mut DVector<f64>,
    hess: Option<&mut dyn crate::jet::HessianSink>,
) -> Option<Energy> {
    let want_h = hess.is_some();
    // `A(p)` of every body once (gravity and the joint angles on each side read each body's),
    // the identity for the ground, as `pair_of` gives it.
    let (a, ground) = (crate::jet::body_rotations(q), crate::jet::ground_rotation());
    let side = |b: Option<BodyId>| b.map_or(&ground, |b| &a[b.0]);
    let mut e = Energy::default();
    let mut add = Sum {
        magnitude: 0.0,
        grad,
        hess,
    };
    for (i, b) in model.bodies.iter().enumerate() {
        if b.gravity_mass == 0.0 {
            continue;
        }
        let w = -b.gravity_mass * model.gravity;
        let v = match add.derivatives() {
            Some((g, h)) => stacked::weighted_point(BodyId(i), q, &a[i], &b.gravity_com, &w, g, h),
            None => {
                stacked::weighted_point_gradient(BodyId(i), q, &a[i], &b.gravity_com, &w, add.grad)
            }
        };
        add.value(v, 1.0, &mut e.gravity);
    }
    for l in &model.loads {
        let w = -l.force;
        let v = match add.derivatives() {
            Some((g, h)) => stacked::weighted_point(l.body, q, &a[l.body.0], &l.point, &w, g, h),
            None => {
                stacked::weighted_point_gradient(l.body, q, &a[l.body.0], &l.point, &w, add.grad)
            }
        };
        add.value(v, 1.0, &mut e.loads);
    }
    for s in &model.springs {
        let bodies = [s.ends[0].body, s.ends[1].body];
        let pair = pair_of(&bodies, q, want_h);
        let d = pair
            .point(1, &s.ends[1].point)
            .sub(&pair.point(0, &s.ends[0].point));
        let l2 = pair.dot(&d, &d);
        let l = l2.v.sqrt();
        let (u, f, k) = law::evaluate(&s.law, s.mode, l - s.free_length)?;
        if l < 1e-12 {
            e.springs += u;
            e.magnitude += u.abs();
            continue;
        }
        let len = l2.compose(l, 0.5 / l, -0.25 / (l * l * l));
        add.term(&bodies, &len.compose(u, f, k), 1.0, &mut e.springs);
    }
    for js in &model.joint_springs {
        let j = &model.joints[js.joint.0];
        let pair = pair_of(&j.bodies, q, want_h);
        let rot = [side(j.bodies[0]), side(j.bodies[1])];
        let reference = branches.get(js.joint, js.dof);
        if let Some(((g, h), theta)) = add
            .derivatives()
            .and_then(|d| stacked_angle(j, &pair, rot, js.dof).map(|t| (d, t)))
        {
            let v = on_branch(theta.v, reference);
            let (u, f, k) = law::evaluate(&js.law, SpringMode::Both, v - js.reference)?;
            stacked::scatter_angle(&j.bodies, &theta, Some((f, k)), 1.0, g, h);
            add.value(u, 1.0, &mut e.joint_springs);
            continue;
        }
        if let Some((theta, grad)) = revolute_angle(j, &pair, rot, js.dof).filter(|_| !want_h) {
            let v = on_branch(theta, reference);
            let (u, f, _) = law::evaluate(&js.law, SpringMode::Both, v - js.reference)?;
            // `Scalar::compose`'s gradient `f ∇θ`, added with `c = 1`.
            stacked::scatter_gradient(&j.bodies, &(grad * f), 1.0, add.grad);
            add.value(u, 1.0, &mut e.joint_springs);
            continue;
        }
        let theta = joint_coordinate(j, &pair, js.dof, reference)?;
        let (u, f, k) = law::evaluate(&js.law, SpringMode::Both, theta.v - js.reference)?;
        add.term(
            &j.bodies,
            &theta.compose(u, f, k),
            1.0,
            &mut e.joint_springs,
        );
    }
    for ef in &model.efforts {
        let j = &model.joints[ef.joint.0];
        let pair = pair_of(&j.bodies, q, want_h);
        let rot = [side(j.bodies[0]), side(j.bodies[1])];
        let reference = branches.get(ef.joint, ef.dof);
        if let Some(((g, h), theta)) = add
            .derivatives()
            .and_then(|d| stacked_angle(j, &pair, rot, ef.dof).map(|t| (d, t)))
        {
            let v = on_branch(theta.v, reference);
            stacked::scatter_angle(&j.bodies, &theta, None, -ef.value, g, h);
            add.value(v, -ef.value, &mut e.loads);
            continue;
        }
        if let Some((theta, grad)) = revolute_angle(j, &pair, rot, ef.dof).filter(|_| !want_h) {
            let v = on_branch(theta, reference);
            stacked::scatter_gradient(&j.bodies, &grad, -ef.value, add.grad);
            add.value(v, -ef.value, &mut e.loads);
            continue;
        }
        let theta = joint_coordinate(j, &pair, ef.dof, reference)?;
        add.term(&j.bodies, &theta, -ef.value, &mut e.loads);
    }
    e.total = e.gravity + e.springs + e.joint_springs + e.loads;
    e.magnitude += add.magnitude;
    Some(e)
}

/// The sums of [`potential`]: `Σ |c V_k|`, the gradient and the Hessian sink.
struct Sum<'g, 'h> {
    magnitude: f64,
    grad: &'g mut DVector<f64>,
    hess: Option<&'h mut dyn crate::jet::HessianSink>,
}

impl<'h> Sum<'_, 'h> {
    /// Adds `c f` (value into `slot`, gradient and Hessian into the sums).
    fn term(&mut self, bodies: &[Option<BodyId>; 2], s: &Scalar, c: f64, slot: &mut f64) {
        self.value(s.v, c, slot);
        scatter(bodies, s, c, self.grad, self.hess.as_deref_mut());
    }

    /// Adds the value `c v` of a term whose derivatives were added already.
    fn value(&mut self, v: f64, c: f64, slot: &mut f64) {
        *slot += c * v;
        self.magnitude += (c * v).abs();
    }

    /// The gradient and the Hessian sink, when the Hessian is wanted.
    fn derivatives(
        &mut self,
    ) -> Option<(&mut DVector<f64>, &mut (dyn crate::jet::HessianSink + 'h))> {
        let grad = &mut *self.grad;
        self.hess.as_deref_mut().map(|h| (grad, h))
    }
}

/// A revolute angle (`dof` 0 of a revolute or continuous joint) with its Hessian on the stack
/// (module `stacked`), `None` for any other coordinate.
fn stacked_angle(
    joint: &crate::model::Joint,
    pair: &Pair,
    a: [&Matrix3<f64>; 2],
    dof: usize,
) -> Option<stacked::Angle> {
    use crate::model::JointKind;
    matches!(
        (joint.kind, dof),
        (JointKind::Revolute | JointKind::Continuous, 0)
    )
    .then(|| stacked::revolute_angle(joint, pair, a))
}

/// A revolute angle (`dof` 0 of a revolute or continuous joint) and its gradient, without the
/// Hessian (module `stacked`), `None` for any other coordinate.
fn revolute_angle(
    joint: &crate::model::Joint,
    pair: &Pair,
    a: [&Matrix3<f64>; 2],
    dof: usize,
) -> Option<(f64, crate::jet::LVec)> {
    use crate::model::JointKind;
    matches!(
        (joint.kind, dof),
        (JointKind::Revolute | JointKind::Continuous, 0)
    )
    .then(|| stacked::revolute_angle_gradient(joint, pair, a))
}

/// The angle `v` read on the branch `reference` ([`crate::kinematics::on_branch`]).
fn on_branch(v: f64, reference: f64) -> f64 {
    let s = Scalar {
        v,
        g: crate::jet::LVec::zeros(),
        h: None,
    };
    crate::kinematics::on_branch(s, reference).v
}

/// The error naming the first force table evaluated outside its range at `q` (tables with
/// `extrapolate="error"`), or `None` if every term of `V` is defined there.
pub(crate) fn undefined_term(
    model: &Model,
    branches: &Branches,
    q: &DVector<f64>,
) -> Option<crate::Error> {
    let refuse = |element: String, law: &crate::model::ForceLaw, deflection: f64| {
        let crate::model::ForceLaw::Table { points, .. } = law else {
            return None;
        };
        Some(crate::Error::ForceTableOutOfRange {
            element,
            deflection,
            lower: points.first().map_or(0.0, |p| p.0),
            upper: points.last().map_or(0.0, |p| p.0),
        })
    };
    for s in &model.springs {
        let pair = pair_of(&[s.ends[0].body, s.ends[1].body], q, false);
        let d = pair
            .point(1, &s.ends[1].point)
            .sub(&pair.point(0, &s.ends[0].point));
        let delta = d.v.norm() - s.free_length;
        if law::evaluate(&s.law, s.mode, delta).is_none() {
            return refuse(format!("spring `{}`", s.name), &s.law, delta);
        }
    }
    for js in &model.joint_springs {
        let j = &model.joints[js.joint.0];
        let pair = pair_of(&j.bodies, q, false);
        let Some(theta) = coordinate(j, &pair, js.dof, branches.get(js.joint, js.dof)) else {
            continue;
        };
        let delta = theta.v - js.reference;
        if law::evaluate(&js.law, SpringMode::Both, delta).is_none() {
            return refuse(format!("joint spring on `{}`", j.name), &js.law, delta);
        }
    }
    None
}

/// Whether anything in `model` stores or releases energy: a body with mass under non-zero
/// gravity, a spring, a joint spring, a non-zero load or effort.
pub(crate) fn has_energy(model: &Model) -> bool {
    (model.gravity != nalgebra::Vector3::zeros()
        && model.bodies.iter().any(|b| b.gravity_mass != 0.0))
        || !model.springs.is_empty()
        || !model.joint_springs.is_empty()
        || model
            .loads
            .iter()
            .any(|l| l.force != nalgebra::Vector3::zeros())
        || model.efforts.iter().any(|e| e.value != 0.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::jet::closed::tests::assert_same;
    use crate::jet::testing::{check_scalar, sample_joint, sample_pair};
    use crate::model::JointKind;

    /// The closed-form revolute angle equals the generic jets' (value, gradient, Hessian) and
    /// matches central differences.
    #[test]
    fn closed_form_revolute_angle_equals_the_jets() {
        let joint = sample_joint(JointKind::Revolute);
        for seed in 0..5 {
            let pair = sample_pair(seed);
            for reference in [0.0, 7.0] {
                let what = format!("seed {seed}, branch {reference}");
                let jet = coordinate(&joint, &pair, 0, reference).unwrap();
                let closed = joint_coordinate(&joint, &pair, 0, reference).unwrap();
                assert_same(&jet, &closed, &what);
                check_scalar(
                    &pair,
                    &|q| joint_coordinate(&joint, q, 0, reference).unwrap(),
                    &what,
                );
            }
        }
    }
}
