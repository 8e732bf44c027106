//! Stability, reactions, locks, units and unbounded energy.
use crate::common::*;
use approx::assert_abs_diff_eq;
use restpose::urdf::{load_str, ImportOptions};
use restpose::Options;

const BAR: &str = r#"<robot name="bar" xmlns:mech="urn:urdf-mech:1">
  <link name="world"/>
  <link name="bar"><inertial><origin xyz="SCALE 0 0"/><mass value="2"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.6" iyz="0" izz="0.6"/></inertial></link>
  <joint name="pivot" type="continuous"><parent link="world"/><child link="bar"/><axis xyz="0 0 1"/></joint>
  <mech:gravity xyz="0 -GRAV 0"/>
  EXTRA
</robot>"#;

fn bar(scale: f64, extra: &str) -> String {
    BAR.replace("SCALE", &scale.to_string())
        .replace("GRAV", &(9.81 * scale).to_string())
        .replace("EXTRA", extra)
}

/// Started exactly upright (a maximum, zero gradient), the pendulum leaves along the negative
/// curvature and ends hanging down; with `allow_unstable` it stays and says `unstable`.
#[test]
fn inverted_start_ends_at_the_stable_equilibrium() {
    let m = model_from(&bar(
        1.0,
        r#"<mech:initial joint="pivot" value="1.5707963267948966"/>"#,
    ));
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
    let m = model_from(&bar(
        1.0,
        &format!(r#"<mech:lock joint="pivot" value="{angle}"/>"#),
    ));
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
    let spring = |s: f64| {
        format!(
            r#"<mech:spring name="k" stiffness="30" free_length="{}"><end link="bar" xyz="{} 0 0"/><end link="world" xyz="{} {} 0"/></mech:spring>
               <mech:initial joint="pivot" value="-0.3"/>"#,
            0.5 * s,
            2.0 * s,
            -s,
            -2.0 * s
        )
    };
    let m1 = model_from(&bar(1.0, &spring(1.0)));
    let m2 = model_from(&bar(1000.0, &spring(1000.0)));
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
    let text = r#"<robot name="drop" xmlns:mech="urn:urdf-mech:1"><link name="world"/>
      <link name="box"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
      <joint name="slide" type="prismatic"><parent link="world"/><child link="box"/><axis xyz="0 0 1"/></joint></robot>"#;
    let m = model_from(text);
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
    let text = bar(1.0, "");
    let opts = ImportOptions {
        locks: vec![("nope".into(), 0, Some(0.0))],
        ..Default::default()
    };
    let err = load_str(&text, "t.urdf", &opts).unwrap_err().to_string();
    assert!(err.contains("nope"), "{err}");
}

/// Links welded by fixed joints share one body but keep their own reported poses; a floating
/// base held by springs finds its rest pose.
#[test]
fn merged_fixed_links_report_their_poses_and_floating_base_solves() {
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
    assert_eq!(m.bodies.len(), 1, "arm, tool and tip are one body");
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

    let hung = r#"<robot name="hung" xmlns:mech="urn:urdf-mech:1">
      <link name="box"><inertial><mass value="2"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
      <mech:spring name="a" stiffness="400" free_length="1"><end link="box" xyz="0.1 0 0"/><end link="world" xyz="0.1 0 2"/></mech:spring>
      <mech:spring name="b" stiffness="400" free_length="1"><end link="box" xyz="-0.05 0.08660254037844387 0"/><end link="world" xyz="-0.05 0.08660254037844387 2"/></mech:spring>
      <mech:spring name="c" stiffness="400" free_length="1"><end link="box" xyz="-0.05 -0.08660254037844387 0"/><end link="world" xyz="-0.05 -0.08660254037844387 2"/></mech:spring>
    </robot>"#;
    let opts = restpose::urdf::ImportOptions {
        floating_base: true,
        ..Default::default()
    };
    let m = restpose::urdf::load_str(hung, "h.urdf", &opts)
        .unwrap()
        .model;
    assert_eq!(m.bodies.len(), 1);
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
    let mut text = restpose::generate::chain(n, true);
    let locks: String = (0..n)
        .map(|i| format!("<mech:lock joint=\"joint{i}\" value=\"0\"/>"))
        .collect();
    text = text.replace("</robot>", &format!("{locks}</robot>"));
    let m = model_from(&text);
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
    let text = bar(1.0, "").replace(
        r#"<joint name="pivot" type="continuous">"#,
        r#"<joint name="pivot" type="revolute"><limit lower="0" upper="0.5"/>"#,
    );
    let m = model_from(&text);
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
    let fine = model_from(&bar(1.0, ""));
    let (s, r) = solve(&fine);
    assert!(restpose::export::json::AnalysisResult::new(&fine, &s, &r)
        .limit_violations
        .is_empty());
}
