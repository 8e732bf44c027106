//! Joint stops and ground contact (issue 13), each against an independent answer: closed
//! forms, and for the Solo-12 quadruped a rigid-contact solution computed without restpose
//! (`benches/peers/solo12_mujoco.py` on MuJoCo's import of the same file, saved in
//! `benches/peers/solo12_reference.json`).
use crate::common::*;
use approx::assert_abs_diff_eq;
use nalgebra::{DVector, UnitQuaternion, Vector3};
use restpose::model::Friction;
use restpose::solver::{ContactState, Verdict};
use restpose::urdf::{load_file, load_str, ImportOptions};
use restpose::{Limits, Options, State};

/// A 2 kg bar with its centre of mass 1 m from a hinge about z, gravity −y: `θ` from +x, the
/// energy `V = m g sin θ + ½ k θ²`, `dV/dθ = m g cos θ + k θ`.
fn pendulum(k: f64, lower: f64, upper: f64, initial: f64) -> restpose::Model {
    model_from(&format!(
        r#"<robot name="stop" xmlns:mech="urn:urdf-mech:1">
  <link name="world"/>
  <link name="bar"><inertial><origin xyz="1 0 0"/><mass value="2"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.6" iyz="0" izz="0.6"/></inertial></link>
  <joint name="pivot" type="revolute"><parent link="world"/><child link="bar"/><axis xyz="0 0 1"/>
    <limit lower="{lower}" upper="{upper}" effort="10" velocity="1"/></joint>
  <mech:gravity xyz="0 -9.81 0"/>
  <mech:joint_spring joint="pivot" stiffness="{k}"/>
  <mech:initial joint="pivot" value="{initial}"/>
</robot>"#
    ))
}

const MG: f64 = 2.0 * 9.81;

/// Gravity pulls the bar below its lower stop: it rests on the stop, which holds
/// `dV/dθ = m g cos θ + k θ` there.
#[test]
fn pendulum_rests_on_its_lower_stop_with_the_closed_form_effort() {
    let (k, lower) = (5.0, -0.5);
    let m = pendulum(k, lower, 1.0, 0.3);
    let (s, r) = solve(&m);
    assert_abs_diff_eq!(s.joint(&m, "pivot").unwrap()[0], lower, epsilon = 1e-10);
    assert_eq!(r.active_limits.len(), 1);
    let l = &r.active_limits[0];
    assert_eq!((l.joint.as_str(), l.bound.as_str()), ("pivot", "lower"));
    assert_abs_diff_eq!(l.effort, MG * lower.cos() + k * lower, epsilon = 1e-8);
    assert!(l.effort > 0.0);
    // With limits ignored, the bar hangs through the stop to `m g cos θ + k θ = 0`.
    let ignore = Options {
        limits: Limits::Ignore,
        ..Default::default()
    };
    let (s, r) = restpose::solve(&m, &ignore).unwrap();
    let th = s.joint(&m, "pivot").unwrap()[0];
    assert!(th < lower && r.active_limits.is_empty());
    assert_abs_diff_eq!(MG * th.cos() + k * th, 0.0, epsilon = 1e-7);
}

/// An upper stop holds against a spring pulling past it: effort `dV/dθ` (negative).
#[test]
fn spring_pushes_the_bar_onto_its_upper_stop() {
    let text = r#"<robot name="up" xmlns:mech="urn:urdf-mech:1">
  <link name="world"/>
  <link name="bar"><inertial><origin xyz="1 0 0"/><mass value="2"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.6" iyz="0" izz="0.6"/></inertial></link>
  <joint name="pivot" type="revolute"><parent link="world"/><child link="bar"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="0.2" effort="10" velocity="1"/></joint>
  <mech:gravity xyz="0 -9.81 0"/>
  <mech:joint_spring joint="pivot" stiffness="40" reference="1"/>
</robot>"#;
    let m = model_from(text);
    let (s, r) = solve(&m);
    let th = s.joint(&m, "pivot").unwrap()[0];
    assert_abs_diff_eq!(th, 0.2, epsilon = 1e-10);
    let l = &r.active_limits[0];
    assert_eq!(l.bound, "upper");
    // dV/dθ = m g cos θ + k (θ − 1) < 0 at 0.2: the applied generalized force −dV/dθ pushes
    // θ up, and the stop balances it with dV/dθ < 0.
    let dv = MG * 0.2f64.cos() + 40.0 * (0.2 - 1.0);
    assert!(dv < 0.0);
    assert_abs_diff_eq!(l.effort, dv, epsilon = 1e-8);
}

