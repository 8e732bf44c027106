//! Joint stops and ground contact (issue 13), each against an independent answer: closed
//! forms, and for the Solo-12 quadruped a rigid-contact solution computed without restpose
//! (`benches/peers/solo12_mujoco.py` on MuJoCo's import of the same file, saved in
//! `benches/peers/solo12_reference.json`).
use crate::common::contact::{
    assert_sticks_on_slope, assert_verified_contacts, check, verify_with_options,
};
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
/// four supporting vertices carrying `m g / 4` each; sliding and yaw are neutral.
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
        // Statically indeterminate (four rows, three degrees of freedom): the least-norm
        // distribution, by symmetry `m g / 4` on each vertex.
        assert_abs_diff_eq!(c.normal_force, MG / 4.0, epsilon = 1e-9);
        assert!(c.gap.abs() < 1e-9);
        assert_abs_diff_eq!(c.point_world[2], 0.0, epsilon = 1e-9);
        assert_eq!(c.state, ContactState::Touching);
    }
    // The box's z axis is vertical.
    let pose = s.link_pose(&m, "box").unwrap();
    assert_abs_diff_eq!((pose.rotation * Vector3::z()).z.abs(), 1.0, epsilon = 1e-9);
    assert_eq!(r.stability.unwrap().verdict, Verdict::Neutral);
}

/// A body on a plane sloping by `slope` about y: a uniform ball of radius 0.1 m
/// (`box = false`) or the 0.4 × 0.3 × 0.2 m box.
fn on_slope(slope: f64, box_: bool) -> restpose::Model {
    let shape = if box_ {
        r#"<box size="0.4 0.3 0.2"/>"#
    } else {
        r#"<sphere radius="0.1"/>"#
    };
    floating(&format!(
        r#"<robot name="slope" xmlns:mech="urn:urdf-mech:1">
  <link name="body">
    <inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry>{shape}</geometry></collision>
  </link>
  <mech:ground normal="{} 0 {}" xyz="0 0 -0.1"/>
</robot>"#,
        slope.sin(),
        slope.cos()
    ))
}

/// A box on a frictionless slope slides away (unbounded). With sticking friction it rests
/// on its face: the ground's force balances the weight, `Σ f_n = m g cos(slope)` and
/// `|Σ f_t| = m g sin(slope)` (closed form); with `mu` below `tan(slope)` a contact slips. A
/// uniform ball does not rest even with sticking friction: it rolls (no slip at the touching
/// point), and the search gives up.
#[test]
fn friction_holds_a_box_on_a_slope_and_says_when_it_cannot() {
    let slope = 0.3f64;
    let m = on_slope(slope, true);
    let stick = Options {
        friction: Friction::Stick,
        ..Default::default()
    };
    let (s, rep) = restpose::solve(&m, &stick).unwrap();
    assert_sticks_on_slope(&rep, 9.81, slope);
    assert_verified_contacts(&m, &s, Friction::Stick);
    let weak = Options {
        mu: Some(0.2),
        ..stick.clone()
    };
    let (_, rep) = restpose::solve(&m, &weak).unwrap();
    assert!(rep
        .contacts
        .iter()
        .any(|c| c.state == ContactState::Slipping));
    let (_, rep) = restpose::solve(&m, &Options::default()).unwrap();
    assert!(!rep.converged());
    let (_, rep) = restpose::solve(&on_slope(slope, false), &stick).unwrap();
    assert!(!rep.converged(), "{:?}", rep.termination);
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
    // Sticking: the foot rolls from where it first touched (module docs of `active_set`), as
    // in the rolling-contact reference.
    for (run, key, friction) in [
        ("none", "rigid", Friction::None),
        ("stick", "rigid_rolling", Friction::Stick),
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
        let ground = m.grounds()[0].origin.z;
        assert_abs_diff_eq!(
            base.translation.vector.z - ground,
            rigid["base"]["height"].as_f64().unwrap(),
            epsilon = 1e-6
        );
    }
}

// ---- verify: poses resting on stops and grounds -----------------------------------------

use restpose::verify::{verify_using, Tolerances, Unilaterals};
use restpose::LinearAlgebra;

/// analyze's answer on a stop passes verify, which finds the stop's effort itself (closed
/// form `m g cos θ + k θ`); with limits ignored the same pose needs that effort from the joint
/// and fails.
#[test]
fn verify_accepts_a_pose_on_a_stop_and_finds_its_effort() {
    let (k, lower) = (5.0, -0.5);
    let m = pendulum(k, lower, 1.0, 0.3);
    let (s, _) = solve(&m);
    let v = check(&m, &s, Friction::None);
    assert!(v.passed, "{v:?}");
    assert_eq!(v.unilateral.active_limits.len(), 1);
    let l = &v.unilateral.active_limits[0];
    assert_eq!(l.bound, "lower");
    assert_abs_diff_eq!(l.effort, MG * lower.cos() + k * lower, epsilon = 1e-8);
    assert!(v.unilateral.failures.is_empty() && v.unilateral.penetration == 0.0);
    assert!(v.unilateral.complementarity <= 1e-8 * l.effort.abs());
    let ignore = Unilaterals {
        limits: Limits::Ignore,
        ..Default::default()
    };
    let v = verify_with_options(&m, &s, &Tolerances::default(), &ignore).unwrap();
    assert!(!v.passed);
    let worst = v.max_imbalance.unwrap();
    assert_eq!(worst.joint, "pivot");
    assert_abs_diff_eq!(worst.effort, MG * lower.cos() + k * lower, epsilon = 1e-8);
}

