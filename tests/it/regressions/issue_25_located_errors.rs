//! Issue 25, items 5, 7, 8 and 10: errors about an element that did not say where it is
//! written, and inputs accepted silently. A link selected for contact without collision
//! geometry, a drake spring with a negative free length, a contact point's row in an assembly
//! or inconsistency error, a constant energy (no file named), and `check` exiting 1 with no
//! `error:` line; a non-finite energy written into verify's report as `null` / "NaN J"; a
//! second `<parent>` inside a `mech:loop_joint` accepted; a spring whose two ends are the same
//! point of the same link accepted without a word.

use restpose::urdf::{load_str, ImportOptions};
use std::process::Command;

const ROBOTS: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/robots");

/// Line and column (from 1) where `needle` starts in `text`.
fn line_col(text: &str, needle: &str) -> (usize, usize) {
    let at = text.find(needle).unwrap();
    let line = text[..at].matches('\n').count() + 1;
    let col = at - text[..at].rfind('\n').map_or(0, |i| i + 1) + 1;
    (line, col)
}

fn load_err(text: &str) -> String {
    match load_str(text, "t.urdf", &ImportOptions::default()) {
        Ok(_) => panic!("the file must be refused"),
        Err(e) => e.to_string(),
    }
}

const ARM: &str = r#"<robot name="r" xmlns:mech="urn:urdf-mech:1" xmlns:drake="http://drake.mit.edu">
  <link name="world"/>
  <link name="arm"><inertial><origin xyz="0.5 0 0"/><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0.5 0 0"/><geometry><sphere radius="0.1"/></geometry></collision></link>
  <link name="log"><inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="pivot" type="continuous"><parent link="world"/><child link="arm"/><axis xyz="0 1 0"/></joint>
  <joint name="hinge" type="continuous"><parent link="arm"/><child link="log"/><axis xyz="0 1 0"/></joint>
  <mech:ground/>
  <mech:contact link="arm"/>
</robot>"#;