/// Started on its lower stop with a spring strong enough to lift it off, the bar leaves the
/// stop (the stop's multiplier has the wrong sign) and rests inside its range where
/// `m g cos θ + k θ = 0`.
#[test]
fn a_stop_pulling_the_wrong_way_is_released() {
    let (k, lower) = (20.0, -1.2);
    let m = pendulum(k, lower, 1.0, lower);
    let (s, r) = solve(&m);
    let th = s.joint(&m, "pivot").unwrap()[0];
    assert!(r.active_limits.is_empty(), "{:?}", r.active_limits);
    assert!(th > lower + 0.1, "θ = {th}");
    assert_abs_diff_eq!(MG * th.cos() + k * th, 0.0, epsilon = 1e-7);
    assert!(r.active_set_changes >= 2, "{}", r.active_set_changes);
    assert_verified_minimum(&m, &s);
}

const BOX: &str = r#"<robot name="box" xmlns:mech="urn:urdf-mech:1">
  <link name="box">
    <inertial><mass value="2"/><inertia ixx="0.02" iyy="0.03" izz="0.04" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.4 0.3 0.2"/></geometry></collision>
  </link>
  <mech:ground/>
</robot>"#;

fn floating(text: &str) -> restpose::Model {
    let opts = ImportOptions {
        floating_base: true,
        ..Default::default()
    };
    load_str(text, "test.urdf", &opts).unwrap().model
}

/// A box released tilted 0.5 m above the ground rests on its largest face: `V = m g h/2`,
/// four supporting vertices, normal forces summing to `m g`; sliding and yaw are neutral.
#[test]
fn a_tilted_box_falls_and_rests_flat_on_a_face() {
    let m = floating(BOX);
    let tilt = UnitQuaternion::from_scaled_axis(Vector3::new(0.25, -0.2, 0.1));
    let mut q = DVector::zeros(7);
    q[2] = 0.5;
    q[3] = tilt.w;
    q[4] = tilt.i;
    q[5] = tilt.j;
    q[6] = tilt.k;
    let start = State {
        q,
        branches: Default::default(),
    };
    let (s, r) = restpose::solve_from(&m, start, &Options::default()).unwrap();
    assert!(r.converged(), "{:?}", r.termination);
    assert_abs_diff_eq!(r.energy.total, MG * 0.1, epsilon = 1e-9);
    assert_eq!(r.contacts.len(), 4, "{:?}", r.contacts);
    let total: f64 = r.contacts.iter().map(|c| c.normal_force).sum();
    assert_abs_diff_eq!(total, MG, epsilon = 1e-9);
    for c in &r.contacts {
        assert!(c.normal_force >= -1e-9 && c.gap.abs() < 1e-9);
        assert_abs_diff_eq!(c.point_world[2], 0.0, epsilon = 1e-9);
        assert_eq!(c.state, ContactState::Touching);
    }
    // The box's z axis is vertical.
    let pose = s.link_pose(&m, "box").unwrap();
    assert_abs_diff_eq!((pose.rotation * Vector3::z()).z.abs(), 1.0, epsilon = 1e-9);
    assert_eq!(r.stability.unwrap().verdict, Verdict::Neutral);
}

