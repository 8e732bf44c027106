//! Regression (issue 22, item 3): a 1 kg box on a finite frictionless ramp (a world-fixed box
//! obstacle tilted by 0.3 rad) has no rest: it slides to the ramp's edge and falls off. The
//! solve ended `line_search_failed` after 17 iterations and 406 corrector failures, with two
//! contacts at the edge pulling (normal force −1.4495 N): a round whose line search fails
//! kept its active set, so the pulling rows never left. Such rows now leave as at a stationary
//! point; contacts hanging on the edge that a translation along the pull opens let go (module
//! `inequality::let_go`), and the free fall that follows is reported `unbounded`, within the
//! iteration limit, naming the box.

use restpose::model::Friction;
use restpose::urdf::{load_file, ImportOptions};
use restpose::{Options, Termination};

/// The ramp (2 × 2 × 0.2 m, pitched by `TILT` about y, centred on the world origin) and the
/// 0.4 × 0.3 × 0.2 m box.
fn ramp() -> String {
    format!(
        r#"<robot name="box_on_tilted_box" xmlns:mech="urn:urdf-mech:1">
  <link name="world"/>
  <link name="ramp">
    <collision><origin rpy="0 {TILT} 0"/><geometry><box size="2 2 0.2"/></geometry></collision>
  </link>
  <joint name="ramp_mount" type="fixed"><parent link="world"/><child link="ramp"/></joint>
  <link name="box">
    <inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.4 0.3 0.2"/></geometry></collision>
  </link>
  <joint name="free" type="floating"><parent link="world"/><child link="box"/></joint>
  <mech:obstacle link="ramp"/>
  <mech:contact link="box"/>
</robot>
"#
    )
}

const TILT: f64 = 0.3;

/// The lowest point of the ramp, `−(sin α · 1 + cos α · 0.1)` m, less the box's half
/// diagonal: a box centre below this is clear of the ramp.
fn below_the_ramp() -> f64 {
    let half_diagonal = (0.2f64 * 0.2 + 0.15 * 0.15 + 0.1 * 0.1).sqrt();
    -(TILT.sin() + TILT.cos() * 0.1) - half_diagonal
}

fn frictionless() -> Options {
    Options {
        friction: Friction::None,
        ..Default::default()
    }
}

fn solve(urdf: &str) -> (restpose::State, restpose::Report) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("ramp.urdf");
    std::fs::write(&path, urdf).unwrap();
    let model = load_file(&path, &ImportOptions::default()).unwrap().model;
    restpose::solve(&model, &frictionless()).unwrap()
}

fn assert_falls_off(report: &restpose::Report, what: &str) {
    assert_eq!(report.termination, Termination::Unbounded, "{what}");
    assert!(
        report.iterations <= Options::default().max_iterations,
        "{what}: {} iterations",
        report.iterations
    );
    let dirs = &report.diagnostics.free_directions;
    assert!(
        dirs.iter().any(|d| d.contains("body `box`")),
        "{what}: {dirs:?}"
    );
}

/// The case of the issue (`restpose analyze ramp.urdf --friction none`; the box is a child of
/// `world` by a `floating` joint, so it starts at the origin, inside the ramp, and is pushed
/// out onto its faces): the box slides to the edge,
/// the edge contacts pull, then hang, then let go; it falls clear of the ramp.
#[test]
fn a_box_pushed_out_onto_a_finite_frictionless_ramp_falls_off_unbounded() {
    let (state, report) = solve(&ramp());
    assert_falls_off(&report, "from the origin");
    // Independent check: the box's centre is below every point of the ramp by more than its
    // half diagonal (it fell off; it does not hang on the edge).
    let z = state.q[2];
    assert!(z < below_the_ramp(), "box centre z = {z}");
    // Along gravity: the last step named is a fall straight down.
    let dirs = &report.diagnostics.free_directions;
    assert!(
        dirs.iter()
            .any(|d| d.contains("body `box` translating along (0.000, 0.000, -1.000)")),
        "{dirs:?}"
    );
}

