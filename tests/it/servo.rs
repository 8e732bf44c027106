//! Position servos (`--servo`, `ImportOptions::servos`): a joint spring `τ = −k (θ − θ_ref)`
//! reported as the actuator torque, with references from the initial pose, a joint_states
//! file or an SRDF `group_state`.

use restpose::urdf::{load_str, srdf_state, ImportOptions, ServoRequest};
use restpose::Options;
use std::process::Command;

/// A 2 kg bar, centre of mass 1 m from a pivot about z, gravity −y: `V = m g sin θ`.
const BAR: &str = r#"<robot name="bar">
  <link name="world"/>
  <link name="bar">
    <inertial><origin xyz="1 0 0"/><mass value="2"/>
      <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.6667" iyz="0" izz="0.6667"/></inertial>
  </link>
  <joint name="pivot" type="continuous">
    <parent link="world"/><child link="bar"/><axis xyz="0 0 1"/>
  </joint>
</robot>"#;

fn bar(servos: Vec<ServoRequest>, reference: Vec<(String, f64)>) -> restpose::Model {
    let options = ImportOptions {
        gravity: nalgebra::Vector3::new(0.0, -9.81, 0.0),
        servos,
        servo_reference: reference,
        ..Default::default()
    };
    load_str(BAR, "bar.urdf", &options).unwrap().model
}

/// The root of `m g cos θ + k (θ − r) = 0` near `r` (Newton), the closed-form rest angle.
fn closed_form(k: f64, r: f64) -> f64 {
    let mg = 2.0 * 9.81;
    let mut t = r;
    for _ in 0..100 {
        t -= (mg * t.cos() + k * (t - r)) / (-mg * t.sin() + k);
    }
    t
}

#[test]
fn a_servo_holds_the_bar_where_its_torque_balances_gravity() {
    for (k, r) in [(200.0, 0.0), (50.0, 0.3), (1000.0, -0.7)] {
        let model = bar(
            vec![ServoRequest {
                joint: Some("pivot".into()),
                stiffness: k,
                reference: Some(r),
            }],
            Vec::new(),
        );
        let (state, report) = restpose::solve(&model, &Options::default()).unwrap();
        assert!(report.converged());
        let theta = state.joint(&model, "pivot").unwrap()[0];
        let expected = closed_form(k, r);
        assert!(
            (theta - expected).abs() < 1e-9,
            "k {k}: {theta} vs {expected}"
        );
        let servos = restpose::export::json::servo_results(&model, &state);
        assert_eq!(servos.len(), 1);
        // The actuator torque holds the gravity torque m g ℓ cos θ.
        let gravity = 2.0 * 9.81 * theta.cos();
        assert!((servos[0].torque - gravity).abs() < 1e-7, "{servos:?}");
        assert!((servos[0].torque + k * (theta - r)).abs() < 1e-12);
    }
}

#[test]
fn the_reference_comes_from_the_request_then_the_reference_pose_then_the_initial_value() {
    let all = |r: Option<f64>| ServoRequest {
        joint: None,
        stiffness: 100.0,
        reference: r,
    };
    let from_pose = bar(vec![all(None)], vec![("pivot".into(), 0.25)]);
    assert_eq!(from_pose.servos().len(), 1);
    assert_eq!(from_pose.servos()[0].reference, 0.25);
    let own = bar(vec![all(Some(-0.5))], vec![("pivot".into(), 0.25)]);
    assert_eq!(own.servos()[0].reference, -0.5);
    let initial = bar(vec![all(None)], Vec::new());
    assert_eq!(initial.servos()[0].reference, 0.0);
    // A later request on the same joint replaces the earlier one (and its spring).
    let twice = bar(
        vec![
            all(None),
            ServoRequest {
                joint: Some("pivot".into()),
                stiffness: 7.0,
                reference: Some(1.0),
            },
        ],
        Vec::new(),
    );
    assert_eq!(twice.servos().len(), 1);
    assert_eq!(twice.joint_springs().len(), 1);
    assert_eq!(twice.servos()[0].stiffness, 7.0);
}

/// Regression (pybullet_data's Spirit 40, Vision 60, Spirit 40 newer held about a crouch by
/// `--servo JOINT=K@REF`): a servo's own reference was not the start, as the reference pose of
/// `--servo-reference` / `--srdf-state` is, so the robots started from the file's zero pose
/// (legs flat, every contact sticking) and ended with errors, cycling, or lying clamped at
/// 4,774 J; started crouched they stand in 3-4 iterations. The bar starts at its servo's
/// reference, which overrides the reference pose; `--initial` overrides both.
#[test]
fn a_servo_reference_is_also_the_start() {
    let own = |r: f64| ServoRequest {
        joint: Some("pivot".into()),
        stiffness: 100.0,
        reference: Some(r),
    };
    let start = |m: &restpose::Model| restpose::State::initial(m).joint(m, "pivot").unwrap()[0];
    assert_eq!(start(&bar(vec![own(-0.5)], Vec::new())), -0.5);
    assert_eq!(
        start(&bar(vec![own(-0.5)], vec![("pivot".into(), 0.25)])),
        -0.5
    );
    let options = ImportOptions {
        servos: vec![own(-0.5)],
        initial: vec![("pivot".into(), 0, 0.1)],
        ..Default::default()
    };
    let m = load_str(BAR, "bar.urdf", &options).unwrap().model;
    assert!((start(&m) - 0.1).abs() < 1e-15);
    // `all=K@REF` sets the references, not the start.
    let all = ServoRequest {
        joint: None,
        ..own(-0.5)
    };
    assert_eq!(start(&bar(vec![all], Vec::new())), 0.0);
}

