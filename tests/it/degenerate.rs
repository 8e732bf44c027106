//! Degenerate and invalid models end with a specific message, never a confident answer
//! (issue 12 §3): constant energy, a floating base nothing holds, an effort on a free joint,
//! negative or absurd numbers, unknown joint names.

use crate::common::builders::{initial, linear, pendulum};
use nalgebra::{Matrix3, Vector3};
use restpose::model::{Effort, ForceLaw, JointId, JointKind, ModelBuilder};
use restpose::{urdf, Error, Options, Termination};
use std::process::Command;

const INERTIA: &str = r#"<inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/>"#;

fn load(text: &str) -> restpose::Result<restpose::Model> {
    urdf::load_str(text, "bad.urdf", &Default::default()).map(|l| l.model)
}

fn one_joint(kind: &str, link: &str, extra: &str) -> String {
    format!(
        r#"<robot name="d" xmlns:mech="urn:urdf-mech:1">
  <link name="world"/>
  {link}
  <joint name="pivot" type="{kind}"><parent link="world"/><child link="bar"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  {extra}
</robot>"#
    )
}

/// A bar on joint `pivot` (about z at the origin) of `kind`, limits ±1: massless, or 1 kg
/// at the pivot with inertia 0.1 𝟙 (what [`one_joint`] writes in URDF).
fn one_joint_built(kind: JointKind, mass: f64) -> (ModelBuilder, JointId) {
    let inertia = Matrix3::identity() * if mass > 0.0 { 0.1 } else { 0.0 };
    let (mut b, pivot) = pendulum("d", kind, mass, Vector3::zeros(), inertia);
    b.set_limits(pivot, -1.0, 1.0);
    (b, pivot)
}

fn run(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_restpose"))
        .args(args)
        .output()
        .unwrap()
}

#[test]
fn massless_links_without_springs_are_refused() {
    let m = one_joint_built(JointKind::Revolute, 0.0).0.build().unwrap();
    match restpose::solve(&m, &Options::default()) {
        Err(e @ Error::ConstantEnergy { dof: 1, .. }) => {
            let msg = e.to_string();
            assert!(msg.contains("<inertial>"), "{msg}");
            assert!(
                !msg.contains("--"),
                "a library message names a CLI flag: {msg}"
            );
        }
        other => panic!("expected ConstantEnergy, got {other:?}"),
    }
    // The same mechanism with a spring is well posed.
    let (mut sprung, pivot) = one_joint_built(JointKind::Revolute, 0.0);
    sprung.add_joint_spring(pivot, 0, linear(1.0), 0.25);
    let sprung = sprung.build().unwrap();
    let (s, r) = restpose::solve(&sprung, &Options::default()).unwrap();
    assert!(r.converged());
    assert!((s.joint(&sprung, "pivot").unwrap()[0] - 0.25).abs() < 1e-9);
    // The CLI, given the mechanism as URDF, exits 1 and adds the option that gives links
    // masses from their geometry.
    let text = one_joint("revolute", r#"<link name="bar"/>"#, "");
    let dir = tempfile::tempdir().unwrap();
    let f = dir.path().join("m.urdf");
    std::fs::write(&f, &text).unwrap();
    let out = run(&["analyze", f.to_str().unwrap(), "--quiet"]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("--inertia-from-geometry"), "{err}");
}

#[test]
fn floating_base_held_by_nothing_is_unbounded() {
    let l = urdf::load_file(
        concat!(env!("CARGO_MANIFEST_DIR"), "/robots/pendulum.urdf"),
        &urdf::ImportOptions {
            floating_base: true,
            ..Default::default()
        },
    )
    .unwrap();
    let (_, r) = restpose::solve(&l.model, &Options::default()).unwrap();
    assert_eq!(r.termination, Termination::Unbounded);
    assert!(r.iterations < 50, "{} iterations", r.iterations);
    // Gravity is along −y in that file: the free bodies fall along −y.
    let falling = r
        .diagnostics
        .free_directions
        .iter()
        .any(|d| d.contains("translating along (0.000, -1.000, 0.000)"));
    assert!(falling, "{:?}", r.diagnostics.free_directions);
    let out = run(&[
        "analyze",
        concat!(env!("CARGO_MANIFEST_DIR"), "/robots/pendulum.urdf"),
        "--floating-base",
        "--quiet",
    ]);
    assert_eq!(out.status.code(), Some(3));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("unbounded") && err.contains("falls without bound"),
        "{err}"
    );
}

#[test]
fn effort_on_a_free_continuous_joint_is_unbounded() {
    let (mut b, pivot) = one_joint_built(JointKind::Continuous, 1.0);
    b.add_effort(Effort {
        joint: pivot,
        dof: 0,
        value: 2.0,
    });
    let m = b.clone().build().unwrap();
    let (_, r) = restpose::solve(&m, &Options::default()).unwrap();
    assert_eq!(r.termination, Termination::Unbounded);
    assert!(r.iterations < 50, "{} iterations", r.iterations);
    assert_eq!(
        r.diagnostics.free_directions,
        vec!["joint `pivot` coordinate 0 increasing".to_string()]
    );
    // Resisted by a spring it rests where 3 θ = 2.
    b.add_joint_spring(pivot, 0, linear(3.0), 0.0);
    let m = b.build().unwrap();
    let (s, r) = restpose::solve(&m, &Options::default()).unwrap();
    assert!(r.converged(), "{:?}", r.termination);
    assert!((s.joint(&m, "pivot").unwrap()[0] - 2.0 / 3.0).abs() < 1e-9);
}

