//! Regression (issue 21, the standing corpus's last row above 30 iterations): Bolt, a biped on
//! two wheel-like mesh feet held by servos about its SRDF `standing` state, cannot stand: its
//! centre of mass is 30 mm off its start support. The Newton/active-set loop let it fall over
//! its foot treads and knee ends onto its trunk one mesh vertex per step: 36 iterations in 61
//! rounds. Now a floating group whose centre of mass is not over its ground start's support
//! (nor over the points within 1 % of its size of the ground, which the joints' settling can
//! reach) topples first as a rigid body, over the support's edge onto the next point it lands
//! on, by a closed form per point (module `solver::topple`), and the solve starts from there:
//! Bolt converges in 3 iterations, onto its thighs and trunk, and the result says so
//! (`topple`).

use restpose::urdf::{load_str, ImportOptions};
use restpose::{Options, Topple};
use std::process::Command;

fn sticking(topple: Topple) -> Options {
    Options {
        friction: restpose::model::Friction::Stick,
        topple,
        ..Default::default()
    }
}

fn floating_on_ground(text: &str) -> restpose::Model {
    let options = ImportOptions {
        floating_base: true,
        ground: true,
        ..Default::default()
    };
    load_str(text, "t.urdf", &options).unwrap().model
}

const INERTIA: &str = r#"<inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/>"#;

/// A plank (x from −0.05 to 0.95 m, z from 0.1 to 0.15 m, 3 kg, centre of mass at x = 0.45 m,
/// z = 0.125 m) on a massless foot (a 0.1 m cube under its end, x and y within ±0.05 m): the
/// ground start sets the foot's sole on the ground with the centre of mass 0.40 m beyond its
/// edge x = 0.05 m. It turns about that edge until the plank's far lower corners (0.9 m out,
/// 0.1 m up from the edge) touch: `tan θ = 1/9`; its centre of mass, (0.4, 0.125) from the edge,
/// ends at the height `(−0.4 sin θ + 0.125 cos θ) = 0.725/√82` m, and the solve from there
/// has nothing to do: `V = m g · 0.725/√82`.
#[test]
fn a_plank_on_a_foot_topples_onto_its_far_edge() {
    let text = format!(
        r#"<robot name="plank">
  <link name="plank"><inertial><origin xyz="0.45 0 0.125"/><mass value="3"/>{INERTIA}</inertial>
    <collision><origin xyz="0.45 0 0.125"/><geometry><box size="1.0 0.2 0.05"/></geometry></collision></link>
  <link name="foot"><collision><origin xyz="0 0 0.05"/><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link>
  <joint name="weld" type="fixed"><parent link="plank"/><child link="foot"/></joint>
</robot>"#
    );
    let model = floating_on_ground(&text);
    let (state, report) = restpose::solve(&model, &sticking(Topple::On)).unwrap();
    assert!(report.converged(), "{:?}", report.termination);
    assert_eq!(report.toppled.len(), 1, "{:?}", report.toppled);
    let t = &report.toppled[0];
    assert_eq!(t.steps, 1);
    assert!(
        (t.angle - (1.0f64 / 9.0).atan()).abs() < 1e-12,
        "{}",
        t.angle
    );
    assert!((t.com_outside - 0.40).abs() < 1e-12, "{}", t.com_outside);
    assert_eq!(t.support_before, ["foot"]);
    assert_eq!(t.support_after, ["plank", "foot"]);
    assert!(t.stopped.is_none());
    let (m, g) = (3.0, 9.81);
    let rest = 0.725 / 82f64.sqrt();
    assert!((t.energy_released - m * g * (0.125 - rest)).abs() < 1e-12);
    assert!(
        (report.energy.total - m * g * rest).abs() < 1e-9,
        "{} {}",
        report.energy.total,
        m * g * rest
    );
    assert_eq!(report.iterations, 0);
    // The JSON carries it.
    let json = serde_json::to_value(restpose::export::json::AnalysisResult::new(
        &model, &state, &report,
    ))
    .unwrap();
    let topple = &json["topple"][0];
    assert_eq!(topple["steps"], 1);
    assert_eq!(topple["support_before"][0], "foot");
    for key in ["angle", "com_outside", "energy_released"] {
        assert!(topple[key].is_f64(), "{key}: {topple}");
    }
    // Off, it is not toppled (and the field is absent).
    let (_, off) = restpose::solve(&model, &sticking(Topple::Off)).unwrap();
    assert!(off.toppled.is_empty());
}

