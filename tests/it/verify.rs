//! `restpose verify` and the verification API.
use crate::common::*;
use approx::assert_abs_diff_eq;
use restpose::verify::{parse_pose, pose_state, verify, Tolerances};
use std::process::Command;

/// Holding the pendulum bar level takes the gravity and spring torques, by hand.
#[test]
fn pendulum_level_effort_by_hand() {
    let m = robot("pendulum");
    let pose = parse_pose(r#"{"pivot": 0.0}"#, "pose.json").unwrap();
    let (s, missing) = pose_state(&m, &pose).unwrap();
    assert!(missing.is_empty());
    let v = verify(&m, &s, &Tolerances::default()).unwrap();
    assert!(!v.passed);
    // Weight 19.62 N at x = 1; spring from (2, 0) to (−1, −2), free length 2, k = 3.
    let l = (9.0f64 + 4.0).sqrt();
    let tension = 3.0 * (l - 2.0);
    let spring_torque = 2.0 * tension * (-2.0 / l);
    let load_torque = -19.62 + spring_torque;
    let e = v.max_imbalance.unwrap();
    assert_eq!(e.joint, "pivot");
    assert_abs_diff_eq!(e.effort, -load_torque, epsilon = 1e-9);
}

/// The solver's answers pass; every format of the same pose gives the same verdict.
#[test]
fn solver_answers_pass_in_every_pose_format() {
    for name in ["pendulum", "slider_crank", "four_bar_spatial", "chain20"] {
        let m = robot(name);
        let (rest, _) = solve(&m);
        let result = restpose::export::json::AnalysisResult::new(&m, &rest, &solve(&m).1);
        let json = result.to_json();
        let values = parse_pose(&json, "result.json").unwrap();
        let (s, _) = pose_state(&m, &values).unwrap();
        let v = verify(&m, &s, &Tolerances::default()).unwrap();
        assert!(v.passed, "{name}: {v:?}");
        assert_eq!(
            v.stability.unwrap().verdict,
            restpose::solver::Verdict::Stable,
            "{name}"
        );
        // A {"joint": [values]} map.
        let map: serde_json::Map<String, serde_json::Value> = result
            .joints
            .iter()
            .map(|(n, j)| (n.clone(), serde_json::json!(j.position)))
            .collect();
        let values = parse_pose(&serde_json::Value::Object(map).to_string(), "map.json").unwrap();
        let (s1, _) = pose_state(&m, &values).unwrap();
        assert!(
            verify(&m, &s1, &Tolerances::default()).unwrap().passed,
            "{name}: map format"
        );
        // joint_states YAML carries one position per joint: only for scalar-joint models.
        if result.joints.iter().any(|(_, j)| j.position.len() > 1) {
            continue;
        }
        let mut names = Vec::new();
        let mut pos = Vec::new();
        for (jn, jr) in &result.joints {
            if jr.position.len() == 1 {
                names.push(jn.clone());
                pos.push(format!("{:?}", jr.position[0]));
            }
        }
        let yaml = format!(
            "name: [{}]\nposition: [{}]\n",
            names.join(", "),
            pos.join(", ")
        );
        let values = parse_pose(&yaml, "js.yaml").unwrap();
        let (s2, _) = pose_state(&m, &values).unwrap();
        let v2 = verify(&m, &s2, &Tolerances::default()).unwrap();
        assert!(v2.passed, "{name}: joint_states format");
    }
}

/// Perturbing one joint of the chain's rest pose fails, naming that joint.
#[test]
fn perturbed_chain_fails_at_the_perturbed_joint() {
    let m = robot("chain20");
    let (rest, _) = solve(&m);
    for k in [0usize, 7, 19] {
        let mut values: restpose::state::JointValues = rest.joint_values(&m).into_iter().collect();
        values.get_mut(&format!("joint{k}")).unwrap()[0] += 0.01;
        let (s, _) = pose_state(&m, &values).unwrap();
        let v = verify(&m, &s, &Tolerances::default()).unwrap();
        assert!(!v.passed);
        assert_eq!(v.max_imbalance.unwrap().joint, format!("joint{k}"));
    }
}

#[test]
fn loop_closure_error_is_reported_per_loop_joint() {
    let m = robot("slider_crank");
    let (rest, _) = solve(&m);
    let mut values: restpose::state::JointValues = rest.joint_values(&m).into_iter().collect();
    values.get_mut("slide").unwrap()[0] += 0.002;
    let (s, _) = pose_state(&m, &values).unwrap();
    let v = verify(&m, &s, &Tolerances::default()).unwrap();
    assert!(!v.passed);
    let c = v.closure.iter().find(|c| c.joint == "wrist_pin").unwrap();
    assert!(c.loop_joint);
    assert_abs_diff_eq!(c.position_error, 0.002, epsilon = 1e-12);
}

#[test]
fn bad_pose_files_are_errors() {
    let m = robot("pendulum");
    assert!(parse_pose("[1, 2]", "p.json").is_err());
    assert!(parse_pose("name: [a]\nposition: [1, 2]\n", "p.yaml")
        .unwrap_err()
        .to_string()
        .contains("1 names but 2 positions"));
    let v = parse_pose(r#"{"elbow": 1.0}"#, "p.json").unwrap();
    assert!(pose_state(&m, &v)
        .unwrap_err()
        .to_string()
        .contains("pose `elbow`: the model has no joint"));
}

fn restpose() -> Command {
    Command::new(env!("CARGO_BIN_EXE_restpose"))
}

#[test]
fn cli_verify_exit_codes_and_json() {
    let dir = tempfile::tempdir().unwrap();
    let urdf = format!("{}/robots/slider_crank.urdf", env!("CARGO_MANIFEST_DIR"));
    let result = dir.path().join("r.json");
    assert!(restpose()
        .args(["analyze", &urdf, "-q", "--json"])
        .arg(&result)
        .status()
        .unwrap()
        .success());
    let o = restpose()
        .args(["verify", &urdf, "--pose"])
        .arg(&result)
        .output()
        .unwrap();
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(String::from_utf8_lossy(&o.stdout).contains("PASSES"));
    let o = restpose()
        .args(["verify", &urdf, "--pose"])
        .arg(&result)
        .args(["--joint", "crank_joint=0.3", "--json", "-"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(4));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["passed"], false);
    assert!(String::from_utf8_lossy(&o.stderr).contains("not a rest pose"));
    let o = restpose()
        .args(["verify", &urdf, "--joint", "nope=1"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
}

/// Issue 12 §6: at 1,000+ links `verify` (sparse path, relative effort tolerance) accepts the
/// solver's own answer after its JSON round trip, rejects the same pose with one joint turned,
/// and `balance` (what `check` reports) counts the degrees of freedom.
#[test]
fn verify_accepts_analyze_answers_at_1000_links() {
    for (family, m) in [
        (
            "chain1000",
            restpose::urdf::load_str(
                &restpose::generate::chain(1000, false),
                "chain.urdf",
                &Default::default(),
            )
            .unwrap()
            .model,
        ),
        (
            "ladder400",
            restpose::urdf::load_str(
                &restpose::generate::ladder(400),
                "ladder.urdf",
                &Default::default(),
            )
            .unwrap()
            .model,
        ),
    ] {
        let (rest, report) = restpose::solve(&m, &Default::default()).unwrap();
        assert!(report.converged(), "{family}");
        let json = restpose::export::json::AnalysisResult::new(&m, &rest, &report).to_json();
        let mut values = parse_pose(&json, "result.json").unwrap();
        let (s, missing) = pose_state(&m, &values).unwrap();
        assert!(missing.is_empty(), "{family}");
        let v = verify(&m, &s, &Tolerances::default()).unwrap();
        assert!(v.passed, "{family}: {:?}", v.max_imbalance);
        assert!(
            v.effort_tolerance < 1e-3 * v.force_scale.max(1.0),
            "{family}"
        );
        let b = restpose::verify::balance(&m, &s).unwrap();
        assert_eq!(b.dof, report.dof, "{family}");
        // `check`'s count (the sparse partition's rank at the assembled initial guess) is the
        // same number.
        assert_eq!(
            restpose::verify::check(&m).dof,
            Some(report.dof),
            "{family}"
        );
        // verify's stability verdict (from its balance check's partition; above 200 degrees
        // of freedom from the shifted KKT inertia by default, without eigenvalues) is
        // analyze's, with the same tolerance; asked for, the smallest eigenvalues (Lanczos)
        // are analyze's too (asked for there too), with the same verdict and tolerance.
        let full = restpose::verify::verify_reporting(
            &m,
            &s,
            &Tolerances::default(),
            &Default::default(),
            restpose::LinearAlgebra::Auto,
            restpose::verify::Eigenvalues::Always,
        )
        .unwrap();
        let (vs, fs, rs) = (
            v.stability.as_ref().unwrap(),
            full.stability.as_ref().unwrap(),
            report.stability.as_ref().unwrap(),
        );
        assert_eq!(vs.verdict, rs.verdict, "{family}");
        // (The pose read back from the JSON differs from the solver's by rounding.)
        assert!(
            (vs.tolerance - rs.tolerance).abs() <= 1e-9 * rs.tolerance,
            "{family}"
        );
        assert_eq!(vs.verdict, restpose::solver::Verdict::Stable, "{family}");
        assert!(vs.eigenvalues.is_empty() && vs.modes.is_empty(), "{family}");
        assert!(rs.eigenvalues.is_empty(), "{family}");
        assert_eq!(report.diagnostics.eigenvalues_by, "inertia", "{family}");
        let asked = restpose::Options {
            eigenvalues: true,
            ..Default::default()
        };
        let (_, report) = restpose::solve(&m, &asked).unwrap();
        let rs = report.stability.as_ref().unwrap();
        assert_eq!(fs.verdict, vs.verdict, "{family}");
        assert_eq!(fs.tolerance, vs.tolerance, "{family}");
        assert!(!fs.eigenvalues.is_empty(), "{family}");
        assert_eq!(fs.eigenvalues.len(), rs.eigenvalues.len(), "{family}");
        for (a, b) in fs.eigenvalues.iter().zip(&rs.eigenvalues) {
            assert!((a - b).abs() <= 1e-8 * b.abs(), "{family}: {a} vs {b}");
        }
        // One joint turned by 0.01 rad needs an effort there.
        let name = if family == "chain1000" {
            "joint500"
        } else {
            "hang_left200"
        };
        values.get_mut(name).unwrap()[0] += 0.01;
        let (s, _) = pose_state(&m, &values).unwrap();
        let v = verify(&m, &s, &Tolerances::default()).unwrap();
        assert!(!v.passed, "{family}: turned {name}");
        assert!(v.max_imbalance.unwrap().effort.abs() > 1e3 * v.effort_tolerance);
    }
}

/// Above 200 degrees of freedom `verify`'s stability verdict comes from the KKT inertia, with
/// no eigenvalues in the JSON; `--eigenvalues` adds the lowest ones (Lanczos), with the same
/// verdict and tolerance; the text report is the same either way.
#[test]
fn cli_verify_eigenvalues_on_request_above_200_dof() {
    let dir = tempfile::tempdir().unwrap();
    let urdf = dir.path().join("chain.urdf");
    std::fs::write(&urdf, restpose::generate::chain(250, false)).unwrap();
    let result = dir.path().join("r.json");
    assert!(restpose()
        .arg("analyze")
        .arg(&urdf)
        .args(["-q", "--json"])
        .arg(&result)
        .status()
        .unwrap()
        .success());
    let run = |extra: &[&str]| {
        let json = restpose()
            .arg("verify")
            .arg(&urdf)
            .arg("--pose")
            .arg(&result)
            .args(["--json", "-"])
            .args(extra)
            .output()
            .unwrap();
        assert_eq!(json.status.code(), Some(0));
        let text = restpose()
            .arg("verify")
            .arg(&urdf)
            .arg("--pose")
            .arg(&result)
            .args(extra)
            .output()
            .unwrap();
        assert_eq!(text.status.code(), Some(0));
        let v: serde_json::Value = serde_json::from_slice(&json.stdout).unwrap();
        (v["stability"].clone(), text.stdout)
    };
    let (fast, fast_text) = run(&[]);
    let (full, full_text) = run(&["--eigenvalues"]);
    assert_eq!(fast["verdict"], "stable");
    assert_eq!(fast["verdict"], full["verdict"]);
    assert_eq!(fast["tolerance"], full["tolerance"]);
    assert_eq!(fast["eigenvalues"].as_array().unwrap().len(), 0);
    assert_eq!(fast["modes"].as_array().unwrap().len(), 0);
    assert_eq!(full["eigenvalues"].as_array().unwrap().len(), 6);
    assert_eq!(full["modes"].as_array().unwrap().len(), 6);
    assert_eq!(fast_text, full_text);
    assert!(String::from_utf8_lossy(&fast_text).contains("stability: stable"));
}