/// The message of a load error, asserting it is located in the file.
fn load_error(text: &str) -> String {
    match load(text) {
        Err(e @ Error::Input { .. }) => e.to_string(),
        other => panic!("expected a located input error, got {other:?}"),
    }
}

#[test]
fn negative_stiffness_and_absurd_numbers_are_refused_at_load() {
    let link =
        format!(r#"<link name="bar"><inertial><mass value="1"/>{INERTIA}</inertial></link>"#);
    let msg = load_error(&one_joint(
        "continuous",
        &link,
        r#"<mech:joint_spring joint="pivot" stiffness="-3"/>"#,
    ));
    assert!(msg.starts_with("bad.urdf:6:3:"), "{msg}");
    assert!(
        msg.contains("stiffness") && msg.contains("negative"),
        "{msg}"
    );
    let msg = load_error(&one_joint(
        "continuous",
        &format!(r#"<link name="bar"><inertial><mass value="1e308"/>{INERTIA}</inertial></link>"#),
        "",
    ));
    assert!(msg.starts_with("bad.urdf:3:"), "{msg}");
    assert!(msg.contains("link `bar`") && msg.contains("mass"), "{msg}");
    let msg = load_error(&one_joint(
        "continuous",
        &link,
        r#"<mech:joint_effort joint="pivot" value="1e300"/>"#,
    ));
    assert!(
        msg.contains("effort on `pivot`") && msg.contains("value"),
        "{msg}"
    );
    let msg = load_error(&one_joint(
        "continuous",
        &link,
        r#"<mech:gravity xyz="0 0 -1e200"/>"#,
    ));
    assert!(msg.contains("gravity"), "{msg}");
    // Non-finite numbers are refused where they are parsed.
    let msg = load_error(&one_joint(
        "continuous",
        &link,
        r#"<mech:joint_spring joint="pivot" stiffness="NaN"/>"#,
    ));
    assert!(msg.contains("stiffness"), "{msg}");
}

/// A result never carries non-finite numbers: on every example robot the JSON has no
/// `null` and a verdict only with finite eigenvalues.
#[test]
fn results_have_no_null_numbers() {
    for name in ["pendulum", "slider_crank", "ur5_class", "four_bar_spatial"] {
        let path = format!("{}/robots/{name}.urdf", env!("CARGO_MANIFEST_DIR"));
        let l = urdf::load_file(&path, &Default::default()).unwrap();
        let (s, r) = restpose::solve(&l.model, &Options::default()).unwrap();
        let json = restpose::export::json::AnalysisResult::new(&l.model, &s, &r).to_json();
        assert!(!json.contains("null"), "{name}: {json}");
        if let Some(st) = &r.stability {
            assert!(st.eigenvalues.iter().all(|x| x.is_finite()), "{name}");
        }
    }
}

#[test]
fn unknown_joint_names_get_a_suggestion() {
    let l = urdf::load_file(
        concat!(env!("CARGO_MANIFEST_DIR"), "/robots/pendulum.urdf"),
        &Default::default(),
    )
    .unwrap();
    let values = [("pivto".to_string(), vec![0.1])].into_iter().collect();
    match restpose::verify::pose_state(&l.model, &values) {
        Err(e @ Error::UnknownJoint { .. }) => {
            assert!(e.to_string().contains("did you mean `pivot`?"), "{e}")
        }
        other => panic!("expected UnknownJoint, got {other:?}"),
    }
    let values = [("pivot".to_string(), vec![0.1, 0.2])]
        .into_iter()
        .collect();
    assert!(matches!(
        restpose::verify::pose_state(&l.model, &values),
        Err(Error::ValueCount { got: 2, .. })
    ));
    let out = run(&[
        "analyze",
        concat!(env!("CARGO_MANIFEST_DIR"), "/robots/pendulum.urdf"),
        "--lock",
        "pivto=0.1",
        "--quiet",
    ]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("did you mean `pivot`?"), "{err}");
}

#[test]
fn force_table_out_of_range_names_the_spring_and_the_deflection() {
    let (mut b, pivot) = one_joint_built(JointKind::Continuous, 1.0);
    let table = ForceLaw::Table {
        points: vec![(-0.1, -1.0), (0.1, 1.0)],
        extrapolate_linear: false,
        bounded: true,
    };
    b.add_joint_spring(pivot, 0, table, 0.0);
    initial(&mut b, pivot, 0, 0.5);
    let m = b.build().unwrap();
    match restpose::solve(&m, &Options::default()) {
        Err(Error::ForceTableOutOfRange {
            element,
            deflection,
            lower,
            upper,
        }) => {
            assert_eq!(element, "joint spring on `pivot`");
            assert!((deflection - 0.5).abs() < 1e-9, "{deflection}");
            assert_eq!((lower, upper), (-0.1, 0.1));
        }
        other => panic!("expected ForceTableOutOfRange, got {other:?}"),
    }
    // A lock on a coordinate the joint does not have, asked of the importer.
    let link =
        format!(r#"<link name="bar"><inertial><mass value="1"/>{INERTIA}</inertial></link>"#);
    let text = one_joint("continuous", &link, "");
    let e = urdf::load_str(
        &text,
        "bad.urdf",
        &urdf::ImportOptions {
            locks: vec![("pivot".into(), 1, Some(0.0))],
            ..Default::default()
        },
    )
    .unwrap_err();
    assert!(
        matches!(
            &e,
            Error::CoordinateOutOfRange {
                dof: 1,
                count: 1,
                ..
            }
        ),
        "{e}"
    );
    assert!(!e.to_string().contains("--"), "{e}");
}
