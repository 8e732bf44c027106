//! Joint angles are real numbers, never wrapped into (−π, π] (issue 12 §2): locks, initial
//! values, springs, `verify` and the output all use the unwrapped angle, and a continuous
//! joint is tracked through the solve (a torsion spring winds up over several turns). Every
//! expectation is a hand computation written in the test.

use crate::common::builders::{inertia, initial, linear, lock, pendulum};
use approx::assert_abs_diff_eq;
use nalgebra::Vector3;
use restpose::model::{ForceLaw, JointId, JointKind, ModelBuilder};
use restpose::{urdf, Options};
use std::f64::consts::{PI, TAU};
use std::process::Command;

const M: f64 = 2.0;
const G: f64 = 9.81;
const L: f64 = 1.0;

/// A bar of mass `M` with its centre of mass `L` from a pivot about z (limits ±20), gravity
/// along −y: `V_gravity = M G L sin θ`.
fn bar(kind: JointKind) -> (ModelBuilder, JointId) {
    let (mut b, pivot) = pendulum(
        "p",
        kind,
        M,
        Vector3::new(L, 0.0, 0.0),
        inertia(0.01, 0.1, 0.1),
    );
    b.set_limits(pivot, -20.0, 20.0);
    b.set_gravity(Vector3::new(0.0, -G, 0.0));
    (b, pivot)
}

fn load(text: &str) -> restpose::Model {
    urdf::load_str(text, "<angles>", &Default::default())
        .unwrap()
        .model
}

/// Locked at ±3.5 rad with a spring (stiffness 3, reference 0): the state reads ±3.5, the
/// energy is `M G L sin θ + ½ 3 θ²` and the lock holds `dV/dθ = M G L cos θ + 3 θ`.
#[test]
fn spring_loaded_joint_locked_beyond_pi() {
    for theta in [3.5, -3.5] {
        let (mut b, pivot) = bar(JointKind::Revolute);
        b.add_joint_spring(pivot, 0, linear(3.0), 0.0);
        lock(&mut b, pivot, theta);
        let m = b.build().unwrap();
        let (s, r) = restpose::solve(&m, &Options::default()).unwrap();
        assert_abs_diff_eq!(s.joint(&m, "pivot").unwrap()[0], theta, epsilon = 1e-9);
        let v = M * G * L * theta.sin() + 0.5 * 3.0 * theta * theta;
        assert_abs_diff_eq!(r.energy.total, v, epsilon = 1e-9);
        assert_abs_diff_eq!(
            r.energy.joint_springs,
            0.5 * 3.0 * theta * theta,
            epsilon = 1e-9
        );
        let (_, reaction) = r.reactions.iter().find(|(n, _)| n == "pivot").unwrap();
        let torque = reaction.torque_joint[2].abs();
        let expected = (M * G * L * theta.cos() + 3.0 * theta).abs();
        assert_abs_diff_eq!(torque, expected, epsilon = 1e-6);
    }
}

/// Started at ±3.5 rad with the spring's rest there (reference ±3.5, stiffness 50): the rest
/// pose is on the same branch, `50 (θ − θ_ref) + M G L cos θ = 0`, solved here by Newton.
#[test]
fn spring_loaded_joint_started_beyond_pi() {
    for reference in [3.5, -3.5] {
        let (mut b, pivot) = bar(JointKind::Revolute);
        b.add_joint_spring(pivot, 0, linear(50.0), reference);
        initial(&mut b, pivot, 0, reference);
        let m = b.build().unwrap();
        let mut t: f64 = reference;
        for _ in 0..50 {
            t -= (50.0 * (t - reference) + M * G * L * t.cos()) / (50.0 - M * G * L * t.sin());
        }
        let (s, r) = restpose::solve(&m, &Options::default()).unwrap();
        assert!(r.converged(), "{:?}", r.termination);
        assert_abs_diff_eq!(s.joint(&m, "pivot").unwrap()[0], t, epsilon = 1e-7);
        let v = M * G * L * t.sin() + 25.0 * (t - reference).powi(2);
        assert_abs_diff_eq!(r.energy.total, v, epsilon = 1e-9);
    }
}

