//! `--write-urdf` and `--write-joint-states`: the next run starts at rest.
use crate::common::*;
use std::process::Command;

#[test]
fn written_urdf_starts_at_rest_and_keeps_the_rest_of_the_file() {
    for (name, max_iterations) in [
        ("pendulum", 0),
        ("slider_crank", 0),
        ("four_bar_spatial", 0),
        ("stewart_platform", 1),
        ("tractor_trailer", 1),
    ] {
        let m = robot(name);
        let (rest, _) = solve(&m);
        let path = format!("{}/robots/{name}.urdf", env!("CARGO_MANIFEST_DIR"));
        let text = std::fs::read_to_string(&path).unwrap();
        let out = restpose::urdf::with_initial_pose(&text, &path, &m, &rest).unwrap();
        // Comments and every non-initial element survive.
        assert_eq!(
            out.matches("<!--").count(),
            text.matches("<!--").count(),
            "{name}"
        );
        assert_eq!(
            out.matches("<joint ").count(),
            text.matches("<joint ").count(),
            "{name}"
        );
        assert_eq!(
            out.matches("mech:spring ").count(),
            text.matches("mech:spring ").count(),
            "{name}"
        );
        let m2 = model_from(&out);
        let (s2, r2) = solve(&m2);
        assert!(
            r2.iterations <= max_iterations,
            "{name}: {} iterations from the written pose",
            r2.iterations
        );
        for l in m.links() {
            let (a, b) = (
                rest.link_pose(&m, &l.name).unwrap(),
                s2.link_pose(&m2, &l.name).unwrap(),
            );
            assert!(
                (a.translation.vector - b.translation.vector).norm() < 1e-8,
                "{name}: link {}",
                l.name
            );
        }
        // Written twice: one set of initial values, not two.
        let again = restpose::urdf::with_initial_pose(&out, &path, &m2, &s2).unwrap();
        assert_eq!(
            again.matches(":initial ").count(),
            out.matches(":initial ").count(),
            "{name}"
        );
    }
}

#[test]
fn joint_states_round_trip_through_verify() {
    let m = robot("slider_crank");
    let (rest, _) = solve(&m);
    let yaml = restpose::export::joint_states::joint_states_yaml(&m, &rest);
    let values = restpose::verify::parse_pose(&yaml, "rest.yaml").unwrap();
    assert_eq!(values.len(), 4);
    let (s, _) = restpose::verify::pose_state(&m, &values).unwrap();
    assert!(
        restpose::verify::verify(&m, &s, &Default::default())
            .unwrap()
            .passed
    );
}

#[test]
fn cli_writes_only_converged_poses() {
    let dir = tempfile::tempdir().unwrap();
    let urdf = format!("{}/robots/pendulum.urdf", env!("CARGO_MANIFEST_DIR"));
    let (u, y) = (dir.path().join("rest.urdf"), dir.path().join("rest.yaml"));
    let run = |extra: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_restpose"))
            .args(["analyze", &urdf, "-q", "--write-urdf"])
            .arg(&u)
            .arg("--write-joint-states")
            .arg(&y)
            .args(extra)
            .status()
            .unwrap()
    };
    assert_eq!(run(&["--max-iterations", "1"]).code(), Some(3));
    assert!(!u.exists() && !y.exists());
    assert_eq!(run(&[]).code(), Some(0));
    assert!(std::fs::read_to_string(&u)
        .unwrap()
        .contains("<mech:initial joint=\"pivot\" value=\"-1.3815770"));
    assert!(std::fs::read_to_string(&y)
        .unwrap()
        .contains("name: [\"pivot\"]"));
}

/// Issue 12 §6: `analyze --write-joint-states` then `verify --pose` passes for every robot in
/// `robots/`, including the joints `sensor_msgs/JointState` cannot carry (spherical,
/// universal, floating: the `multi_dof` section). Before it, four of them failed.
#[test]
fn every_robot_round_trips_joint_states_through_verify() {
    let dir = tempfile::tempdir().unwrap();
    let robots = format!("{}/robots", env!("CARGO_MANIFEST_DIR"));
    let mut names: Vec<_> = std::fs::read_dir(&robots)
        .unwrap()
        .filter_map(|e| e.ok()?.path().to_str().map(str::to_string))
        .filter(|p| p.ends_with(".urdf"))
        .collect();
    names.sort();
    assert!(names.len() >= 11, "{names:?}");
    let mut with_multi = 0;
    for urdf in &names {
        let yaml = dir.path().join("rest.yaml");
        let st = Command::new(env!("CARGO_BIN_EXE_restpose"))
            .args(["analyze", urdf, "-q", "--write-joint-states"])
            .arg(&yaml)
            .status()
            .unwrap();
        assert_eq!(st.code(), Some(0), "{urdf}: analyze");
        let text = std::fs::read_to_string(&yaml).unwrap();
        // Every joint with coordinates is in the file, with as many values as it has.
        let m = restpose::urdf::load_file(urdf, &Default::default())
            .unwrap()
            .model;
        let values = restpose::verify::parse_pose(&text, "rest.yaml").unwrap();
        for j in m.joints() {
            let n = restpose::export::json::coordinate_units(j.kind).len();
            if n > 0 {
                assert_eq!(
                    values.get(&j.name).map(Vec::len),
                    Some(n),
                    "{urdf}: joint `{}`",
                    j.name
                );
            }
        }
        with_multi += usize::from(text.contains("multi_dof:"));
        let o = Command::new(env!("CARGO_BIN_EXE_restpose"))
            .args(["verify", urdf, "--pose"])
            .arg(&yaml)
            .output()
            .unwrap();
        assert_eq!(
            o.status.code(),
            Some(0),
            "{urdf}: verify\n{}\n{}",
            String::from_utf8_lossy(&o.stdout),
            String::from_utf8_lossy(&o.stderr)
        );
        assert!(String::from_utf8_lossy(&o.stdout).contains("pose PASSES"));
        assert!(
            !String::from_utf8_lossy(&o.stderr).contains("keep their initial values"),
            "{urdf}: a joint is missing from the joint states"
        );
    }
    assert!(with_multi >= 4, "{with_multi} robots with multi_dof joints");
}

