//! The retraction on a tree of revolute, prismatic and continuous joints (fixed and floating
//! base): it leaves `q` along the tangent, keeps every tree joint closed at any step length,
//! and moves each joint coordinate linearly, `θ(α) = θ + α θ̇`.
use super::*;
use crate::constraints::Constraints;
use crate::solver::system::{Backend, System};
use crate::state::State;
use crate::urdf::{load_str, ImportOptions};
use nalgebra::DVector;

/// An arm with a prismatic, a continuous, a branch and a fixed joint (also the path Hessian's
/// test model, module `path_hessian`).
pub(crate) const ARM: &str = r#"<robot name="arm">
  <link name="base"/>
  <link name="a"><inertial><origin xyz="0.1 0 0.2"/><mass value="1"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="b"><inertial><origin xyz="0 0.1 -0.1"/><mass value="1"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="c"><inertial><origin xyz="0.2 0 0"/><mass value="1"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="d"><inertial><origin xyz="0 0 -0.3"/><mass value="1"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="e"><inertial><origin xyz="0.05 0 0"/><mass value="0.5"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="tool"><inertial><origin xyz="0 0 0.05"/><mass value="0.2"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="pan" type="revolute"><parent link="base"/><child link="a"/>
    <origin xyz="0 0 0.1"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="slide" type="prismatic"><parent link="a"/><child link="b"/>
    <origin xyz="0.1 0 0.3" rpy="0.3 0 0"/><axis xyz="1 0 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="roll" type="continuous"><parent link="b"/><child link="c"/>
    <origin xyz="0 0.2 0" rpy="0 0.4 0.1"/><axis xyz="1 1 0"/></joint>
  <joint name="lift" type="revolute"><parent link="c"/><child link="d"/>
    <origin xyz="0.4 0 0"/><axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="wrist" type="revolute"><parent link="a"/><child link="e"/>
    <origin xyz="0 -0.2 0.1"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="weld" type="fixed"><parent link="d"/><child link="tool"/><origin xyz="0 0 -0.4"/></joint>
</robot>"#;

fn start(floating: bool) -> (crate::model::Model, DVector<f64>) {
    let options = ImportOptions {
        floating_base: floating,
        ..ImportOptions::default()
    };
    let model = load_str(ARM, "arm.urdf", &options).unwrap().model;
    let values = [
        ("pan", 0.4),
        ("slide", 0.1),
        ("roll", -0.7),
        ("lift", 1.1),
        ("wrist", 0.2),
    ]
    .iter()
    .map(|(n, v)| (n.to_string(), vec![*v]))
    .collect();
    let q = State::from_joint_values(&model, &values).q;
    (model, q)
}

/// A tangent of the constraint manifold at `q`: `Z d` for a fixed `d`.
fn tangent(sys: &mut System, q: &DVector<f64>) -> DVector<f64> {
    let part = sys.partition(q);
    let eval = sys.evaluate(q, &part).unwrap();
    let dof = part.independent.len();
    let d = DVector::from_fn(dof, |i, _| 0.3 * (1.0 + i as f64).sin());
    sys.tangent_step(&part, &eval, &d)
}

fn joint_values(model: &crate::model::Model, q: &DVector<f64>) -> Vec<f64> {
    let state = State {
        q: q.clone(),
        branches: Default::default(),
    };
    state
        .joint_values(model)
        .into_iter()
        .filter(|(_, v)| v.len() == 1)
        .map(|(_, v)| v[0])
        .collect()
}

#[test]
fn the_path_leaves_along_the_tangent() {
    for floating in [false, true] {
        let (model, q) = start(floating);
        let mut sys = System::new(&model, Constraints::new(&model, &[]), Backend::Dense);
        let dq = tangent(&mut sys, &q);
        let r = Retraction::new(&model);
        assert_eq!(r.point(&q, &dq, 0.0), q);
        let h = 1e-6;
        let fd = (r.point(&q, &dq, h) - r.point(&q, &dq, -h)) / (2.0 * h);
        assert!(
            (&fd - &dq).amax() < 1e-8 * (1.0 + dq.amax()),
            "floating {floating}: {:.3e}",
            (&fd - &dq).amax()
        );
    }
}

#[test]
fn tree_joints_hold_and_joint_coordinates_move_linearly() {
    for floating in [false, true] {
        let (model, q) = start(floating);
        let mut sys = System::new(&model, Constraints::new(&model, &[]), Backend::Dense);
        let dq = tangent(&mut sys, &q);
        let r = Retraction::new(&model);
        let theta = joint_values(&model, &q);
        let h = 1e-6;
        let rate: Vec<f64> = joint_values(&model, &r.point(&q, &dq, h))
            .iter()
            .zip(joint_values(&model, &r.point(&q, &dq, -h)))
            .map(|(a, b)| (a - b) / (2.0 * h))
            .collect();
        assert!(rate.iter().all(|x| x.abs() > 1e-3), "every joint moves");
        for alpha in [0.3, 1.0, 2.5] {
            let qa = r.point(&q, &dq, alpha);
            sys.residual(&qa);
            let residual = sys.dimensionless_residual();
            assert!(residual < 1e-13, "α {alpha}: ‖DΦ‖ {residual:.3e}");
            for (k, value) in joint_values(&model, &qa).iter().enumerate() {
                let expected = theta[k] + alpha * rate[k];
                assert!(
                    (value - expected).abs() < 1e-8,
                    "floating {floating}, α {alpha}, joint {k}: {value} against {expected}"
                );
            }
            // The straight line leaves the tree joints at second order.
            sys.residual(&(&q + &dq * alpha));
            assert!(sys.dimensionless_residual() > 1e-4 * alpha * alpha);
        }
    }
}