/// A joint the file starts by `mech:initial` keeps that start under a reference pose (so that
/// a rest written back by `--write-urdf` and analysed again with the same options starts at
/// that rest); the servo's reference is still the reference pose's, and `--initial` overrides
/// both.
#[test]
fn a_files_initial_value_keeps_its_start_under_a_reference_pose() {
    let text = BAR
        .replace(
            "</robot>",
            r#"<mech:initial joint="pivot" value="0.4"/></robot>"#,
        )
        .replacen("<robot ", r#"<robot xmlns:mech="urn:urdf-mech:1" "#, 1);
    let load = |initial: Vec<(String, usize, f64)>| {
        let options = ImportOptions {
            servos: vec![ServoRequest {
                joint: None,
                stiffness: 100.0,
                reference: None,
            }],
            servo_reference: vec![("pivot".into(), 0.25)],
            initial,
            ..Default::default()
        };
        load_str(&text, "bar.urdf", &options).unwrap().model
    };
    let start = |m: &restpose::Model| restpose::State::initial(m).joint(m, "pivot").unwrap()[0];
    let m = load(Vec::new());
    assert!((start(&m) - 0.4).abs() < 1e-15, "{}", start(&m));
    assert_eq!(m.servos()[0].reference, 0.25);
    let m = load(vec![("pivot".into(), 0, 0.1)]);
    assert!((start(&m) - 0.1).abs() < 1e-15);
    // Without the file's value the reference pose starts it, as before.
    let options = ImportOptions {
        servo_reference: vec![("pivot".into(), 0.25)],
        ..Default::default()
    };
    let m = load_str(BAR, "bar.urdf", &options).unwrap().model;
    assert!((start(&m) - 0.25).abs() < 1e-15);
}

#[test]
fn an_unknown_servo_joint_is_named_with_a_suggestion() {
    let options = ImportOptions {
        servos: vec![ServoRequest {
            joint: Some("pivto".into()),
            stiffness: 1.0,
            reference: None,
        }],
        ..Default::default()
    };
    let e = load_str(BAR, "bar.urdf", &options).unwrap_err().to_string();
    assert!(
        e.contains("servo `pivto`") && e.contains("did you mean `pivot`"),
        "{e}"
    );
}

#[test]
fn an_srdf_group_state_is_read_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let srdf = dir.path().join("r.srdf");
    std::fs::write(
        &srdf,
        r#"<robot name="bar">
  <group_state name="up" group="all">
    <joint name="root_joint" value="0 0 0.3 0 0 0 1"/>
    <joint name="pivot" value="1.2"/>
  </group_state>
</robot>"#,
    )
    .unwrap();
    assert_eq!(
        srdf_state(&srdf, "up").unwrap(),
        vec![("pivot".to_string(), 1.2)]
    );
    let e = srdf_state(&srdf, "down").unwrap_err().to_string();
    assert!(
        e.contains("no <group_state name=\"down\">") && e.contains("up"),
        "{e}"
    );
}

#[test]
fn the_cli_reports_servo_torques_in_the_summary_and_the_json() {
    let dir = tempfile::tempdir().unwrap();
    let urdf = dir.path().join("bar.urdf");
    std::fs::write(
        &urdf,
        BAR.replace(
            "<robot name=\"bar\">",
            "<robot name=\"bar\" xmlns:mech=\"urn:urdf-mech:1\"><mech:gravity xyz=\"0 -9.81 0\"/>",
        ),
    )
    .unwrap();
    let states = dir.path().join("ref.yaml");
    std::fs::write(&states, "name: [\"pivot\"]\nposition: [0.3]\n").unwrap();
    let json = dir.path().join("r.json");
    let out = Command::new(env!("CARGO_BIN_EXE_restpose"))
        .args(["analyze", "--servo", "all=50", "--servo-reference"])
        .arg(&states)
        .arg("--json")
        .arg(&json)
        .arg(&urdf)
        .output()
        .unwrap();
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.contains("servo (actuator)"), "{text}");
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let s = &v["servos"][0];
    assert_eq!(s["joint"], "pivot");
    assert_eq!(s["reference"], 0.3);
    let theta = s["position"].as_f64().unwrap();
    assert!((theta - closed_form(50.0, 0.3)).abs() < 1e-9);
    assert!((s["torque"].as_f64().unwrap() + 50.0 * (theta - 0.3)).abs() < 1e-12);
    // A bad value is a usage error naming the option.
    let bad = Command::new(env!("CARGO_BIN_EXE_restpose"))
        .args(["analyze", "--servo", "pivot=-3"])
        .arg(&urdf)
        .output()
        .unwrap();
    assert_ne!(bad.status.code(), Some(0));
    let err = String::from_utf8_lossy(&bad.stderr);
    assert!(err.contains("--servo pivot=-3"), "{err}");
}