/// Issue 21 (every written pose round-trips through re-analysis in 0 iterations): Bolt held by
/// servos about its SRDF `standing` state, its meshes named relative to its file, the rest
/// written with `--write-urdf` into another folder. Re-analysed with the same options, the
/// written file said "mesh `meshes/bolt_body.stl` was not found" (its relative mesh names
/// resolved from the new folder), and, next to its meshes, took 3 iterations (the reference
/// pose's start overrode the written `mech:initial` values; the A1 that way moved its
/// sticking rest by 1.7e-5 J). Now the relative names are rewritten to resolve from the
/// written file's folder (`urdf::relocated`) and a joint the file starts by `mech:initial`
/// keeps that start: 0 iterations, the same energy.
#[test]
fn a_servo_held_rest_written_elsewhere_reanalyses_in_zero_iterations() {
    let dir = tempfile::tempdir().unwrap();
    let bolt = format!("{}/robots/bolt", env!("CARGO_MANIFEST_DIR"));
    let urdf = format!("{bolt}/bolt.urdf");
    let written = dir.path().join("out").join("rest.urdf");
    std::fs::create_dir_all(written.parent().unwrap()).unwrap();
    let analyze = |file: &std::path::Path, json: &std::path::Path, extra: &[&std::ffi::OsStr]| {
        let o = Command::new(env!("CARGO_BIN_EXE_restpose"))
            .current_dir(&bolt)
            .arg("analyze")
            .arg(file)
            .args(BOLT_STANDING)
            .args(["--load-steps", "1", "-q", "--json"])
            .arg(json)
            .args(extra)
            .output()
            .unwrap();
        assert_eq!(
            o.status.code(),
            Some(0),
            "{}",
            String::from_utf8_lossy(&o.stderr)
        );
        let v: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(json).unwrap()).unwrap();
        (
            v["iterations"].as_u64().unwrap(),
            v["potential_energy"].as_f64().unwrap(),
        )
    };
    let (first, energy) = analyze(
        std::path::Path::new(&urdf),
        &dir.path().join("a.json"),
        &["--write-urdf".as_ref(), written.as_os_str()],
    );
    assert!(first > 0);
    let text = std::fs::read_to_string(&written).unwrap();
    assert!(!text.contains("filename=\"meshes/"), "{text}");
    let (again, energy2) = analyze(&written, &dir.path().join("b.json"), &[]);
    assert_eq!(again, 0, "iterations from the written rest");
    assert!(
        (energy2 - energy).abs() <= 1e-12 * energy.abs(),
        "{energy2} vs {energy}"
    );
}

/// A servo whose reference is its joint's start would be held about the rest when the written
/// file is analysed again (its start is now the rest): `--write-urdf` names it with the option
/// that keeps it (`--servo JOINT=K@REF`), and says nothing where every reference is given.
#[test]
fn a_servo_referenced_to_the_start_is_named_when_the_rest_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let urdf = format!("{}/robots/pendulum.urdf", env!("CARGO_MANIFEST_DIR"));
    let (out, json) = (dir.path().join("rest.urdf"), dir.path().join("r.json"));
    let run = |servo: &str| {
        let o = Command::new(env!("CARGO_BIN_EXE_restpose"))
            .args(["analyze", &urdf, "-q", "--servo", servo, "--write-urdf"])
            .arg(&out)
            .arg("--json")
            .arg(&json)
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(0));
        String::from_utf8_lossy(&o.stderr).into_owned()
    };
    let err = run("all=100");
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let reference = v["servos"][0]["reference"].as_f64().unwrap();
    let position = v["servos"][0]["position"].as_f64().unwrap();
    assert!(
        (reference - position).abs() > 1e-3,
        "{reference} {position}"
    );
    assert!(
        err.contains(&format!(
            "to keep these servos add: --servo pivot=100@{reference}"
        )),
        "{err}"
    );
    assert!(!run("pivot=100@0.3").contains("servo(s) take their reference"));
}