/// The model of `tests/it/obstacle.rs` (`on_tilted_box`): the box started flat on the ramp's
/// face, 0.21 m along its normal from the centre (`mech:initial`). Frictionless, it slides down
/// the face to the lower edge, tips over it and falls. Each vertex sliding across the edge took
/// geometrically shrinking steps (the corrector cannot keep it on the face past the edge), and
/// the box, its upper vertices hanging on the ramp's lower back edge, stalled there until
/// `max_iterations` (100 iterations, 2,033 corrector failures). A round whose steps halve
/// while the reduced gradient stays now ends; the vertices its step carries past the edge let
/// go (module `inequality::stall`).
#[test]
fn a_box_started_on_the_ramp_slides_off_and_falls_unbounded() {
    let n = (TILT.sin(), TILT.cos());
    let at = (n.0 * 0.21, n.1 * 0.21);
    let urdf = ramp().replace(
        "<mech:obstacle",
        &format!(
            "<mech:initial joint=\"free\" value=\"{} 0 {} {} 0 {} 0\"/>\n  <mech:obstacle",
            at.0,
            at.1,
            (TILT / 2.0).cos(),
            (TILT / 2.0).sin()
        ),
    );
    let (state, report) = solve(&urdf);
    assert_falls_off(&report, "from the ramp's face");
    // Well within the limit: a few iterations per vertex leaving the edge, not the limit.
    assert!(report.iterations <= 40, "{} iterations", report.iterations);
    // Independent check: it left the ramp, over its lower edge (x beyond the edge's
    // `cos α · 1 − sin α · 0.1`), and is below every point of the ramp.
    let (x, z) = (state.q[0], state.q[2]);
    assert!(x > TILT.cos() - TILT.sin() * 0.1, "box centre x = {x}");
    assert!(z < below_the_ramp(), "box centre z = {z}");
    // The energy reported is the 1 kg box's `m g z` at the state reported.
    assert!(
        (report.energy.total - 9.81 * z).abs() < 1e-9 * z.abs(),
        "{} vs {}",
        report.energy.total,
        9.81 * z
    );
    let dirs = &report.diagnostics.free_directions;
    assert!(
        dirs.iter().any(|d| {
            d.strip_prefix("body `box` translating along (")
                .and_then(|r| r.split(')').next())
                .map(|v| {
                    v.split(", ")
                        .filter_map(|c| c.parse::<f64>().ok())
                        .collect::<Vec<_>>()
                })
                .is_some_and(|v| v.len() == 3 && v[2] < -0.9)
        }),
        "down: {dirs:?}"
    );
}

/// The command line of the issue gives the same answer, in the JSON; the base pose it was
/// tried with (`--base-xyz`, `--base-rpy`) places a floating root link, which this model does
/// not have: an input error naming the file and the remedy, not a silently ignored option.
#[test]
fn analyze_reports_the_box_off_the_ramp_unbounded() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("ramp.urdf");
    std::fs::write(&path, ramp()).unwrap();
    let analyze = |extra: &[&str]| {
        std::process::Command::new(env!("CARGO_BIN_EXE_restpose"))
            .args(["analyze", "--friction", "none", "--json", "-"])
            .arg(&path)
            .args(extra)
            .output()
            .unwrap()
    };
    let out = analyze(&[]);
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(json["termination"], "unbounded", "{json}");
    assert!(json["iterations"].as_u64().unwrap() <= 200, "{json}");
    // Not converged: exit 3.
    assert_eq!(out.status.code(), Some(3));
    let placed = analyze(&[
        "--base-xyz",
        "0.062",
        "0",
        "0.2006",
        "--base-rpy",
        "0",
        "0.3",
        "0",
    ]);
    assert_eq!(placed.status.code(), Some(1));
    let err = String::from_utf8_lossy(&placed.stderr);
    assert!(
        err.contains("ramp.urdf:1:1:")
            && err.contains("--base-xyz")
            && err.contains("has none")
            && err.contains("--floating-base"),
        "{err}"
    );
    assert!(placed.stdout.is_empty(), "no half-written output");
}

/// A base pose given to the importer for a model whose root is fixed to the world is refused
/// (it would be ignored); a file's `mech:base` is the start when the base floats and is read.
#[test]
fn a_base_pose_without_a_floating_root_is_refused() {
    let placed = ImportOptions {
        base_pose: Some(nalgebra::Isometry3::translation(0.0, 0.0, 1.0)),
        ..Default::default()
    };
    let Err(err) = restpose::urdf::load_str(&ramp(), "ramp.urdf", &placed) else {
        panic!("a base pose with no floating root must be refused");
    };
    let err = err.to_string();
    assert!(err.starts_with("ramp.urdf:1:1:"), "{err}");
    assert!(err.contains("floating root link"), "{err}");
    let text = ramp().replace(
        "<mech:obstacle",
        "<mech:base xyz=\"0 0 1\"/>\n  <mech:obstacle",
    );
    assert!(restpose::urdf::load_str(&text, "ramp.urdf", &ImportOptions::default()).is_ok());
}