/// A continuous joint with a spring preloaded so that its rest is at 2.5 turns
/// (`F = −k·5π + k θ`): from θ = 0 the solve winds it up to `θ = 5π + M G L / k`
/// (`k (θ − 5π) + M G L cos θ = 0`, `cos θ ≈ −1` there), and the JSON reports that angle.
#[test]
fn continuous_spring_winds_up_two_and_a_half_turns() {
    let k = 200.0;
    let rest = 5.0 * PI;
    let (mut b, pivot) = bar(JointKind::Continuous);
    let law = ForceLaw::Linear {
        stiffness: k,
        preload: -k * rest,
    };
    b.add_joint_spring(pivot, 0, law, 0.0);
    let m = b.build().unwrap();
    let mut t: f64 = rest;
    for _ in 0..50 {
        t -= (k * (t - rest) + M * G * L * t.cos()) / (k - M * G * L * t.sin());
    }
    assert!((t - rest - M * G * L / k).abs() < 1e-2);
    let (s, r) = restpose::solve(&m, &Options::default()).unwrap();
    assert!(r.converged(), "{:?}", r.termination);
    let theta = s.joint(&m, "pivot").unwrap()[0];
    assert_abs_diff_eq!(theta, t, epsilon = 1e-7);
    let spring = -k * rest * t + 0.5 * k * t * t;
    assert_abs_diff_eq!(r.energy.joint_springs, spring, epsilon = 1e-6);
    assert_abs_diff_eq!(r.energy.gravity, M * G * L * t.sin(), epsilon = 1e-9);
    assert_eq!(
        r.stability.as_ref().unwrap().verdict,
        restpose::solver::Verdict::Stable
    );
    let json = restpose::export::json::AnalysisResult::new(&m, &s, &r);
    let v = serde_json::to_value(&json).unwrap();
    let reported = v["joints"]["pivot"]["position"][0].as_f64().unwrap();
    assert_abs_diff_eq!(reported, t, epsilon = 1e-7);
    // The verification of that answer reads the same branch and passes.
    let check = restpose::verify::verify(&m, &s, &Default::default()).unwrap();
    assert!(check.passed, "{:?}", check.max_imbalance);
}

fn ur5() -> String {
    std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/robots/ur5_class.urdf"
    ))
    .unwrap()
}

/// `verify` at wrist_3_joint = 3.5 evaluates the wrist spring (stiffness 10, reference 0) at
/// 3.5, not at 3.5 − 2π: the two poses are the same configuration, so their energies differ
/// by exactly `½ 10 (3.5² − (3.5 − 2π)²)`.
#[test]
fn verify_evaluates_springs_at_the_given_angle() {
    let m = load(&ur5());
    let at = |x: f64| {
        let values = [("wrist_3_joint".to_string(), vec![x])]
            .into_iter()
            .collect();
        let (s, _) = restpose::verify::pose_state(&m, &values).unwrap();
        assert_abs_diff_eq!(s.joint(&m, "wrist_3_joint").unwrap()[0], x, epsilon = 1e-12);
        s
    };
    let (a, b) = (at(3.5), at(3.5 - TAU));
    for id in m.body_ids() {
        let (pa, pb) = (a.body_pose(id), b.body_pose(id));
        assert!(
            pa.rotation.angle_to(&pb.rotation) < 1e-9,
            "same configuration"
        );
        assert!((pa.translation.vector - pb.translation.vector).amax() < 1e-12);
    }
    let va = restpose::verify::potential_energy(&m, &a).unwrap();
    let vb = restpose::verify::potential_energy(&m, &b).unwrap();
    assert_abs_diff_eq!(
        va - vb,
        5.0 * (3.5f64.powi(2) - (3.5 - TAU).powi(2)),
        epsilon = 1e-9
    );
}

/// A UR-class wrist (limits ±2π) started at 5 rad with its spring's rest moved to 4.5 rad:
/// it rests near 4.5 rad (not at 4.5 − 2π), the spring energy is that of the unwrapped
/// deflection, and `verify` accepts the answer.
#[test]
fn ur_wrist_at_five_radians() {
    let text = ur5()
        .replace(
            r#"<mech:joint_spring joint="wrist_3_joint" stiffness="10" reference="0.0"/>"#,
            r#"<mech:joint_spring joint="wrist_3_joint" stiffness="10" reference="4.5"/>"#,
        )
        .replace(
            r#"<mech:initial joint="wrist_3_joint" value="0.0"/>"#,
            r#"<mech:initial joint="wrist_3_joint" value="5"/>"#,
        );
    assert!(text.contains(r#"reference="4.5""#) && text.contains(r#"value="5""#));
    let m = load(&text);
    let start = restpose::solver::initial_state(&m);
    assert_abs_diff_eq!(
        start.joint(&m, "wrist_3_joint").unwrap()[0],
        5.0,
        epsilon = 1e-12
    );
    let (s, r) = restpose::solve(&m, &Options::default()).unwrap();
    assert!(r.converged(), "{:?}", r.termination);
    let w = s.joint(&m, "wrist_3_joint").unwrap()[0];
    assert!((w - 4.5).abs() < 0.05, "wrist_3 rests at {w}");
    let check = restpose::verify::verify(&m, &s, &Default::default()).unwrap();
    assert!(check.passed, "{:?}", check.max_imbalance);
    // The same configuration read on the principal branch would store ½·10·(w − 2π − 4.5)².
    let v = restpose::verify::potential_energy(&m, &s).unwrap();
    assert_abs_diff_eq!(v, r.energy.total, epsilon = 1e-9);
}

/// `--lock pivot=3.2` assembles and reports 3.2 (it failed with a loop-geometry message).
#[test]
fn cli_lock_beyond_pi() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("r.json");
    let st = Command::new(env!("CARGO_BIN_EXE_restpose"))
        .args([
            "analyze",
            concat!(env!("CARGO_MANIFEST_DIR"), "/robots/pendulum.urdf"),
            "--quiet",
            "--lock",
            "pivot=3.2",
            "--json",
        ])
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(
        st.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    let p = v["joints"]["pivot"]["position"][0].as_f64().unwrap();
    assert_abs_diff_eq!(p, 3.2, epsilon = 1e-9);
}
