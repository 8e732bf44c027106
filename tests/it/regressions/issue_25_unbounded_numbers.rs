//! Issue 25, items 1–3 (a black-box fuzz campaign): numbers that statics computes with were
//! accepted unbounded. An obstacle's `<box size="1 -1 1"/>` panicked in
//! `Obstacle::tangent_plane` (`f64::clamp`: min > max); a spring `<end xyz="1e308 0 0"/>`
//! made `verify` panic in nalgebra's SVD ("Singular value was NaN"), and `-1e308` (or a drake
//! `p_BQ` of 1e308) made it loop forever in that SVD, while `check` accepted the file. Now the
//! importer bounds every length it reads (spring ends, drake `p_AP`/`p_BQ`, `mech:force xyz`,
//! origins of shapes and frames, shape sizes (not negative), screw pitch, distance length,
//! mimic coefficients) with an error at `FILE:LINE:COL` naming the element, and no matrix
//! with a non-finite entry reaches a decomposition (`verify` checks the pose first).

use restpose::urdf::{load_str, ImportOptions};
use std::process::Command;

const ROBOTS: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/robots");

/// The contact test's ball on a hinge resting on a world-fixed box (tests/it/contact.rs).
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

/// Line and column (from 1) where `needle` starts in `text`.
fn line_col(text: &str, needle: &str) -> (usize, usize) {
    let at = text
        .find(needle)
        .unwrap_or_else(|| panic!("{needle} not in the text"));
    let line = text[..at].matches('\n').count() + 1;
    let col = at - text[..at].rfind('\n').map_or(0, |i| i + 1) + 1;
    (line, col)
}

/// `text` with `from` replaced (once, and it must be there).
fn edit(text: &str, from: &str, to: &str) -> String {
    assert!(text.contains(from), "{from} not in the text");
    text.replacen(from, to, 1)
}

fn robot(name: &str) -> String {
    std::fs::read_to_string(format!("{ROBOTS}/{name}")).unwrap()
}

/// Loads `text`; the error must be an input error at the element starting with `element`
/// (its line and column) and mention `what`.
fn refused_at(text: &str, element: &str, what: &str) {
    let e = load_str(text, "t.urdf", &ImportOptions::default())
        .err()
        .unwrap_or_else(|| panic!("accepted: {element}"))
        .to_string();
    let (line, col) = line_col(text, element);
    assert!(
        e.starts_with(&format!("t.urdf:{line}:{col}: ")),
        "{e} (expected at {line}:{col})"
    );
    assert!(e.contains(what), "{e} (expected to mention {what})");
}