/// A bar on its lower stop whose spring lifts it off: the stop would have to pull, so the pose
/// fails, naming the stop and the pulling effort `m g cos θ + k θ < 0`; a pose beyond the stop
/// fails as well.
#[test]
fn verify_refuses_a_stop_that_would_have_to_pull_and_a_pose_beyond_a_stop() {
    let (k, lower) = (20.0, -1.2);
    let m = pendulum(k, lower, 1.0, lower);
    let pulling = MG * lower.cos() + k * lower;
    assert!(pulling < -1.0);
    let on_stop = State::from_joint_values(&m, &[("pivot".to_string(), vec![lower])].into());
    let v = check(&m, &on_stop, Friction::None);
    assert!(!v.passed);
    // The stop that would pull, then the effort the joint needs instead.
    assert_eq!(
        v.unilateral.failures.len(),
        2,
        "{:?}",
        v.unilateral.failures
    );
    assert!(v.unilateral.failures[0].contains("pivot.lower_limit"));
    assert!(v.unilateral.failures[1].contains("`pivot` (dof 0) needs an effort"));
    assert!(v.unilateral.failures[0].contains(&format!("{pulling:.3e}")));
    // The stop carries nothing; the joint needs the whole effort.
    assert_abs_diff_eq!(v.unilateral.active_limits[0].effort, 0.0, epsilon = 1e-12);
    assert_abs_diff_eq!(v.max_imbalance.unwrap().effort, pulling, epsilon = 1e-8);
    let beyond = State::from_joint_values(&m, &[("pivot".to_string(), vec![lower - 0.01])].into());
    let v = check(&m, &beyond, Friction::None);
    assert!(!v.passed);
    assert_abs_diff_eq!(v.unilateral.penetration, 0.01, epsilon = 1e-12);
    assert!(v
        .unilateral
        .failures
        .iter()
        .any(|f| f.contains("beyond its stop")));
}

/// The box flat on the ground passes with `m g / 4` on each vertex (the minimum-norm
/// distribution); pushed 1 mm into the ground it fails (penetration), lifted 1 mm it fails
/// (nothing holds it: the floating base's unassigned force is its weight).
#[test]
fn verify_accepts_the_flat_box_and_refuses_it_in_or_above_the_ground() {
    let m = floating(BOX);
    let mut q = DVector::zeros(7);
    q[2] = 0.1;
    q[3] = 1.0;
    let flat = State {
        q,
        branches: Default::default(),
    };
    let v = check(&m, &flat, Friction::None);
    assert!(v.passed, "{v:?}");
    assert_eq!(v.unilateral.contacts.len(), 4);
    for c in &v.unilateral.contacts {
        assert_abs_diff_eq!(c.normal_force, MG / 4.0, epsilon = 1e-9);
    }
    assert_eq!(v.stability.unwrap().verdict, Verdict::Neutral);
    let mut sunk = flat.clone();
    sunk.q[2] -= 1e-3;
    let v = check(&m, &sunk, Friction::None);
    assert!(!v.passed);
    assert_abs_diff_eq!(v.unilateral.penetration, 1e-3, epsilon = 1e-12);
    assert_eq!(
        v.unilateral.failures.len(),
        4,
        "{:?}",
        v.unilateral.failures
    );
    let mut lifted = flat.clone();
    lifted.q[2] += 1e-3;
    let v = check(&m, &lifted, Friction::None);
    assert!(!v.passed && v.unilateral.contacts.is_empty());
    assert!(v.unassigned > 0.1 * MG, "{}", v.unassigned);
    // analyze's own answer from a tilted start passes too.
    let (s, _) = restpose::solve_from(&m, flat, &Options::default()).unwrap();
    assert!(check(&m, &s, Friction::None).passed);
}

/// The box on the slope: analyze's sticking answer passes verify with friction, whose
/// forces balance the weight (closed form); frictionless the same pose fails (it would slide),
/// and with `mu` below `tan(slope)` it fails as slipping. A uniform ball resting where the
/// box's face is fails: it would roll.
#[test]
fn verify_checks_friction_on_the_slope() {
    let slope = 0.3f64;
    let m = on_slope(slope, true);
    let stick = Options {
        friction: Friction::Stick,
        ..Default::default()
    };
    let (s, _) = restpose::solve(&m, &stick).unwrap();
    let v = check(&m, &s, Friction::Stick);
    assert!(v.passed, "{v:?}");
    let fnorm: f64 = v.unilateral.contacts.iter().map(|c| c.normal_force).sum();
    let ft: Vector3<f64> = v
        .unilateral
        .contacts
        .iter()
        .map(|c| Vector3::from(c.tangential_force))
        .sum();
    assert_abs_diff_eq!(fnorm, 9.81 * slope.cos(), epsilon = 1e-8);
    assert_abs_diff_eq!(ft.norm(), 9.81 * slope.sin(), epsilon = 1e-8);
    assert!(!check(&m, &s, Friction::None).passed);
    let weak = Unilaterals {
        friction: Friction::Stick,
        mu: Some(0.2),
        ..Default::default()
    };
    let v = verify_with_options(&m, &s, &Tolerances::default(), &weak).unwrap();
    assert!(!v.passed);
    assert!(v
        .unilateral
        .contacts
        .iter()
        .any(|c| c.state == ContactState::Slipping));
    assert!(
        v.unilateral.failures[0].contains("friction cones"),
        "{:?}",
        v.unilateral.failures
    );
    // A ball touching the slope with its centre 0.1 m above it: the friction at the touching
    // point cannot stop it rolling.
    let ball = on_slope(slope, false);
    let mut q = DVector::zeros(7);
    q[3] = 1.0;
    let n = Vector3::new(slope.sin(), 0.0, slope.cos());
    let c = Vector3::new(0.0, 0.0, -0.1) + n * 0.1;
    q[0] = c.x;
    q[2] = c.z;
    let v = check(
        &ball,
        &State {
            q,
            branches: Default::default(),
        },
        Friction::Stick,
    );
    assert_eq!(v.unilateral.contacts.len(), 1);
    assert!(!v.passed && v.unassigned > 0.01, "{v:?}");
}

