//! Issue 12: when the loops could not be closed, the assembly error named a constraint row
//! (`coupler_rocker.pos_x`) but not where that joint is written, so on a file of hundreds of
//! joints the user had to search for it. Errors raised after import about one joint
//! (assembly, a held coordinate out of range) now start with `FILE:LINE:COL: joint `NAME`
//! (ELEMENT)`, the place of the joint's element in the file.
use restpose::urdf::{load_file, ImportOptions};
use std::process::Command;

/// A planar four-bar whose ground link (2 m) is longer than crank, coupler and rocker together
/// (0.1 + 0.3 + 0.15 m): the loop joint on line 19 cannot close.
const SHORT_FOUR_BAR: &str = r#"<?xml version="1.0"?>
<robot name="short_four_bar" xmlns:mech="urn:urdf-mech:1">
  <link name="world"/>
  <link name="crank"><inertial><mass value="1"/>
    <inertia ixx="1e-3" ixy="0" ixz="0" iyy="1e-3" iyz="0" izz="1e-3"/></inertial></link>
  <link name="coupler"><inertial><mass value="1"/>
    <inertia ixx="1e-3" ixy="0" ixz="0" iyy="1e-3" iyz="0" izz="1e-3"/></inertial></link>
  <link name="rocker"><inertial><mass value="1"/>
    <inertia ixx="1e-3" ixy="0" ixz="0" iyy="1e-3" iyz="0" izz="1e-3"/></inertial></link>
  <joint name="crank_joint" type="continuous">
    <parent link="world"/><child link="crank"/><axis xyz="0 1 0"/>
  </joint>
  <joint name="crank_coupler" type="continuous">
    <parent link="crank"/><child link="coupler"/><origin xyz="0.1 0 0"/><axis xyz="0 1 0"/>
  </joint>
  <joint name="rocker_joint" type="continuous">
    <parent link="world"/><child link="rocker"/><origin xyz="2 0 0"/><axis xyz="0 1 0"/>
  </joint>
    <mech:loop_joint name="coupler_rocker" type="continuous">
    <parent link="coupler"/><origin xyz="0.3 0 0"/>
    <child link="rocker"/><child_origin xyz="0.15 0 0"/>
    <axis xyz="0 1 0"/>
  </mech:loop_joint>
</robot>
"#;

/// Line and column (from 1) where `needle` starts in `text`.
fn line_col(text: &str, needle: &str) -> (usize, usize) {
    let at = text.find(needle).unwrap();
    let line = text[..at].matches('\n').count() + 1;
    let col = at - text[..at].rfind('\n').map_or(0, |i| i + 1) + 1;
    (line, col)
}

fn write(dir: &tempfile::TempDir) -> String {
    let path = dir.path().join("short_four_bar.urdf");
    std::fs::write(&path, SHORT_FOUR_BAR).unwrap();
    path.display().to_string()
}

#[test]
fn assembly_error_names_the_loop_joint_file_line_and_column() {
    let dir = tempfile::tempdir().unwrap();
    let file = write(&dir);
    let loaded = load_file(&file, &ImportOptions::default()).unwrap();
    let e = restpose::solve(&loaded.model, &Default::default()).unwrap_err();
    // A planar loop is over-constrained (its axes are parallel): Newton closes the
    // independent rows and a redundant one stays violated.
    let restpose::Error::Inconsistent { site, .. } = &e else {
        panic!("expected an inconsistent-loop error, got {e}");
    };
    let site = site.as_ref().expect("the failing row belongs to a joint");
    assert_eq!(site.joint, "coupler_rocker");
    let at = site.at.as_ref().expect("the joint came from a file");
    let (line, col) = line_col(SHORT_FOUR_BAR, "<mech:loop_joint");
    assert_eq!((at.line as usize, at.col as usize), (line, col));
    assert_eq!(at.element, "mech:loop_joint");
    let message = e.to_string();
    let expected = format!("{file}:{line}:{col}: joint `coupler_rocker` (mech:loop_joint): ");
    assert!(message.starts_with(&expected), "{message}");
}

#[test]
fn cli_prints_the_located_assembly_error_and_exits_1() {
    let dir = tempfile::tempdir().unwrap();
    let file = write(&dir);
    let (line, col) = line_col(SHORT_FOUR_BAR, "<mech:loop_joint");
    for sub in ["analyze", "check"] {
        let out = Command::new(env!("CARGO_BIN_EXE_restpose"))
            .args([sub, &file])
            .output()
            .unwrap();
        // `analyze` reports on standard error, `check` in its summary on standard output.
        let err = String::from_utf8_lossy(&out.stderr).to_string()
            + &String::from_utf8_lossy(&out.stdout);
        assert_eq!(out.status.code(), Some(1), "{sub}: {err}");
        assert!(
            err.contains(&format!(
                "{file}:{line}:{col}: joint `coupler_rocker` (mech:loop_joint)"
            )),
            "{sub}: {err}"
        );
        assert!(err.contains("redundant constraint"), "{sub}: {err}");
    }
}

#[test]
fn held_coordinate_out_of_range_names_the_joint_line() {
    let dir = tempfile::tempdir().unwrap();
    let file = write(&dir);
    let options = ImportOptions {
        locks: vec![("rocker_joint".into(), 1, Some(0.0))],
        ..Default::default()
    };
    let e = load_file(&file, &options).unwrap_err();
    let (line, col) = line_col(SHORT_FOUR_BAR, r#"<joint name="rocker_joint""#);
    let message = e.to_string();
    assert!(
        message.starts_with(&format!("{file}:{line}:{col}: lock `rocker_joint`")),
        "{message}"
    );
    assert!(matches!(
        e,
        restpose::Error::CoordinateOutOfRange { dof: 1, .. }
    ));
}

/// The spatial four-bar of `robots/` with its coupler shortened from 0.4272 m to 0.05 m: no
/// row is redundant, the damped Newton iteration gets stuck, and the error is `Assembly`.
#[test]
fn spatial_loop_too_short_names_the_loop_joint() {
    let text = std::fs::read_to_string(format!(
        "{}/robots/four_bar_spatial.urdf",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap();
    assert!(text.contains(r#"<origin xyz="0.4272 0 0"/>"#));
    let short = text.replace(
        r#"<origin xyz="0.4272 0 0"/>"#,
        r#"<origin xyz="0.05 0 0"/>"#,
    );
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("short_spatial.urdf");
    std::fs::write(&path, &short).unwrap();
    let file = path.display().to_string();
    let (line, col) = line_col(&short, "<mech:loop_joint");
    let out = Command::new(env!("CARGO_BIN_EXE_restpose"))
        .args(["analyze", &file])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains(&format!(
            "{file}:{line}:{col}: joint `coupler_rocker` (mech:loop_joint): cannot assemble"
        )),
        "{err}"
    );
    assert!(err.contains("constraint `coupler_rocker."), "{err}");
}