#[test]
fn a_contact_link_without_collision_geometry_is_located_at_its_mech_contact() {
    let text = ARM.replace(
        r#"<mech:contact link="arm"/>"#,
        r#"<mech:contact link="log"/>"#,
    );
    let e = load_err(&text);
    let (line, col) = line_col(&text, r#"<mech:contact link="log"/>"#);
    assert!(e.starts_with(&format!("t.urdf:{line}:{col}: ")), "{e}");
    assert!(
        e.contains("link `log` is selected for contact but has no <collision>"),
        "{e}"
    );
}

#[test]
fn a_drake_spring_with_a_negative_free_length_is_located() {
    let spring = r#"<drake:linear_spring_damper>
    <drake:linear_spring_damper_body_A name="arm"/><drake:linear_spring_damper_p_AP value="1 0 0"/>
    <drake:linear_spring_damper_body_B name="world"/><drake:linear_spring_damper_p_BQ value="0 0 1"/>
    <drake:linear_spring_damper_free_length value="-0.5"/><drake:linear_spring_damper_stiffness value="3"/>
  </drake:linear_spring_damper>
</robot>"#;
    let text = ARM.replace("</robot>", spring);
    let e = load_err(&text);
    let (line, col) = line_col(&text, r#"<drake:linear_spring_damper_free_length"#);
    assert!(e.starts_with(&format!("t.urdf:{line}:{col}: ")), "{e}");
    assert!(
        e.contains("linear_spring_damper_0") && e.contains("negative"),
        "{e}"
    );
}

/// The row of a contact point (`arm.contact[0]@floor`) names the link's element, as a joint's
/// row names the joint's.
#[test]
fn a_contact_row_names_its_link_and_where_it_is_written() {
    let m = load_str(ARM, "t.urdf", &ImportOptions::default())
        .unwrap()
        .model;
    let site = m.row_site("arm.contact[0]@floor").expect("a site");
    let (line, col) = line_col(ARM, r#"<link name="arm">"#);
    assert_eq!(
        site.to_string(),
        format!("t.urdf:{line}:{col}: link `arm` (link)")
    );
    let joint = m.row_site("hinge.pos_x").unwrap();
    let (line, col) = line_col(ARM, r#"<joint name="hinge""#);
    assert_eq!(
        joint.to_string(),
        format!("t.urdf:{line}:{col}: joint `hinge` (joint)")
    );
}

#[test]
fn a_constant_energy_names_the_file() {
    let text = r#"<robot name="t"><link name="world"/><link name="a"/>
  <joint name="j" type="continuous"><parent link="world"/><child link="a"/></joint></robot>"#;
    let m = load_str(text, "t.urdf", &ImportOptions::default())
        .unwrap()
        .model;
    let e = restpose::solve(&m, &Default::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("t.urdf: the potential energy of `t` is constant"),
        "{e}"
    );
}

/// `check` exits 1 when the initial guess does not assemble, and says why on standard error.
#[test]
fn check_prints_an_error_line_when_it_exits_non_zero() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("short.urdf");
    // The slider-crank's wrist pin moved 0.5 m out of the mechanism's plane: the planar
    // loop cannot close.
    let text = std::fs::read_to_string(format!("{ROBOTS}/slider_crank.urdf"))
        .unwrap()
        .replace(
            r#"<parent link="rod"/>   <origin xyz="0.3 0 0"/>"#,
            r#"<parent link="rod"/>   <origin xyz="0.3 0 0.5"/>"#,
        );
    std::fs::write(&file, text).unwrap();
    for format in ["text", "json"] {
        let o = Command::new(env!("CARGO_BIN_EXE_restpose"))
            .args(["check", file.to_str().unwrap(), "--format", format])
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{err}");
        assert!(
            err.lines()
                .any(|l| l.starts_with("error: ") && l.contains(file.to_str().unwrap())),
            "{format}: {err}"
        );
    }
}

/// verify's report never carries a non-finite number: a pose whose energy overflows is an
/// error (exit 1) naming the term, and no JSON is written.
#[test]
fn verify_reports_no_non_finite_number() {
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("v.json");
    let o = Command::new(env!("CARGO_BIN_EXE_restpose"))
        .args([
            "verify",
            &format!("{ROBOTS}/slider_crank.urdf"),
            "--joint",
            "slide=1e300",
            "--json",
            json.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    let (out, err) = (
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr),
    );
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("spring `return_spring`"), "{err}");
    assert!(!out.contains("NaN") && !err.contains("NaN"), "{out}{err}");
    assert!(!json.exists());
}

#[test]
fn a_second_parent_in_a_loop_joint_is_refused() {
    let text = std::fs::read_to_string(format!("{ROBOTS}/four_bar_spatial.urdf")).unwrap();
    let one = r#"<parent link="coupler"/>"#;
    assert!(text.contains(one));
    let twice = text.replacen(one, &format!(r#"{one}<parent link="crank"/>"#), 1);
    let e = load_err(&twice);
    let (line, col) = line_col(&twice, &format!(r#"{one}<parent link="crank"/>"#));
    let col = col + one.len();
    assert!(e.starts_with(&format!("t.urdf:{line}:{col}: ")), "{e}");
    assert!(e.contains("`coupler_rocker` has a second <parent>"), "{e}");
}

#[test]
fn a_spring_between_one_point_of_one_link_is_warned_about() {
    let spring = r#"<mech:spring name="idle" stiffness="10" free_length="0.1">
    <end link="arm" xyz="0.2 0 0"/><end link="arm" xyz="0.2 0 0"/></mech:spring>
</robot>"#;
    let text = ARM.replace("</robot>", spring);
    let loaded = load_str(&text, "t.urdf", &ImportOptions::default()).unwrap();
    let (line, col) = line_col(&text, r#"<mech:spring name="idle""#);
    let w: Vec<&String> = loaded
        .warnings
        .iter()
        .filter(|w| w.contains("spring `idle`"))
        .collect();
    assert_eq!(w.len(), 1, "{:?}", loaded.warnings);
    assert!(
        w[0].starts_with(&format!("t.urdf:{line}:{col}: ")),
        "{}",
        w[0]
    );
    assert!(w[0].contains("same point"), "{}", w[0]);
    // Two different points of one link, or the same point of two links: no warning.
    for other in [
        r#"<end link="arm" xyz="0.3 0 0"/>"#,
        r#"<end link="log" xyz="0.2 0 0"/>"#,
    ] {
        let text = text.replacen(
            r#"<end link="arm" xyz="0.2 0 0"/></mech:spring>"#,
            &format!("{other}</mech:spring>"),
            1,
        );
        let loaded = load_str(&text, "t.urdf", &ImportOptions::default()).unwrap();
        assert!(
            !loaded.warnings.iter().any(|w| w.contains("spring `idle`")),
            "{:?}",
            loaded.warnings
        );
    }
}