/// analyze's Solo-12 answers (frictionless and sticking) pass verify with the same friction
/// setting; the frictionless verify refuses the sticking pose (its feet need friction), and a
/// pose with the base pushed 2 mm down (feet into the ground) fails.
#[test]
fn verify_accepts_solo12_standing_and_refuses_it_sunk() {
    let dir = env!("CARGO_MANIFEST_DIR");
    let opts = ImportOptions {
        floating_base: true,
        ..Default::default()
    };
    let m = load_file(format!("{dir}/robots/solo12/solo12_ground.urdf"), &opts)
        .unwrap()
        .model;
    for friction in [Friction::None, Friction::Stick] {
        let options = Options {
            friction,
            ..Default::default()
        };
        let (s, r) = restpose::solve(&m, &options).unwrap();
        let v = check(&m, &s, friction);
        assert!(v.passed, "{friction:?}: {v:?}");
        assert_eq!(v.unilateral.contacts.len(), 4);
        for c in &v.unilateral.contacts {
            let a = r.contacts.iter().find(|a| a.link == c.link).unwrap();
            assert_abs_diff_eq!(c.normal_force, a.normal_force, epsilon = 1e-6);
            assert_abs_diff_eq!(c.required_friction, a.required_friction, epsilon = 1e-6);
        }
        if friction == Friction::Stick {
            assert!(!check(&m, &s, Friction::None).passed);
        }
        let mut sunk = s.clone();
        for b in 0..m.bodies().len() {
            sunk.q[7 * b + 2] -= 2e-3;
        }
        let v = check(&m, &sunk, friction);
        assert!(!v.passed);
        assert_abs_diff_eq!(v.unilateral.penetration, 2e-3, epsilon = 1e-9);
    }
}

// ---- a spring-loaded arm folding onto the floor, a rope lying on the ground --------------

/// A two-link arm on a hinge 0.5 m above the floor, both joints about y with springs
/// (`k₁ = 5`, `k₂ = 3` N m/rad, reference straight along +x), links 0.4 m and 1 kg with their
/// centres of mass at mid-length, a sphere of radius 0.02 m at the tip. A turn `θ` about y
/// takes +x to `(cos θ, 0, −sin θ)`.
const ARM: &str = r#"<robot name="arm" xmlns:mech="urn:urdf-mech:1">
  <link name="world"/>
  <link name="upper"><inertial><origin xyz="0.2 0 0"/><mass value="1"/>
    <inertia ixx="1e-4" ixy="0" ixz="0" iyy="0.0134" iyz="0" izz="0.0134"/></inertial></link>
  <link name="fore"><inertial><origin xyz="0.2 0 0"/><mass value="1"/>
    <inertia ixx="1e-4" ixy="0" ixz="0" iyy="0.0134" iyz="0" izz="0.0134"/></inertial>
    <collision><origin xyz="0.4 0 0"/><geometry><sphere radius="0.02"/></geometry></collision></link>
  <joint name="shoulder" type="continuous"><parent link="world"/><child link="upper"/>
    <origin xyz="0 0 0.5"/><axis xyz="0 1 0"/></joint>
  <joint name="elbow" type="continuous"><parent link="upper"/><child link="fore"/>
    <origin xyz="0.4 0 0"/><axis xyz="0 1 0"/></joint>
  <mech:joint_spring joint="shoulder" stiffness="5"/>
  <mech:joint_spring joint="elbow" stiffness="3"/>
  <mech:initial joint="shoulder" value="0.3"/>
  <mech:initial joint="elbow" value="0.3"/>
  <mech:ground/>
</robot>"#;

/// The arm's energy in joint coordinates, and its tip height.
fn arm_energy(t1: f64, t2: f64) -> (f64, f64) {
    let (h, l, g) = (0.5, 0.4, 9.81);
    let z1 = h - 0.5 * l * t1.sin();
    let z2 = h - l * t1.sin() - 0.5 * l * (t1 + t2).sin();
    let tip = h - l * t1.sin() - l * (t1 + t2).sin();
    (
        g * (z1 + z2) + 0.5 * 5.0 * t1 * t1 + 0.5 * 3.0 * t2 * t2,
        tip,
    )
}

