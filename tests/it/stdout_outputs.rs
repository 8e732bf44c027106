//! `-` as the path of `--write-joint-states` and `--write-urdf` means standard output (it used
//! to create a file named `-`), which then carries only that text; two outputs to standard
//! output at once are a usage error (exit 2) that writes nothing.
use std::path::Path;
use std::process::{Command, Output};

fn robot(name: &str) -> String {
    format!("{}/robots/{name}.urdf", env!("CARGO_MANIFEST_DIR"))
}

/// `restpose analyze ROBOT ARGS…` run in `dir`.
fn analyze(dir: &Path, name: &str, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_restpose"))
        .current_dir(dir)
        .arg("analyze")
        .arg(robot(name))
        .args(args)
        .output()
        .unwrap()
}

fn files_in(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
        .collect();
    names.sort();
    names
}

#[test]
fn write_joint_states_dash_is_standard_output() {
    let dir = tempfile::tempdir().unwrap();
    let out = analyze(
        dir.path(),
        "four_bar_spatial",
        &["--write-joint-states", "-"],
    );
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        files_in(dir.path()).is_empty(),
        "{:?}",
        files_in(dir.path())
    );
    let yaml = String::from_utf8(out.stdout).unwrap();
    // Only the YAML: no summary line.
    assert!(!yaml.contains("robot `"), "{yaml}");
    assert!(
        yaml.starts_with("# rest pose of `four_bar_spatial`"),
        "{yaml}"
    );
    // The same text as the file output, and it verifies as a rest pose.
    let file = dir.path().join("rest.yaml");
    let to_file = analyze(
        dir.path(),
        "four_bar_spatial",
        &["--quiet", "--write-joint-states", file.to_str().unwrap()],
    );
    assert_eq!(to_file.status.code(), Some(0));
    assert_eq!(std::fs::read_to_string(&file).unwrap(), yaml);
    let piped = dir.path().join("piped.yaml");
    std::fs::write(&piped, &yaml).unwrap();
    let verify = Command::new(env!("CARGO_BIN_EXE_restpose"))
        .args(["verify", &robot("four_bar_spatial"), "--pose"])
        .arg(&piped)
        .output()
        .unwrap();
    assert_eq!(
        verify.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&verify.stdout)
    );
}

#[test]
fn write_urdf_dash_is_standard_output() {
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("r.json");
    let out = analyze(
        dir.path(),
        "slider_crank",
        &["--write-urdf", "-", "--json", json.to_str().unwrap()],
    );
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(files_in(dir.path()), vec!["r.json".to_string()]);
    let urdf = String::from_utf8(out.stdout).unwrap();
    assert!(urdf.trim_start().starts_with("<?xml"), "{urdf}");
    assert!(urdf.contains("mech:initial"), "{urdf}");
    // Loaded back, the written file starts at the rest pose: analyze takes no step from it.
    let back = dir.path().join("back.urdf");
    std::fs::write(&back, &urdf).unwrap();
    let again = Command::new(env!("CARGO_BIN_EXE_restpose"))
        .args(["analyze", back.to_str().unwrap(), "--json", "-"])
        .output()
        .unwrap();
    assert_eq!(again.status.code(), Some(0));
    let v: serde_json::Value = serde_json::from_slice(&again.stdout).unwrap();
    let first: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let e0 = first["potential_energy"].as_f64().unwrap();
    let e1 = v["potential_energy"].as_f64().unwrap();
    assert!((e0 - e1).abs() <= 1e-9 * e0.abs().max(1.0), "{e0} vs {e1}");
    assert!(first["iterations"].as_u64().unwrap() > 0);
    assert_eq!(
        v["iterations"], 0,
        "the written file starts at the rest pose"
    );
}

#[test]
fn two_outputs_to_standard_output_are_a_usage_error() {
    for other in ["--write-urdf", "--write-joint-states"] {
        let dir = tempfile::tempdir().unwrap();
        let out = analyze(dir.path(), "pendulum", &["--json", "-", other, "-"]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{other}: {err}");
        assert!(out.stdout.is_empty(), "{other}: nothing is written");
        assert!(files_in(dir.path()).is_empty());
        assert!(
            err.contains("--json") && err.contains(other) && err.contains("standard output"),
            "{err}"
        );
    }
    let dir = tempfile::tempdir().unwrap();
    let out = analyze(
        dir.path(),
        "pendulum",
        &["--write-urdf", "-", "--write-joint-states", "-"],
    );
    assert_eq!(out.status.code(), Some(2));
    assert!(out.stdout.is_empty() && files_in(dir.path()).is_empty());
}
