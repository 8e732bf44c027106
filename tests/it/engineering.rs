//! Stability, reactions, locks, units and unbounded energy.
use crate::common::builders::{chain, inertia, initial, linear, lock, pendulum};
use crate::common::*;
use approx::assert_abs_diff_eq;
use nalgebra::{Isometry3, Matrix3, Vector3};
use restpose::model::{JointId, JointKind, ModelBuilder, Spring, SpringEnd, SpringMode};
use restpose::urdf::{load_file, ImportOptions};
use restpose::Options;

/// A 2 kg bar with its centre of mass `scale` from a pivot about z, gravity `9.81 scale`
/// along −y (lengths in metres for `scale` 1, millimetres for 1000).
fn bar(scale: f64, kind: JointKind) -> (ModelBuilder, JointId) {
    let com = Vector3::new(scale, 0.0, 0.0);
    let (mut b, pivot) = pendulum("bar", kind, 2.0, com, inertia(0.01, 0.6, 0.6));
    b.set_gravity(Vector3::new(0.0, -9.81 * scale, 0.0));
    (b, pivot)
}

/// Started exactly upright (a maximum, zero gradient), the pendulum leaves along the negative
/// curvature and ends hanging down; with `allow_unstable` it stays and says `unstable`.
#[test]
fn inverted_start_ends_at_the_stable_equilibrium() {
    let (mut b, pivot) = bar(1.0, JointKind::Continuous);
    initial(&mut b, pivot, 0, std::f64::consts::FRAC_PI_2);
    let m = b.build().unwrap();
    let (s, r) = solve(&m);
    assert_abs_diff_eq!(
        s.joint(&m, "pivot").unwrap()[0],
        -std::f64::consts::FRAC_PI_2,
        epsilon = 1e-8
    );
    assert_eq!(
        r.stability.unwrap().verdict,
        restpose::solver::Verdict::Stable
    );
    assert!(r.diagnostics.negative_curvature_steps >= 1);

    let opts = Options {
        allow_unstable: true,
        ..Default::default()
    };
    let (s, r) = restpose::solve(&m, &opts).unwrap();
    assert!(r.converged());
    assert_abs_diff_eq!(
        s.joint(&m, "pivot").unwrap()[0],
        std::f64::consts::FRAC_PI_2,
        epsilon = 1e-12
    );
    assert_eq!(
        r.stability.unwrap().verdict,
        restpose::solver::Verdict::Unstable
    );
}

/// A locked joint holds the gravity torque: m g x_com, by hand.
#[test]
fn lock_holding_torque_equals_gravity_torque() {
    let angle: f64 = -0.4;
    let (mut b, pivot) = bar(1.0, JointKind::Continuous);
    lock(&mut b, pivot, angle);
    let m = b.build().unwrap();
    let (s, r) = solve(&m);
    assert_eq!(r.dof, 0);
    assert_abs_diff_eq!(s.joint(&m, "pivot").unwrap()[0], angle, epsilon = 1e-12);
    let (_, re) = r.reactions.iter().find(|(n, _)| n == "pivot").unwrap();
    // Gravity torque about +z of the weight (0, −19.62) at (cos a, sin a): −19.62 cos a; the
    // joint holds it with the opposite torque.
    assert_abs_diff_eq!(re.torque_world[2], 19.62 * angle.cos(), epsilon = 1e-9);
    assert_abs_diff_eq!(re.force_world[1], 19.62, epsilon = 1e-9);
}

/// Same mechanism in metres and in millimetres (lengths and gravity × 1000, masses and
/// stiffnesses in consistent units unchanged): same angle, same partition, same iterations,
/// energy × 10⁶.
#[test]
fn metres_and_millimetres_agree() {
    let sprung = |s: f64| {
        let (mut b, pivot) = bar(s, JointKind::Continuous);
        let body = b.joint(pivot).unwrap().bodies[1];
        let end = |body, x: f64, y: f64| SpringEnd {
            body,
            point: Vector3::new(x, y, 0.0),
        };
        b.add_spring(Spring {
            name: "k".into(),
            ends: [end(body, 2.0 * s, 0.0), end(None, -s, -2.0 * s)],
            free_length: 0.5 * s,
            law: linear(30.0),
            mode: SpringMode::Both,
        });
        initial(&mut b, pivot, 0, -0.3);
        b.build().unwrap()
    };
    let m1 = sprung(1.0);
    let m2 = sprung(1000.0);
    let (s1, r1) = solve(&m1);
    let (s2, r2) = restpose::solve(
        &m2,
        &Options {
            gradient_tolerance: 1e-2,
            ..Default::default()
        },
    )
    .unwrap();
    assert!(r2.converged());
    assert_abs_diff_eq!(
        s1.joint(&m1, "pivot").unwrap()[0],
        s2.joint(&m2, "pivot").unwrap()[0],
        epsilon = 1e-8
    );
    assert_eq!(r1.independent_coordinates, r2.independent_coordinates);
    assert_eq!(r1.iterations, r2.iterations);
    assert_abs_diff_eq!(r2.energy.total / 1e6, r1.energy.total, epsilon = 1e-8);
}