/// Gravity folds the arm until its tip rests on the floor. Independent answer: on the contact
/// (`tip = 0.02`) the elbow angle is a function of the shoulder angle,
/// `θ₁ + θ₂ = asin((0.5 − 0.4 sin θ₁ − 0.02)/0.4)` (the branch with the forearm pointing down),
/// and the energy is minimized over `θ₁` by golden-section search; the free minimum would put
/// the tip through the floor, so the contact is active.
#[test]
fn a_spring_loaded_arm_folds_onto_the_floor() {
    let m = model_from(ARM);
    let (s, r) = solve(&m);
    // Without the floor: Newton on the joint-space gradient from the same start.
    let free = {
        let (mut t1, mut t2) = (0.3f64, 0.3f64);
        for _ in 0..100 {
            let h = 1e-5;
            let v = |a: f64, b: f64| arm_energy(a, b).0;
            let g1 = (v(t1 + h, t2) - v(t1 - h, t2)) / (2.0 * h);
            let g2 = (v(t1, t2 + h) - v(t1, t2 - h)) / (2.0 * h);
            t1 -= 0.02 * g1;
            t2 -= 0.02 * g2;
        }
        (t1, t2)
    };
    assert!(
        arm_energy(free.0, free.1).1 < 0.0,
        "the free arm would go through the floor"
    );
    // On the floor, both branches of the asin are scanned and the lower energy kept.
    let branch = |t1: f64, first: bool| {
        let s12 = ((0.5 - 0.4 * t1.sin() - 0.02) / 0.4).clamp(-1.0, 1.0);
        let t12 = if first {
            s12.asin()
        } else {
            std::f64::consts::PI - s12.asin()
        };
        (t12 - t1, arm_energy(t1, t12 - t1).0)
    };
    let mut best = (f64::INFINITY, 0.0, 0.0);
    for first in [true, false] {
        let (mut a, mut b) = (-0.5f64, 1.5f64);
        // Coarse scan, then golden section around the best sample.
        let mut t = a;
        let mut arg = a;
        let mut low = f64::INFINITY;
        while t <= b {
            let v = branch(t, first).1;
            if v < low {
                low = v;
                arg = t;
            }
            t += 1e-3;
        }
        a = arg - 2e-3;
        b = arg + 2e-3;
        let gr = (5f64.sqrt() - 1.0) / 2.0;
        for _ in 0..200 {
            let c = b - gr * (b - a);
            let d = a + gr * (b - a);
            if branch(c, first).1 < branch(d, first).1 {
                b = d;
            } else {
                a = c;
            }
        }
        let t1 = 0.5 * (a + b);
        let (t2, v) = branch(t1, first);
        if v < best.0 {
            best = (v, t1, t2);
        }
    }
    let (v, t1, t2) = best;
    assert_abs_diff_eq!(r.energy.total, v, epsilon = 1e-9);
    assert_abs_diff_eq!(s.joint(&m, "shoulder").unwrap()[0], t1, epsilon = 1e-6);
    assert_abs_diff_eq!(s.joint(&m, "elbow").unwrap()[0], t2, epsilon = 1e-6);
    assert_eq!(r.contacts.len(), 1);
    assert!(r.contacts[0].normal_force > 0.1, "{:?}", r.contacts);
    assert_verified_contacts(&m, &s, Friction::None);
}

/// The generated `n`-link rope hangs from the world onto the ground: converges; every contact
/// reported touches (`|g| ≤ 1e-9` m) and pushes; complementarity `|g| f_n ≤ 1e-9 m · max f_n`;
/// `verify` finds no penetration and balances it with non-negative forces; the energy equals
/// the one written in joint coordinates (`energies::rope`); the vertical forces balance the
/// weight (anchor reaction plus normal forces = `n m g`).
fn rope_lies_partly_on_the_ground(n: usize) {
    rope_on_the_ground_with(
        n,
        &Options::default(),
        &[LinearAlgebra::Dense, LinearAlgebra::Sparse],
    );
}

/// [`rope_lies_partly_on_the_ground`] solved with `options`, verified on the `paths` given.
fn rope_on_the_ground_with(
    n: usize,
    options: &Options,
    paths: &[LinearAlgebra],
) -> restpose::Report {
    let m = model_from(&restpose::generate::rope(n));
    let (s, r) = restpose::solve(&m, options).unwrap_or_else(|e| panic!("{e}"));
    assert!(r.converged(), "{:?}", r.termination);
    assert!(r.contacts.len() > n / 2, "{} contacts", r.contacts.len());
    let fmax = r.contacts.iter().fold(0.0f64, |a, c| a.max(c.normal_force));
    for c in &r.contacts {
        assert!(c.gap.abs() <= 1e-9 && c.normal_force >= 0.0, "{c:?}");
        assert!(c.gap.abs() * c.normal_force <= 1e-9 * fmax, "{c:?}");
    }
    // Both verification paths pass it. Their forces are not compared to `1e-9` of the largest
    // here (as `check` does on the small models): the pose is balanced to the gradient
    // tolerance (1e-8 J), which through the 0.05 m links leaves the forces determined to about
    // 1e-8 N, and the dense least squares and the sparse basic solution place that residue
    // differently (1.5e-8 N at 300 links).
    for &path in paths {
        let v = verify_using(
            &m,
            &s,
            &Tolerances::default(),
            &Unilaterals::default(),
            path,
        )
        .unwrap();
        assert!(v.passed, "{path:?}: {:?}", v.unilateral.failures);
        assert_eq!(v.unilateral.penetration, 0.0, "{path:?}");
    }
    let th: Vec<f64> = (0..n)
        .map(|i| s.joint(&m, &format!("joint{i}")).unwrap()[0])
        .collect();
    assert_abs_diff_eq!(r.energy.total, energies::rope(n, &th), epsilon = 1e-9);
    let anchor = r.reactions.iter().find(|(j, _)| j == "joint0").unwrap();
    let normal: f64 = r.contacts.iter().map(|c| c.normal_force).sum();
    assert_abs_diff_eq!(
        anchor.1.force_world[2] + normal,
        n as f64 * 0.05 * 9.81,
        epsilon = 1e-8
    );
    r
}

#[test]
fn a_rope_lies_partly_on_the_ground() {
    rope_lies_partly_on_the_ground(100);
}

/// The 1,000-link rope (677 contacts at rest) converges by the direct solve, without the
/// gravity ramp (`--load-steps 1`; issue 13: it failed there before, a contact row pivoted on
/// the angle of a link turning vertical above its contact left `Φ_u` nearly singular).
/// Verified on the sparse path only (the dense one takes minutes at this size).
#[test]
fn a_1000_link_rope_converges_by_the_direct_solve() {
    let options = Options {
        load_steps: 1,
        ..Default::default()
    };
    let r = rope_on_the_ground_with(1000, &options, &[LinearAlgebra::Sparse]);
    assert_eq!(r.diagnostics.load_steps, 1);
    assert_eq!(r.contacts.len(), 677);
}

/// The 300-link rope (201 contacts): cheap since each contact row is eliminated with its link
/// (issue 13; it took 1.6 s before, 0.1 s now).
#[test]
fn a_300_link_rope_lies_partly_on_the_ground() {
    rope_lies_partly_on_the_ground(300);
}