/// A sphere on a tilted frictionless plane slides away (unbounded); with sticking friction it
/// rests, needing `tan(slope)` of friction, and is reported slipping when `mu` is below that.
#[test]
fn friction_holds_a_ball_on_a_slope_and_says_when_it_cannot() {
    let slope = 0.3f64;
    let text = format!(
        r#"<robot name="ball" xmlns:mech="urn:urdf-mech:1">
  <link name="ball">
    <inertial><mass value="1"/><inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><sphere radius="0.1"/></geometry></collision>
  </link>
  <mech:ground normal="{} 0 {}" xyz="0 0 -0.1"/>
</robot>"#,
        slope.sin(),
        slope.cos()
    );
    let m = floating(&text);
    let stick = Options {
        friction: Friction::Stick,
        ..Default::default()
    };
    let (_, r) = restpose::solve(&m, &stick).unwrap();
    assert!(r.converged(), "{:?}", r.termination);
    assert_eq!(r.contacts.len(), 1);
    let c = &r.contacts[0];
    assert_abs_diff_eq!(c.normal_force, 9.81 * slope.cos(), epsilon = 1e-8);
    assert_abs_diff_eq!(c.required_friction, slope.tan(), epsilon = 1e-8);
    assert_eq!(c.state, ContactState::Sticking);
    let weak = Options {
        mu: Some(0.2),
        ..stick.clone()
    };
    let (_, r) = restpose::solve(&m, &weak).unwrap();
    assert_eq!(r.contacts[0].state, ContactState::Slipping);
    let (_, r) = restpose::solve(&m, &Options::default()).unwrap();
    assert!(!r.converged());
}

/// The Solo-12 quadruped (published file, foot spheres and joint springs added) standing on
/// the ground with a floating base, against the rigid-contact solution of
/// `benches/peers/solo12_mujoco.py`: joint angles, base height, foot forces, energy.
#[test]
fn solo12_stands_like_the_independent_rigid_contact_solution() {
    let dir = env!("CARGO_MANIFEST_DIR");
    let reference: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(format!("{dir}/benches/peers/solo12_reference.json")).unwrap(),
    )
    .unwrap();
    let opts = ImportOptions {
        floating_base: true,
        ..Default::default()
    };
    let m = load_file(format!("{dir}/robots/solo12/solo12_ground.urdf"), &opts)
        .unwrap()
        .model;
    for (run, key, friction) in [
        ("none", "rigid", Friction::None),
        ("stick", "rigid_material", Friction::Stick),
    ] {
        let rigid = &reference["runs"][run][key];
        let options = Options {
            friction,
            ..Default::default()
        };
        let (s, r) = restpose::solve(&m, &options).unwrap();
        assert!(r.converged(), "{run}: {:?}", r.termination);
        assert_abs_diff_eq!(
            r.energy.total,
            rigid["potential_energy"].as_f64().unwrap(),
            epsilon = 1e-7
        );
        for (joint, value) in rigid["joints"].as_object().unwrap() {
            let th = s.joint(&m, joint).unwrap()[0];
            assert!(
                (th - value.as_f64().unwrap()).abs() < 1e-6,
                "{run}: {joint} {th} vs {value}"
            );
        }
        assert_eq!(r.contacts.len(), 4);
        let total: f64 = r.contacts.iter().map(|c| c.normal_force).sum();
        assert_abs_diff_eq!(
            total,
            rigid["sum_normal_force"].as_f64().unwrap(),
            epsilon = 1e-6
        );
        for foot in rigid["feet"].as_array().unwrap() {
            let link = foot["link"].as_str().unwrap();
            let c = r.contacts.iter().find(|c| c.link == link).unwrap();
            assert_abs_diff_eq!(
                c.normal_force,
                foot["normal_force"].as_f64().unwrap(),
                epsilon = 1e-3
            );
        }
        let base = s.link_pose(&m, "base_link").unwrap();
        let ground = m.grounds[0].origin.z;
        assert_abs_diff_eq!(
            base.translation.vector.z - ground,
            rigid["base"]["height"].as_f64().unwrap(),
            epsilon = 1e-6
        );
    }
}
