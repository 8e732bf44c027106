//! xacro input: published xacro files (vendored in `robots/xacro/` with their licences)
//! expanded in-process equal the same robot's URDF (Unitree's published `a1.urdf`; the URDF
//! `xacrodoc` expands UR5e and A1 to): every link at the same pose at the initial guess, the same
//! joints and body masses; and errors name the xacro file.

use restpose::urdf::{load_file, ImportOptions};
use std::path::{Path, PathBuf};

fn dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("robots/xacro")
}

fn options(args: &[(&str, &str)], packages: &[&str]) -> ImportOptions {
    ImportOptions {
        xacro_args: args
            .iter()
            .map(|(n, v)| (n.to_string(), v.to_string()))
            .collect(),
        packages: packages
            .iter()
            .map(|p| (p.to_string(), dir().join(p)))
            .collect(),
        ..Default::default()
    }
}

/// Every link of `reference` is in `expanded` at the same pose (initial guess, 1e-12); both
/// models have the same joints (type, limits); with `masses`, the bodies have the same masses.
fn assert_same_robot(expanded: &restpose::Model, reference: &restpose::Model, masses: bool) {
    let a = restpose::state::State::initial(expanded);
    let b = restpose::state::State::initial(reference);
    assert_eq!(expanded.links().len(), reference.links().len());
    for l in reference.links() {
        let pa = a
            .link_pose(expanded, &l.name)
            .unwrap_or_else(|| panic!("link `{}` missing from the expansion", l.name));
        let pb = b.link_pose(reference, &l.name).unwrap();
        let dp = (pa.translation.vector - pb.translation.vector).amax();
        let dr = (pa.rotation.to_rotation_matrix().matrix()
            - pb.rotation.to_rotation_matrix().matrix())
        .amax();
        assert!(
            dp < 1e-12 && dr < 1e-12,
            "link `{}`: {dp:e} m, {dr:e}",
            l.name
        );
    }
    // Same joints; limits to the 12 digits a published URDF is printed with.
    let sorted = |m: &restpose::Model| {
        let mut v: Vec<_> = m
            .joints()
            .iter()
            .map(|j| (j.name.clone(), j.kind.name(), j.limits))
            .collect();
        v.sort_by(|x, y| x.0.cmp(&y.0));
        v
    };
    let (ja, jb) = (sorted(expanded), sorted(reference));
    assert_eq!(ja.len(), jb.len());
    for (a, b) in ja.iter().zip(&jb) {
        assert_eq!((&a.0, a.1), (&b.0, b.1));
        match (a.2, b.2) {
            (Some(x), Some(y)) => assert!(
                (x[0] - y[0]).abs() < 1e-9 && (x[1] - y[1]).abs() < 1e-9,
                "joint `{}`: {x:?} vs {y:?}",
                a.0
            ),
            (x, y) => assert_eq!(x, y, "joint `{}`", a.0),
        }
    }
    for body in reference.bodies().iter().filter(|_| masses) {
        let other = expanded
            .bodies()
            .iter()
            .find(|b| b.name == body.name)
            .unwrap();
        assert!(
            (other.mass - body.mass).abs() <= 1e-12 * body.mass.max(1.0),
            "body `{}`",
            body.name
        );
    }
}