// ---- the start pose of a floating base ---------------------------------------------------

/// `<mech:base xyz rpy/>` starts the floating box 0.5 m up, turned 90° about x: it falls onto
/// its 0.4 × 0.2 m face (`V = m g · 0.15`, closed form). From the default start (at the origin,
/// half in the ground) it rests on its largest face (`V = m g · 0.1`). The importer option
/// (the CLI's `--base-xyz` / `--base-rpy`) overrides the file.
#[test]
fn a_floating_base_starts_at_its_base_pose() {
    let text = BOX.replace(
        "<mech:ground/>",
        r#"<mech:ground/><mech:base xyz="0 0 0.5" rpy="1.5707963267948966 0 0"/>"#,
    );
    let m = floating(&text);
    let start = restpose::solver::initial_state(&m);
    let pose = start.link_pose(&m, "box").unwrap();
    assert_abs_diff_eq!(pose.translation.vector.z, 0.5, epsilon = 1e-12);
    assert_abs_diff_eq!((pose.rotation * Vector3::y()).z, 1.0, epsilon = 1e-12);
    let (s, r) = solve(&m);
    // The height of the centre of mass to 1 nm (the contacts' rows hold to the corrector's
    // tolerance).
    assert_abs_diff_eq!(r.energy.total, MG * 0.15, epsilon = MG * 1e-9);
    assert_eq!(r.contacts.len(), 4);
    assert_verified_contacts(&m, &s, Friction::None);
    let (_, r) = solve(&floating(BOX));
    assert_abs_diff_eq!(r.energy.total, MG * 0.1, epsilon = MG * 1e-9);
    let opts = ImportOptions {
        floating_base: true,
        base_pose: Some(nalgebra::Isometry3::translation(0.0, 0.0, 0.3)),
        ..Default::default()
    };
    let m = load_str(&text, "test.urdf", &opts).unwrap().model;
    let start = restpose::solver::initial_state(&m);
    let pose = start.link_pose(&m, "box").unwrap();
    assert_abs_diff_eq!(pose.translation.vector.z, 0.3, epsilon = 1e-12);
    assert_abs_diff_eq!(pose.rotation.angle(), 0.0, epsilon = 1e-12);
    let (_, r) = solve(&m);
    assert_abs_diff_eq!(r.energy.total, MG * 0.1, epsilon = MG * 1e-9);
}

/// The command line: `verify --pose` reads analyze's result JSON of the Solo-12 with sticking
/// feet, including the floating base's pose (`links`), and passes it with `--friction stick`
/// (exit 0, the contacts in its JSON); frictionless it fails (exit 4, the feet need friction).
#[test]
fn verify_command_accepts_analyze_json_of_a_robot_standing_on_the_ground() {
    let dir = env!("CARGO_MANIFEST_DIR");
    let file = format!("{dir}/robots/solo12/solo12_ground.urdf");
    let tmp = std::env::temp_dir().join(format!("restpose-contact-{}", std::process::id()));
    std::fs::create_dir_all(&tmp).unwrap();
    let (result, checked) = (tmp.join("r.json"), tmp.join("v.json"));
    let run = |args: &[&str]| {
        std::process::Command::new(env!("CARGO_BIN_EXE_restpose"))
            .args(args)
            .output()
            .unwrap()
    };
    let a = run(&[
        "analyze",
        &file,
        "--floating-base",
        "--friction",
        "stick",
        "-q",
        "--json",
        result.to_str().unwrap(),
    ]);
    assert!(a.status.success(), "{}", String::from_utf8_lossy(&a.stderr));
    let v = run(&[
        "verify",
        &file,
        "--floating-base",
        "--friction",
        "stick",
        "-q",
        "--pose",
        result.to_str().unwrap(),
        "--json",
        checked.to_str().unwrap(),
    ]);
    assert_eq!(
        v.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&v.stderr)
    );
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&checked).unwrap()).unwrap();
    assert_eq!(json["passed"], true);
    assert_eq!(json["contacts"].as_array().unwrap().len(), 4);
    assert_eq!(json["penetration"], 0.0);
    let v = run(&[
        "verify",
        &file,
        "--floating-base",
        "-q",
        "--pose",
        result.to_str().unwrap(),
    ]);
    assert_eq!(v.status.code(), Some(4));
    let _ = std::fs::remove_dir_all(&tmp);
}

// ---- obstacles: collision shapes of world-fixed links -----------------------------------

/// A 1 kg ball (radius 0.1 m) on a hinge: a massless arm of 0.5 m from a pivot at the origin
/// (about y), the ball's centre at its end, resting on a world-fixed box obstacle whose top is
/// at `z = −0.3`. Closed form: the ball touches when its centre is at `z = −0.2`, i.e. the arm
/// at `θ = asin(0.2/0.5)` below the horizontal; the contact force is vertical (the box's top
/// face) and acts below the ball's centre, so moments about the pivot give
/// `f_n · 0.5 cos θ = m g · 0.5 cos θ`, `f_n = m g = 9.81 N`; `V = m g z = −1.962 J`.
const BALL_ON_BOX: &str = r#"<robot name="ball_on_box" xmlns:mech="urn:urdf-mech:1">
  <link name="world"/>
  <link name="table">
    <collision><origin xyz="0.5 0 -0.8"/><geometry><box size="1 1 1"/></geometry></collision>
  </link>
  <joint name="mount" type="fixed"><parent link="world"/><child link="table"/></joint>
  <link name="arm">
    <inertial><origin xyz="0.5 0 0"/><mass value="1"/><inertia ixx="0.004" iyy="0.004" izz="0.004" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0.5 0 0"/><geometry><sphere radius="0.1"/></geometry></collision>
  </link>
  <joint name="pivot" type="continuous"><parent link="world"/><child link="arm"/><axis xyz="0 1 0"/></joint>
  <mech:obstacle link="table"/>
  <mech:contact link="arm"/>