/// A box standing on its four lower corners with an arm on a sprung hinge, its centre of mass
/// over the box: nothing topples, the result has no `topple`, and `--topple off` gives the
/// same answer bit for bit.
#[test]
fn a_body_over_its_support_does_not_topple() {
    let text = format!(
        r#"<robot name="stand" xmlns:mech="urn:urdf-mech:1">
  <link name="box"><inertial><origin xyz="0 0 0.05"/><mass value="2"/>{INERTIA}</inertial>
    <collision><origin xyz="0 0 0.05"/><geometry><box size="0.3 0.3 0.1"/></geometry></collision></link>
  <link name="arm"><inertial><origin xyz="0.1 0 0"/><mass value="0.5"/>{INERTIA}</inertial></link>
  <joint name="hinge" type="revolute"><parent link="box"/><child link="arm"/><origin xyz="0 0 0.2"/>
    <axis xyz="0 1 0"/><limit lower="-2" upper="2" effort="10" velocity="1"/></joint>
  <mech:joint_spring joint="hinge" stiffness="5" reference="0"/>
</robot>"#
    );
    let model = floating_on_ground(&text);
    let (state, report) = restpose::solve(&model, &sticking(Topple::On)).unwrap();
    assert!(report.converged());
    assert!(report.toppled.is_empty(), "{:?}", report.toppled);
    let json = serde_json::to_value(restpose::export::json::AnalysisResult::new(
        &model, &state, &report,
    ))
    .unwrap();
    assert!(json.get("topple").is_none());
    let (off_state, off) = restpose::solve(&model, &sticking(Topple::Off)).unwrap();
    assert_eq!(state.q.as_slice(), off_state.q.as_slice());
    assert_eq!(report.iterations, off.iterations);
    assert_eq!(report.history, off.history);
    assert_eq!(
        report.energy.total.to_bits(),
        off.energy.total.to_bits(),
        "{} {}",
        report.energy.total,
        off.energy.total
    );
}

/// Bolt (`robots/bolt/`) standing as in the corpus: it topples at the start from its left foot
/// onto its trunk and left thigh, and the solve converges in 3 iterations (36 before) to a
/// stable rest on both thighs and the trunk that `verify` passes.
#[test]
fn bolt_topples_at_the_start_and_converges_in_a_few_iterations() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/robots/bolt");
    let tmp = tempfile::tempdir().unwrap();
    let json = tmp.path().join("bolt.json");
    let args = crate::common::BOLT_STANDING;
    let out = Command::new(env!("CARGO_BIN_EXE_restpose"))
        .current_dir(dir)
        .args(["analyze", "bolt.urdf", "--load-steps", "1", "--json"])
        .arg(&json)
        .args(args)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        text.contains("toppled at the start: `base_link` cannot stand on FL_FOOT"),
        "{text}"
    );
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(v["termination"], "converged");
    let iterations = v["iterations"].as_u64().unwrap();
    assert!(
        iterations <= 5,
        "{iterations} iterations (36 before the topple)"
    );
    assert_eq!(v["stability"]["verdict"], "stable");
    let topple = &v["topple"][0];
    assert_eq!(topple["support_before"], serde_json::json!(["FL_FOOT"]));
    let after = topple["support_after"].as_array().unwrap();
    assert!(after.iter().any(|l| l == "base_link"), "{topple}");
    // Turned over onto its back: more than a right angle.
    assert!(topple["angle"].as_f64().unwrap() > 1.5, "{topple}");
    assert!(
        v["friction"]["required_mu"].as_f64().unwrap() < 5.0,
        "{}",
        v["friction"]
    );
    let verified = Command::new(env!("CARGO_BIN_EXE_restpose"))
        .current_dir(dir)
        .args(["verify", "bolt.urdf", "--pose"])
        .arg(&json)
        .args(args)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&verified.stdout);
    assert_eq!(verified.status.code(), Some(0), "{text}");
    assert!(text.contains("pose PASSES"), "{text}");
}