/// A prismatic joint along gravity with nothing holding it: reported, not iterated forever.
#[test]
fn unbounded_energy_is_detected() {
    let mut b = ModelBuilder::new("drop");
    let body = b.add_rigid_body("box", 1.0, Vector3::zeros(), Matrix3::identity());
    let id = Isometry3::identity();
    b.add_joint("slide", JointKind::Prismatic, None, id, Some(body), id);
    let m = b.build().unwrap();
    let (_, r) = restpose::solve(&m, &Options::default()).unwrap();
    assert_eq!(r.termination, restpose::Termination::Unbounded);
}

/// The spring's energy at the slider-crank's equilibrium, by hand from the link poses, is
/// part of the reported total, and the breakdown sums to it.
#[test]
fn energy_breakdown_sums_and_spring_energy_by_hand() {
    let m = robot("slider_crank");
    let (s, r) = solve(&m);
    let e = r.energy;
    assert_abs_diff_eq!(
        e.gravity + e.springs + e.joint_springs + e.loads,
        e.total,
        epsilon = 1e-12
    );
    let slider = s.link_pose(&m, "slider").unwrap().translation.vector;
    let l = (nalgebra::Vector3::new(0.6, 0.0, 0.0) - slider).norm();
    assert_abs_diff_eq!(e.springs, 0.5 * 500.0 * (l - 0.15).powi(2), epsilon = 1e-12);
    let crank = s.joint(&m, "crank_joint").unwrap()[0];
    assert_abs_diff_eq!(e.joint_springs, 0.5 * 2.0 * crank * crank, epsilon = 1e-12);
    // Load −20 N along x on the slider: minus its work.
    assert_abs_diff_eq!(e.loads, 20.0 * slider.x, epsilon = 1e-12);
}

#[test]
fn cli_lock_overrides_and_unknown_joint_is_an_error() {
    let opts = ImportOptions {
        locks: vec![("nope".into(), 0, Some(0.0))],
        ..Default::default()
    };
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/robots/pendulum.urdf");
    let err = load_file(path, &opts).unwrap_err().to_string();
    assert!(err.contains("nope"), "{err}");
}

/// Links welded by fixed joints share one body but keep their own reported poses (the
/// importer's welding: the mechanism is URDF text).
#[test]
fn merged_fixed_links_report_their_poses() {
    let text = r#"<robot name="flange" xmlns:mech="urn:urdf-mech:1">
      <link name="base"/>
      <link name="arm"><inertial><origin xyz="0.5 0 0"/><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
      <link name="tool"><inertial><mass value="0.5"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
      <link name="tip"/>
      <joint name="shoulder" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 1 0"/></joint>
      <joint name="flange" type="fixed"><parent link="arm"/><child link="tool"/><origin xyz="1 0 0" rpy="0 0 1.5707963267948966"/></joint>
      <joint name="tcp" type="fixed"><parent link="tool"/><child link="tip"/><origin xyz="0.1 0 0"/></joint>
      <mech:joint_spring joint="shoulder" stiffness="50"/>
    </robot>"#;
    let m = model_from(text);
    assert_eq!(m.bodies().len(), 1, "arm, tool and tip are one body");
    let (s, r) = solve(&m);
    assert_eq!(r.dof, 1);
    let th = s.joint(&m, "shoulder").unwrap()[0];
    // Balance: 50 θ = g (1·0.5 cos θ + 0.5·1 cos θ) about +y (weight along −z).
    assert_abs_diff_eq!(50.0 * th, 9.81 * (0.5 + 0.5) * th.cos(), epsilon = 1e-9);
    let tip = s.link_pose(&m, "tip").unwrap();
    // tip = Ry(θ) · (1, 0.1, 0) (the flange turns the tool by 90° about z).
    assert_abs_diff_eq!(tip.translation.x, th.cos(), epsilon = 1e-12);
    assert_abs_diff_eq!(tip.translation.y, 0.1, epsilon = 1e-12);
    assert_abs_diff_eq!(tip.translation.z, -th.sin(), epsilon = 1e-12);
    assert_verified_minimum(&m, &s);
}