</robot>"#;

#[test]
fn a_ball_rests_on_a_fixed_box() {
    let m = model_from(BALL_ON_BOX);
    assert_eq!(m.obstacles().len(), 1);
    let (s, r) = solve(&m);
    let th = s.joint(&m, "pivot").unwrap()[0];
    assert_abs_diff_eq!(th, (0.2f64 / 0.5).asin(), epsilon = 1e-9);
    assert_eq!(r.contacts.len(), 1, "{:?}", r.contacts);
    let c = &r.contacts[0];
    assert_eq!(c.ground, "table");
    assert_abs_diff_eq!(c.normal_force, 9.81, epsilon = 1e-8);
    assert_abs_diff_eq!(c.point_world[2], -0.3, epsilon = 1e-9);
    assert_abs_diff_eq!(r.energy.total, -9.81 * 0.2, epsilon = 1e-8);
    assert_verified_contacts(&m, &s, Friction::None);
    // Pushed 1 mm into the box, verify refuses it.
    let deeper = State::from_joint_values(&m, &[("pivot".to_string(), vec![th + 0.002])].into());
    let v = check(&m, &deeper, Friction::None);
    assert!(!v.passed && v.unilateral.penetration > 5e-4, "{v:?}");
}

/// A floating 2 kg box (0.4 × 0.3 × 0.2 m) released tilted above a world-fixed table link
/// (a 1 × 1 × 0.1 m slab whose top is at `z = 0.75`): it rests flat on the table, four vertices
/// carrying `m g / 4` each, `V = m g (0.75 + 0.1)` (closed form).
#[test]
fn a_box_rests_on_a_fixed_table_link() {
    let text = r#"<robot name="box_on_table" xmlns:mech="urn:urdf-mech:1">
  <link name="world"/>
  <link name="table">
    <collision><origin xyz="0 0 0.7"/><geometry><box size="1 1 0.1"/></geometry></collision>
  </link>
  <joint name="table_mount" type="fixed"><parent link="world"/><child link="table"/></joint>
  <link name="box">
    <inertial><mass value="2"/><inertia ixx="0.02" iyy="0.03" izz="0.04" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.4 0.3 0.2"/></geometry></collision>
  </link>
  <joint name="free" type="floating"><parent link="world"/><child link="box"/></joint>
  <mech:obstacle link="table"/>
  <mech:contact link="box"/>
  <mech:initial joint="free" value="0.05 -0.02 1.0 0.9950 0.0600 -0.0500 0.0500"/>
</robot>"#;
    let m = model_from(text);
    let (s, r) = solve(&m);
    assert!(r.converged(), "{:?}", r.termination);
    assert_abs_diff_eq!(r.energy.total, MG * 0.85, epsilon = MG * 1e-9);
    assert_eq!(r.contacts.len(), 4, "{:?}", r.contacts);
    for c in &r.contacts {
        assert_eq!(c.ground, "table");
        assert_abs_diff_eq!(c.normal_force, MG / 4.0, epsilon = 1e-8);
        assert_abs_diff_eq!(c.point_world[2], 0.75, epsilon = 1e-9);
    }
    assert_verified_contacts(&m, &s, Friction::None);
}