#[test]
fn a_negative_box_size_is_refused_where_it_is_written() {
    let text = edit(
        BALL_ON_BOX,
        r#"<box size="1 1 1"/>"#,
        r#"<box size="1 -1 1"/>"#,
    );
    refused_at(&text, r#"<box size="1 -1 1"/>"#, "negative size -1");
}

#[test]
fn spring_ends_beyond_the_length_bound_are_refused_where_they_are_written() {
    for (file, end) in [
        (
            "four_bar_spatial.urdf",
            r#"<end link="coupler" xyz="0.21 0 0"/>"#,
        ),
        ("slider_crank.urdf", r#"<end link="slider" xyz="0 0 0"/>"#),
    ] {
        for huge in ["1e308", "-1e308", "1e10"] {
            let bad = end.replace(r#"xyz="0.21 0 0""#, &format!(r#"xyz="{huge} 0 0""#));
            let bad = bad.replace(r#"xyz="0 0 0""#, &format!(r#"xyz="{huge} 0 0""#));
            let text = edit(&robot(file), end, &bad);
            refused_at(&text, &bad, "outside the accepted range");
        }
    }
}

#[test]
fn every_length_statics_uses_is_bounded() {
    let cases: Vec<(String, &str)> = vec![
        // A mech:force's point.
        (
            edit(
                &robot("slider_crank.urdf"),
                r#"link="slider" xyz="0 0 0" force"#,
                r#"link="slider" xyz="1e308 0 0" force"#,
            ),
            r#"<mech:force name="piston_load""#,
        ),
        // An obstacle's collision origin.
        (
            edit(
                BALL_ON_BOX,
                r#"<origin xyz="0.5 0 -0.8"/>"#,
                r#"<origin xyz="0.5 0 1e300"/>"#,
            ),
            r#"<origin xyz="0.5 0 1e300"/>"#,
        ),
        // An obstacle's size.
        (
            edit(
                BALL_ON_BOX,
                r#"<box size="1 1 1"/>"#,
                r#"<box size="1 1e12 1"/>"#,
            ),
            r#"<box size="1 1e12 1"/>"#,
        ),
        // A contact sphere's radius.
        (
            edit(
                BALL_ON_BOX,
                r#"<sphere radius="0.1"/>"#,
                r#"<sphere radius="1e308"/>"#,
            ),
            r#"<sphere radius="1e308"/>"#,
        ),
    ];
    for (text, element) in &cases {
        refused_at(text, element, "outside the accepted range");
    }
}

/// Drake's spring points and ball-constraint points, a screw's pitch, a distance joint's
/// length (the importer test's drake fixtures and loop joints).
#[test]
fn drake_points_pitch_and_distance_are_bounded() {
    let drake = r#"<robot name="d" xmlns:drake="http://drake.mit.edu" xmlns:mech="urn:urdf-mech:1">
  <link name="world"/>
  <link name="bar"><inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="pivot" type="continuous"><parent link="world"/><child link="bar"/><axis xyz="0 0 1"/></joint>
  <drake:linear_spring_damper>
    <drake:linear_spring_damper_body_A name="bar"/><drake:linear_spring_damper_p_AP value="2 0 0"/>
    <drake:linear_spring_damper_body_B name="world"/><drake:linear_spring_damper_p_BQ value="-1 -2 0"/>
    <drake:linear_spring_damper_free_length value="2"/><drake:linear_spring_damper_stiffness value="3"/>
  </drake:linear_spring_damper>
</robot>"#;
    assert!(load_str(drake, "t.urdf", &ImportOptions::default()).is_ok());
    let p = r#"<drake:linear_spring_damper_p_BQ value="1e308 -2 0"/>"#;
    refused_at(
        &edit(
            drake,
            r#"<drake:linear_spring_damper_p_BQ value="-1 -2 0"/>"#,
            p,
        ),
        p,
        "outside the accepted range",
    );
    let screw = edit(
        drake,
        r#"<joint name="pivot" type="continuous"><parent link="world"/><child link="bar"/><axis xyz="0 0 1"/></joint>"#,
        r#"<joint name="pivot" type="continuous"><parent link="world"/><child link="bar"/><axis xyz="0 0 1"/></joint>
  <mech:loop_joint name="nut" type="screw" pitch="1e300"><parent link="world"/><child link="bar"/></mech:loop_joint>"#,
    );
    refused_at(
        &screw,
        r#"<mech:loop_joint name="nut""#,
        "outside the accepted range",
    );
    let rod = screw.replace(
        r#"type="screw" pitch="1e300""#,
        r#"type="distance" length="-1e300""#,
    );
    refused_at(
        &rod,
        r#"<mech:loop_joint name="nut""#,
        "outside the accepted range",
    );
    let rod = screw.replace(
        r#"type="screw" pitch="1e300""#,
        r#"type="distance" length="-1""#,
    );
    refused_at(&rod, r#"<mech:loop_joint name="nut""#, "is negative");
}

/// The three commands on the files of the issue: exit 1 with a located error, no panic (101)
/// and no hang (each run is bounded by the test harness's own time).
#[test]
fn the_commands_refuse_the_issue_files_without_panic_or_hang() {
    let dir = tempfile::tempdir().unwrap();
    let pose = dir.path().join("pose.json");
    std::fs::write(&pose, "{}").unwrap();
    let files = [
        edit(
            BALL_ON_BOX,
            r#"<box size="1 1 1"/>"#,
            r#"<box size="1 -1 1"/>"#,
        ),
        edit(
            &robot("four_bar_spatial.urdf"),
            r#"<end link="coupler" xyz="0.21 0 0"/>"#,
            r#"<end link="coupler" xyz="1e308 0 0"/>"#,
        ),
        edit(
            &robot("slider_crank.urdf"),
            r#"<end link="slider" xyz="0 0 0"/>"#,
            r#"<end link="slider" xyz="-1e308 0 0"/>"#,
        ),
    ];
    for (k, text) in files.iter().enumerate() {
        let file = dir.path().join(format!("f{k}.urdf"));
        std::fs::write(&file, text).unwrap();
        let file = file.to_str().unwrap();
        for args in [
            vec!["check", file],
            vec!["analyze", file, "-q"],
            vec!["verify", file, "-q", "--pose", pose.to_str().unwrap()],
        ] {
            let o = Command::new(env!("CARGO_BIN_EXE_restpose"))
                .args(&args)
                .output()
                .unwrap();
            let err = String::from_utf8_lossy(&o.stderr);
            assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
            assert!(
                err.starts_with(&format!("error: {file}:")),
                "{args:?}: {err}"
            );
        }
    }
}

/// The guard behind the importer: a pose whose energy overflows (a prismatic slider 10³⁰⁰ m
/// out stretches the return spring) is an error naming the spring, not a panic, a hang or a
/// NaN in the report.
#[test]
fn verify_refuses_a_pose_whose_energy_is_not_finite() {
    let m = restpose::urdf::load_file(
        format!("{ROBOTS}/slider_crank.urdf"),
        &ImportOptions::default(),
    )
    .unwrap()
    .model;
    let pose = [("slide".to_string(), vec![1e300])].into_iter().collect();
    let (state, _) = restpose::verify::pose_state(&m, &pose).unwrap();
    let e = restpose::verify::verify(&m, &state, &Default::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("not finite") && e.contains("spring `return_spring`"),
        "{e}"
    );
    // A coordinate that is NaN is named too.
    let mut bad = restpose::State::initial(&m);
    bad.q[0] = f64::NAN;
    let e = restpose::verify::verify(&m, &bad, &Default::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("coordinate") && e.contains("NaN"), "{e}");
}