/// A floating body hung from the world by three springs finds its rest pose.
#[test]
fn floating_body_hung_on_springs_solves() {
    let mut b = ModelBuilder::new("hung");
    let body = b.add_rigid_body("box", 2.0, Vector3::zeros(), Matrix3::identity());
    for (name, x, y) in [
        ("a", 0.1, 0.0),
        ("b", -0.05, 0.08660254037844387),
        ("c", -0.05, -0.08660254037844387),
    ] {
        let end = |body, z: f64| SpringEnd {
            body,
            point: Vector3::new(x, y, z),
        };
        b.add_spring(Spring {
            name: name.into(),
            ends: [end(Some(body), 0.0), end(None, 2.0)],
            free_length: 1.0,
            law: linear(400.0),
            mode: SpringMode::Both,
        });
    }
    let m = b.build().unwrap();
    let (s, r) = solve(&m);
    assert_eq!(r.dof, 6);
    // Three parallel springs of 400 N/m, 120° apart around the centre of mass, carry 2 kg
    // equally: stretch 2·9.81/1200 below z = 1.
    let z = s.link_pose(&m, "box").unwrap().translation.z;
    assert_abs_diff_eq!(z, 1.0 - 2.0 * 9.81 / 1200.0, epsilon = 1e-9);
    assert_verified_minimum(&m, &s);
}

/// Mode shapes are joint-coordinate changes along the softest eigenvector: the pendulum's is
/// its one joint; the slider-crank's keeps the loop closed (the slider does not turn:
/// crank + crank pin + wrist pin angles sum to zero).
#[test]
fn mode_shapes_are_feasible_joint_motions() {
    let m = robot("pendulum");
    let (_, r) = solve(&m);
    let s = r.stability.unwrap();
    assert_eq!(s.modes.len(), 1);
    assert_abs_diff_eq!(s.modes[0]["pivot"][0].abs(), 1.0, epsilon = 1e-12);
    let m = robot("slider_crank");
    let (_, r) = solve(&m);
    let mode = &r.stability.unwrap().modes[0];
    let sum = mode["crank_joint"][0] + mode["crank_pin"][0] + mode["wrist_pin"][0];
    assert!(sum.abs() < 1e-9, "{mode:?}");
    assert!(mode["crank_joint"][0].abs() > 0.1);
}

/// A planar arm locked straight out: each joint's holding torque equals the gravity torque of
/// the links it carries, by hand.
#[test]
fn locked_arm_holding_torques_equal_gravity_torques() {
    let n = 5;
    let (mut b, joints) = chain(n, true);
    for j in joints {
        lock(&mut b, j, 0.0);
    }
    let m = b.build().unwrap();
    let (_, r) = solve(&m);
    assert_eq!(r.dof, 0);
    for i in 0..n {
        // Links j ≥ i, 1 kg each, centres at x = 0.2 j + 0.1; joint i at x = 0.2 i; weight along
        // −z gives +y torque (x − x_i)·m·g about joint i; the lock holds its opposite.
        let gravity: f64 = (i..n)
            .map(|j| (0.2 * j as f64 + 0.1 - 0.2 * i as f64) * 9.81)
            .sum();
        let (_, re) = r
            .reactions
            .iter()
            .find(|(name, _)| *name == format!("joint{i}"))
            .unwrap();
        assert_abs_diff_eq!(re.torque_world[1], -gravity, epsilon = 1e-9);
    }
}

/// With limits ignored, a rest pose outside them is reported.
#[test]
fn rest_outside_limits_is_reported() {
    let (mut b, pivot) = bar(1.0, JointKind::Revolute);
    b.set_limits(pivot, 0.0, 0.5);
    let m = b.build().unwrap();
    let ignore = Options {
        limits: restpose::Limits::Ignore,
        ..Default::default()
    };
    let (s, r) = restpose::solve(&m, &ignore).unwrap();
    assert!(r.converged());
    let res = restpose::export::json::AnalysisResult::new(&m, &s, &r);
    assert_eq!(res.limit_violations.len(), 1);
    assert_eq!(res.limit_violations[0].joint, "pivot");
    assert_abs_diff_eq!(
        res.limit_violations[0].position,
        -std::f64::consts::FRAC_PI_2,
        epsilon = 1e-8
    );
    let fine = bar(1.0, JointKind::Continuous).0.build().unwrap();
    let (s, r) = solve(&fine);
    assert!(restpose::export::json::AnalysisResult::new(&fine, &s, &r)
        .limit_violations
        .is_empty());
}