/// A 400-link rope lying on the ground (268 links on it), verified on the sparse path (above
/// 40 bodies): analyze's answer passes, with the closed-form contact forces of the straight
/// lying part (each link's weight `w` at its middle, no spring torque where the rope is flat:
/// every interior tip carries `w`, the free end `w / 2`); the same pose with the ground 1 mm
/// higher fails (every lying tip 1 mm inside), and with a 2 N upward load on link 300's tip
/// the contact there would have to pull, is named, and the pose fails.
#[test]
fn verify_checks_a_rope_of_400_links_on_the_ground_on_the_sparse_path() {
    let text = restpose::generate::rope(400);
    let m = model_from(&text);
    let (s, _) = solve(&m);
    let (tol, uni) = (Tolerances::default(), Unilaterals::default());
    let v = verify_using(&m, &s, &tol, &uni, LinearAlgebra::Auto).unwrap();
    assert!(v.passed, "{:?}", v.unilateral.failures);
    let c = &v.unilateral.contacts;
    assert!(c.len() > 250, "{} contacts", c.len());
    let w = 0.05 * 9.81;
    let force = |link: &str| {
        c.iter()
            .find(|c| c.link == link)
            .unwrap_or_else(|| panic!("{link} does not touch"))
            .normal_force
    };
    for k in 200..399 {
        assert_abs_diff_eq!(force(&format!("link{k}")), w, epsilon = 1e-9);
    }
    assert_abs_diff_eq!(force("link399"), w / 2.0, epsilon = 1e-9);
    assert!(v.stability.is_some());
    // The same pose, the ground 1 mm higher.
    let raised = model_from(&text.replace("<mech:ground/>", r#"<mech:ground xyz="0 0 0.001"/>"#));
    let v = verify_using(&raised, &s, &tol, &uni, LinearAlgebra::Auto).unwrap();
    assert!(!v.passed);
    assert_abs_diff_eq!(v.unilateral.penetration, 1e-3, epsilon = 1e-9);
    let inside = v
        .unilateral
        .failures
        .iter()
        .filter(|f| f.contains("inside the ground"))
        .count();
    assert_eq!(inside, c.len());
    // The same pose, link 300's tip lifted by 2 N > w: its contact would have to pull.
    let lifted = model_from(&text.replace(
        "<mech:ground/>",
        r#"<mech:ground/><mech:force name="lift" link="link300" xyz="0.05 0 0" force="0 0 2"/>"#,
    ));
    let v = verify_using(&lifted, &s, &tol, &uni, LinearAlgebra::Auto).unwrap();
    assert!(!v.passed);
    assert_eq!(v.unilateral.penetration, 0.0);
    // The contact that would pull, then the efforts the joints need instead.
    let f = &v.unilateral.failures;
    assert_eq!(
        f.iter()
            .filter(|f| f.contains("would have to pull"))
            .count(),
        1,
        "{f:?}"
    );
    assert!(
        f[0].starts_with("`link300.contact[") && f[0].contains("would have to pull"),
        "{f:?}"
    );
    assert!(
        f[1..].iter().all(|f| f.contains("needs an effort")),
        "{f:?}"
    );
    let pull: f64 = f[0]
        .split("pull (")
        .nth(1)
        .and_then(|r| r.split(' ').next())
        .and_then(|x| x.parse().ok())
        .unwrap_or_else(|| panic!("{f:?}"));
    // The load acts at the contact point itself: the contact would need `w − 2` N.
    assert_abs_diff_eq!(pull, w - 2.0, epsilon = 1e-3);
    assert!(v.max_imbalance.unwrap().effort.abs() > 0.01);
}

/// The flat box pressed down by 100 N near one corner of its top: the minimum-norm support
/// would pull at the opposite corner (`F/4 (1 − x̄/a − ȳ/b) < 0`, `(x̄, ȳ)` where the total load
/// acts, `a × b` the half sides), yet the pose rests on the other corners, and passes on both
/// paths. The support is statically indeterminate (four corners, three balance equations), and
/// the paths pick different non-negative supports: the sparse path drops the pulling corner
/// and solves again, which gives the three-corner lever rule `F (a − x̄)/2a`, `F (b − ȳ)/2b`
/// and the rest; the dense path's non-negative least squares stops at another corner of the
/// set of non-negative balances. Both are checked as balances (total force and moments).
#[test]
fn verify_rests_the_pressed_box_on_its_corners_on_both_paths() {
    let text = BOX.replace(
        "<mech:ground/>",
        r#"<mech:ground/><mech:force name="press" link="box" xyz="0.18 0.12 0.1" force="0 0 -100"/>"#,
    );
    let m = floating(&text);
    let mut q = DVector::zeros(7);
    q[2] = 0.1;
    q[3] = 1.0;
    let flat = State {
        q,
        branches: Default::default(),
    };
    let (a, b) = (0.2, 0.15);
    let f = MG + 100.0;
    let (x, y) = (100.0 * 0.12 / f * 0.18 / 0.12, 100.0 * 0.12 / f);
    assert!(1.0 - x / a - y / b < -0.3, "the minimum-norm support pulls");
    let uni = Unilaterals::default();
    let tol = Tolerances::default();
    let mut seen = Vec::new();
    for la in [LinearAlgebra::Dense, LinearAlgebra::Sparse] {
        let v = verify_using(&m, &flat, &tol, &uni, la).unwrap();
        assert!(v.passed, "{la:?}: {v:?}");
        assert!(v.unilateral.failures.is_empty(), "{la:?}");
        assert!(
            v.unassigned <= v.effort_tolerance,
            "{la:?}: {}",
            v.unassigned
        );
        let c = &v.unilateral.contacts;
        assert_eq!(c.len(), 4);
        let total: f64 = c.iter().map(|c| c.normal_force).sum();
        let mx: f64 = c.iter().map(|c| c.normal_force * c.point_world[0]).sum();
        let my: f64 = c.iter().map(|c| c.normal_force * c.point_world[1]).sum();
        assert_abs_diff_eq!(total, f, epsilon = 1e-9);
        assert_abs_diff_eq!(mx, f * x, epsilon = 1e-9);
        assert_abs_diff_eq!(my, f * y, epsilon = 1e-9);
        assert!(c.iter().all(|c| c.normal_force >= -1e-9), "{la:?}: {c:?}");
        seen.push(v);
    }
    let at = |sx: f64, sy: f64| {
        seen[1]
            .unilateral
            .contacts
            .iter()
            .find(|c| c.point_world[0] * sx > 0.0 && c.point_world[1] * sy > 0.0)
            .unwrap()
            .normal_force
    };
    assert_abs_diff_eq!(at(-1.0, -1.0), 0.0, epsilon = 1e-9);
    assert_abs_diff_eq!(at(-1.0, 1.0), f * (a - x) / (2.0 * a), epsilon = 1e-9);
    assert_abs_diff_eq!(at(1.0, -1.0), f * (b - y) / (2.0 * b), epsilon = 1e-9);
    assert_abs_diff_eq!(
        at(1.0, 1.0),
        f - f * (a - x) / (2.0 * a) - f * (b - y) / (2.0 * b),
        epsilon = 1e-9
    );
    // On three corners sliding and yaw are free and cost nothing; tipping lifts the load.
    for v in &seen {
        assert_eq!(v.stability.as_ref().unwrap().verdict, Verdict::Neutral);
    }
}

/// The flat box pressed down by 100 N on its top's diagonal: the load's line of action meets
/// the ground on the diagonal through two corners, and the dense path's non-negative least
/// squares rests it on those two alone, the other two touching without force. Held by the two
/// loaded corners only, the box would tip about the diagonal (the load and the centre of mass
/// drop: a negative eigenvalue); each way of tipping pushes one of the unloaded corners into
/// the ground, so on the critical cone (module `solver::cone`) only sliding and yaw are free:
/// neutral on both paths and in analyze, never unstable.
#[test]
fn a_box_pressed_on_its_diagonal_does_not_tip_over_its_unloaded_corners() {
    let text = BOX.replace(
        "<mech:ground/>",
        r#"<mech:ground/><mech:force name="press" link="box" xyz="0.16 0.12 0.1" force="0 0 -100"/>"#,
    );
    let m = floating(&text);
    let mut q = DVector::zeros(7);
    q[2] = 0.1;
    q[3] = 1.0;
    let flat = State {
        q,
        branches: Default::default(),
    };
    let uni = Unilaterals::default();
    let tol = Tolerances::default();
    let mut unloaded = 0;
    for la in [LinearAlgebra::Dense, LinearAlgebra::Sparse] {
        let v = verify_using(&m, &flat, &tol, &uni, la).unwrap();
        assert!(v.passed, "{la:?}: {v:?}");
        let c = &v.unilateral.contacts;
        assert_eq!(c.len(), 4);
        unloaded += c.iter().filter(|c| c.normal_force <= 1e-9).count();
        let s = v.stability.as_ref().unwrap();
        assert_eq!(s.verdict, Verdict::Neutral, "{la:?}: {s:?}");
    }
    // The case this test is about: some corner touches without force.
    assert!(unloaded >= 1, "every corner carries a force");
    let (s, r) = restpose::solve_from(&m, flat, &Options::default()).unwrap();
    assert!(r.converged());
    assert_eq!(r.stability.unwrap().verdict, Verdict::Neutral);
    for la in [LinearAlgebra::Dense, LinearAlgebra::Sparse] {
        let v = verify_using(&m, &s, &tol, &uni, la).unwrap();
        assert!(v.passed, "{la:?}: {v:?}");
        assert_eq!(v.stability.unwrap().verdict, Verdict::Neutral, "{la:?}");
    }
}

/// The bar balanced straight up (`θ = π/2`, spring neutral there, `k < m g`: the top of the
/// energy `m g sin θ + ½ k (θ − π/2)²`) and resting on its lower stop at `π/2` with no effort:
/// the stop blocks falling back but not falling forward, so the rest is unstable (before the
/// critical cone, analyze judged it with the stop held, where nothing can move).
#[test]
fn a_bar_balanced_on_a_stop_that_carries_nothing_is_unstable() {
    let half_pi = std::f64::consts::FRAC_PI_2;
    let text = r#"<robot name="up" xmlns:mech="urn:urdf-mech:1">
  <link name="world"/>
  <link name="bar"><inertial><origin xyz="1 0 0"/><mass value="2"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.6" iyz="0" izz="0.6"/></inertial></link>
  <joint name="pivot" type="revolute"><parent link="world"/><child link="bar"/><axis xyz="0 0 1"/>
    <limit lower="1.5707963267948966" upper="3" effort="10" velocity="1"/></joint>
  <mech:gravity xyz="0 -9.81 0"/>
  <mech:joint_spring joint="pivot" stiffness="5" reference="1.5707963267948966"/>
  <mech:initial joint="pivot" value="1.5707963267948966"/>
</robot>"#;
    let m = model_from(text);
    let options = Options {
        allow_unstable: true,
        ..Default::default()
    };
    let (s, r) = restpose::solve(&m, &options).unwrap();
    assert!(r.converged(), "{:?}", r.termination);
    assert_abs_diff_eq!(s.joint(&m, "pivot").unwrap()[0], half_pi, epsilon = 1e-10);
    assert_eq!(r.active_limits.len(), 1);
    assert!(r.active_limits[0].effort.abs() < 1e-9);
    let st = r.stability.unwrap();
    assert_eq!(st.verdict, Verdict::Unstable, "{st:?}");
    // verify agrees on both paths (the stop's effort is zero to rounding on each).
    for la in [LinearAlgebra::Dense, LinearAlgebra::Sparse] {
        let v = verify_using(&m, &s, &Tolerances::default(), &Unilaterals::default(), la).unwrap();
        assert!(v.passed, "{la:?}: {v:?}");
        assert_eq!(v.stability.unwrap().verdict, Verdict::Unstable, "{la:?}");
    }
}

/// A sticking 1 kg ball (radius 0.1 m) with its centre of mass 0.05 m to the side of its
/// centre, on flat ground, rolls a quarter turn until the centre of mass is below the centre:
/// the touching point moves by the rolled arc `ρ π/2` (closed form, rolling without slip),
/// `V = −m g 0.05`. Each round stops at the roll limit (`solver::rolling::ROLL_LIMIT`) and the
/// sphere is re-anchored, so that no round pivots a quarter turn about one material point.
#[test]
fn an_unbalanced_ball_rolls_a_quarter_turn_on_flat_ground() {
    let m = floating(
        r#"<robot name="flat" xmlns:mech="urn:urdf-mech:1">
  <link name="body">
    <inertial><origin xyz="0.05 0 0"/><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><sphere radius="0.1"/></geometry></collision>
  </link>
  <mech:ground xyz="0 0 -0.1"/>
</robot>"#,
    );
    let options = Options {
        friction: Friction::Stick,
        ..Default::default()
    };
    let (s, r) = restpose::solve(&m, &options).unwrap();
    assert!(r.converged(), "{:?}", r.termination);
    assert_abs_diff_eq!(r.energy.total, -9.81 * 0.05, epsilon = 1e-9);
    assert_eq!(r.contacts.len(), 1);
    let c = &r.contacts[0];
    assert_eq!(c.state, ContactState::Sticking);
    assert_abs_diff_eq!(
        c.point_world[0],
        0.1 * std::f64::consts::FRAC_PI_2,
        epsilon = 1e-9
    );
    assert_abs_diff_eq!(c.point_world[1], 0.0, epsilon = 1e-9);
    assert_abs_diff_eq!(c.normal_force, 9.81, epsilon = 1e-9);
    assert_verified_contacts(&m, &s, Friction::Stick);
}