#[test]
fn a1_xacro_expands_to_unitrees_published_urdf() {
    let x = load_file(
        dir().join("a1_description/xacro/robot.xacro"),
        &options(&[], &["a1_description"]),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    // Unitree's published URDF: the same kinematics (its masses are of a later revision
    // than the xacro's `const.xacro`: hip 0.696 kg there, 0.595 kg in the xacro).
    let r = load_file(
        dir().join("a1_description/urdf/a1.urdf"),
        &options(&[], &[]),
    )
    .unwrap();
    assert_same_robot(&x.model, &r.model, false);
    // The xacro's own numbers, as xacrodoc expands them: everything the same.
    let r = load_file(dir().join("reference/a1.xacrodoc.urdf"), &options(&[], &[])).unwrap();
    assert_same_robot(&x.model, &r.model, true);
    // The 12 leg joints, in the published file's limits.
    assert_eq!(
        x.model
            .joints()
            .iter()
            .filter(|j| j.kind.name() == "revolute")
            .count(),
        12
    );
}

#[test]
fn ur5e_xacro_with_arguments_expands_as_xacrodoc_does() {
    let x = load_file(
        dir().join("ur_description/urdf/ur.urdf.xacro"),
        &options(
            &[("ur_type", "ur5e"), ("name", "ur5e")],
            &["ur_description"],
        ),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let r = load_file(
        dir().join("reference/ur5e.xacrodoc.urdf"),
        &options(&[], &[]),
    )
    .unwrap();
    assert_same_robot(&x.model, &r.model, true);
    // Another argument gives another robot (the UR10e is longer).
    let ur10 = load_file(
        dir().join("ur_description/urdf/ur.urdf.xacro"),
        &options(&[("ur_type", "ur10e")], &["ur_description"]),
    )
    .unwrap();
    let reach = |m: &restpose::Model| {
        let s = restpose::state::State::initial(m);
        s.link_pose(m, "tool0").unwrap().translation.vector.norm()
    };
    assert!(reach(&ur10.model) > reach(&x.model) + 0.3);
}

/// Franka's panda xacro (franka_ros) uses Python expressions that `xacro-rs` 0.2.2 does not
/// evaluate (`xyz.split(' ')[0]`): a clear error naming the file, the expression and the
/// macro stack, not a wrong robot.
#[test]
fn franka_panda_xacro_beyond_xacro_rs_is_a_clear_error() {
    let e = load_file(
        dir().join("franka_description/robots/panda/panda.urdf.xacro"),
        &options(&[], &["franka_description"]),
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("xacro expansion failed") && e.contains("in macro: collision_capsule"),
        "{e}"
    );
    // Located in the included file that holds the expression, at the expression.
    let utils = dir().join("franka_description/robots/common/utils.xacro");
    let at = e
        .strip_prefix(&format!("{}:", utils.display()))
        .unwrap_or_else(|| panic!("not located in utils.xacro: {e}"));
    let mut pos = at.split(':').map(|n| n.parse::<usize>().unwrap_or(0));
    let (line, col) = (pos.next().unwrap(), pos.next().unwrap());
    let text = std::fs::read_to_string(&utils).unwrap();
    let source_line = text.lines().nth(line - 1).unwrap();
    assert!(
        source_line[col - 1..].starts_with("${xyz.split("),
        "{source_line}"
    );
}

/// `restpose analyze FILE.xacro --xacro-arg … --package …` solves the expanded robot; a
/// missing package and a bad expression are errors naming the xacro file (exit 1).
#[test]
fn cli_reads_xacro_and_names_the_file_in_errors() {
    let xacro = dir().join("ur_description/urdf/ur.urdf.xacro");
    let pkg = format!("ur_description={}", dir().join("ur_description").display());
    let run = |args: &[&str]| {
        std::process::Command::new(env!("CARGO_BIN_EXE_restpose"))
            .args(args)
            .output()
            .unwrap()
    };
    let x = xacro.to_str().unwrap();
    let ok = run(&[
        "analyze",
        x,
        "--xacro-arg",
        "ur_type:=ur5e",
        "--package",
        &pkg,
        "--json",
        "-",
    ]);
    assert_eq!(
        ok.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&ok.stderr)
    );
    let json: serde_json::Value = serde_json::from_slice(&ok.stdout).unwrap();
    assert_eq!(json["converged"], true);
    assert_eq!(json["q_mujoco"].as_array().unwrap().len(), 6);
    // A package that is nowhere: `$(find …)` cannot be resolved.
    let tmp = tempfile::tempdir().unwrap();
    let lost = tmp.path().join("lost.urdf.xacro");
    std::fs::write(
        &lost,
        r#"<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro"><xacro:include filename="$(find no_such_package)/arm.xacro"/></robot>"#,
    )
    .unwrap();
    let missing = run(&["check", lost.to_str().unwrap()]);
    assert_eq!(missing.status.code(), Some(1));
    let e = String::from_utf8_lossy(&missing.stderr);
    assert!(
        e.contains("lost.urdf.xacro:1:1: xacro expansion failed")
            && e.contains("no_such_package")
            && e.contains("--package"),
        "{e}"
    );
    // A bad expression in a xacro file of our own.
    let bad = tmp.path().join("bad.urdf.xacro");
    std::fs::write(
        &bad,
        r#"<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro"><link name="${undefined_property * 2}"/></robot>"#,
    )
    .unwrap();
    let b = run(&["check", bad.to_str().unwrap()]);
    assert_eq!(b.status.code(), Some(1));
    let e = String::from_utf8_lossy(&b.stderr);
    // At the expression: line 1, column 73 of the one-line file.
    assert!(
        e.contains("bad.urdf.xacro:1:73: xacro expansion failed")
            && e.contains("undefined_property"),
        "{e}"
    );
    // An error in the expanded URDF: the xacro file, marked as expanded.
    std::fs::write(
        &bad,
        r#"<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro"><xacro:property name="n" value="a"/><link name="${n}"/><joint name="j" type="revolute"><parent link="a"/><child link="nowhere"/></joint></robot>"#,
    )
    .unwrap();
    let b = run(&["check", bad.to_str().unwrap()]);
    assert_eq!(b.status.code(), Some(1));
    let e = String::from_utf8_lossy(&b.stderr);
    assert!(
        e.contains("bad.urdf.xacro (expanded):") && e.contains("nowhere"),
        "{e}"
    );
}

/// A one-link robot that declares the xacro namespace and uses none of it, after a blank line
/// (pybullet_data's `diff_ring.urdf` starts so).
const DECLARED_ONLY: &str = r#"
<?xml version="1.0" ?>
<robot name="r" xmlns:xacro="http://ros.org/wiki/xacro">
  <link name="world"/>
  <link name="arm"><inertial><origin xyz="0 0 -0.5"/><mass value="2"/>
    <inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <joint name="hinge" type="continuous"><parent link="world"/><child link="arm"/>
    <axis xyz="0 1 0"/></joint>
</robot>
"#;

/// A URDF that declares the xacro namespace without using it (xacro's own output keeps the
/// declaration; pybullet_data's `diff_ring.urdf`, with a blank line before `<?xml`) is read as
/// URDF: the late declaration is accepted with its warning, as in any URDF, where the xacro
/// reader refused it. A file that uses xacro still goes through the expansion.
#[test]
fn declared_but_unused_xacro_namespace_is_plain_urdf() {
    let tmp = tempfile::tempdir().unwrap();
    let file = tmp.path().join("exported.urdf");
    let urdf = DECLARED_ONLY;
    std::fs::write(&file, urdf).unwrap();
    let l = load_file(&file, &ImportOptions::default()).unwrap();
    assert_eq!(l.model.bodies().len(), 1);
    assert!(
        l.warnings
            .iter()
            .any(|w| w.contains("XML declaration is not at the start")),
        "{:?}",
        l.warnings
    );
    // The same file using a property is expanded (and its mass is the property's value).
    let used = urdf
        .trim_start()
        .replace(
            "<link name=\"world\"/>",
            "<xacro:property name=\"m\" value=\"3\"/><link name=\"world\"/>",
        )
        .replace("<mass value=\"2\"/>", "<mass value=\"${m}\"/>");
    std::fs::write(&file, used).unwrap();
    let l = load_file(&file, &ImportOptions::default()).unwrap();
    assert_eq!(l.model.bodies()[0].mass, 3.0);
}

/// A URDF that mentions xacro only in comments (xacro's output keeps the commented-out macro
/// calls of its sources, `${…}` included: Talos, PR2, TIAGo, Bolt and Solo of
/// example-robot-data) is read as URDF, without the expansion: an error names the file's own
/// line, not the expansion's.
#[test]
fn xacro_in_comments_only_is_plain_urdf() {
    let tmp = tempfile::tempdir().unwrap();
    let file = tmp.path().join("talos_like.urdf");
    // The declared-but-unused test's robot, with a commented-out macro call on line 3.
    let urdf = DECLARED_ONLY.trim_start().replace(
        "  <link name=\"world\"/>",
        "  <!-- <xacro:gripper name=\"${name}_inner\" reduction=\"1.0\"/> -->\n  <link name=\"world\"/>",
    );
    std::fs::write(&file, &urdf).unwrap();
    let l = load_file(&file, &ImportOptions::default()).unwrap();
    assert_eq!(l.model.bodies().len(), 1);
    assert_eq!(l.model.bodies()[0].mass, 2.0);
    // A bad joint type on line 7: the message names line 7 of the file itself.
    std::fs::write(&file, urdf.replace("\"continuous\"", "\"hinged\"")).unwrap();
    let e = load_file(&file, &ImportOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("talos_like.urdf:7:"), "{e}");
    assert!(!e.contains("expanded"), "{e}");
}
