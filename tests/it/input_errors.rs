//! Bad input gets an error naming the file, line, column and element; never a panic.
use restpose::urdf::{load_str, ImportOptions};

fn err(text: &str) -> String {
    match load_str(text, "bad.urdf", &ImportOptions::default()) {
        Ok(_) => panic!("accepted bad input:\n{text}"),
        Err(e) => e.to_string(),
    }
}

const HEAD: &str = "<robot name=\"r\" xmlns:mech=\"urn:urdf-mech:1\">\n<link name=\"world\"/>\n<link name=\"a\"/>\n";

fn with(body: &str) -> String {
    format!("{HEAD}{body}\n</robot>")
}

const J: &str = r#"<joint name="j" type="revolute"><parent link="world"/><child link="a"/><axis xyz="0 0 1"/></joint>"#;

#[test]
fn each_error_names_file_line_and_element() {
    let cases: Vec<(String, &str, &str)> = vec![
        (with(r#"<joint name="j" type="revolute"><parent link="world"/><child link="nope"/></joint>"#), "bad.urdf:4:", "<child> of joint `j` refers to an unknown link or frame `nope`"),
        (with(&format!("{J}\n<link name=\"a\"/>")), "bad.urdf:5:", "duplicate link name `a`"),
        (with("<link name=\"b\"/>"), "bad.urdf:3:", "second root link `a`"),
        (with(r#"<joint name="j" type="revolute"><parent link="world"/><child link="a"/><axis xyz="0 0 0"/></joint>"#), "bad.urdf:4:", "joint `j` has a zero-length axis"),
        (with(&format!("{J}\n<link name=\"b\"><inertial><mass value=\"-1\"/></inertial></link>")), "bad.urdf:5:", "negative mass"),
        (with(r#"<joint name="j" type="revolute"><parent link="world"/><child link="a"/><origin xyz="0 zero 0"/></joint>"#), "bad.urdf:4:", "<origin> of joint `j`: attribute `xyz` = \"0 zero 0\" must be 3 finite numbers"),
        (with(&format!("{J}\n<mech:spinner/>")), "bad.urdf:5:", "unknown element <mech:spinner>"),
        (with(&format!("{J}\n<mech:joint_spring joint=\"elbow\" stiffness=\"1\"/>")), "bad.urdf:5:", "unknown joint `elbow`"),
        (with(&format!("{J}\n<mech:force name=\"f\" link=\"a\" torque=\"0 0 1\"/>")), "bad.urdf:5:", "torque"),
        (with(&format!("{J}\n<mech:force name=\"f\" link=\"a\" force=\"1 0 0\" frame=\"link\"/>")), "bad.urdf:5:", "follower"),
        (with(&format!("{J}\n<xacro:macro name=\"m\"/>")), "bad.urdf:5:", "xacro"),
        (with("<joint name=\"j\" type=\"hinge\"><parent link=\"world\"/><child link=\"a\"/></joint>"), "bad.urdf:4:", "unknown type \"hinge\""),
        (format!("{HEAD}<joint name=\"j\""), "bad.urdf:", "not well-formed XML"),
        (with(&format!("{J}\n<mech:spring name=\"s\" stiffness=\"1\" free_length=\"1\"><end link=\"a\"/></mech:spring>")), "bad.urdf:5:", "exactly two <end>"),
        (with(&format!("{J}\n<joint name=\"j\" type=\"fixed\"><parent link=\"a\"/><child link=\"world\"/></joint>")), "bad.urdf:5:", "duplicate joint name `j`"),
        (with(&format!("{J}\n<link name=\"b\"><inertial><mass value=\"nan\"/></inertial></link>")), "bad.urdf:5:", "is not a finite number"),
        (with(&format!("{J}\n<link name=\"b\"><inertial><origin xyz=\"0 inf 0\"/><mass value=\"1\"/></inertial></link>")), "bad.urdf:5:", "must be 3 finite numbers"),
        (
            with(&format!("{J}\n<link name=\"b\"/><link name=\"c\"/>\n<joint name=\"k\" type=\"revolute\"><parent link=\"a\"/><child link=\"b\"/><mimic joint=\"m\"/></joint>\n<joint name=\"m\" type=\"revolute\"><parent link=\"a\"/><child link=\"c\"/><mimic joint=\"k\"/></joint>")),
            "bad.urdf:",
            "mimic cycle",
        ),
    ];
    for (text, at, what) in cases {
        let e = err(&text);
        assert!(e.starts_with(at), "expected position {at} in: {e}");
        assert!(e.contains(what), "expected `{what}` in: {e}");
    }
}

#[test]
fn loop_that_cannot_close_is_reported() {
    let text = r#"<robot name="r" xmlns:mech="urn:urdf-mech:1"><link name="world"/>
      <link name="a"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
      <joint name="j" type="revolute"><parent link="world"/><child link="a"/><axis xyz="0 0 1"/></joint>
      <mech:loop_joint name="far" type="spherical"><parent link="a"/><origin xyz="1 0 0"/><child link="world"/><child_origin xyz="5 0 0"/></mech:loop_joint>
    </robot>"#;
    let m = load_str(text, "t.urdf", &ImportOptions::default())
        .unwrap()
        .model;
    let e = restpose::solve(&m, &Default::default())
        .unwrap_err()
        .to_string();
    // One revolute degree of freedom cannot bring a point 1 m from the axis to 5 m: the loop's
    // rows are over-constrained and inconsistent.
    assert!(
        e.contains("inconsistent over-constrained") && e.contains("`far`"),
        "{e}"
    );
}

/// A planar four-bar whose loop pin is 5 cm out of the plane: the redundant out-of-plane rows
/// cannot hold, and the error says so instead of solving something else.
#[test]
fn inconsistent_redundant_rows_are_refused() {
    let path = format!("{}/robots/slider_crank.urdf", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(path).unwrap().replace(
        r#"<child_origin xyz="0 0 0"/>"#,
        r#"<child_origin xyz="0 0 0.05"/>"#,
    );
    let m = load_str(&text, "t.urdf", &ImportOptions::default())
        .unwrap()
        .model;
    let e = restpose::solve(&m, &Default::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("inconsistent over-constrained")
            && e.contains("pos_z")
            && e.contains("`wrist_pin`"),
        "{e}"
    );
}

#[test]
fn undeclared_prefix_is_repaired_with_a_warning() {
    let text = format!("<robot name=\"r\">\n<link name=\"world\"/><link name=\"a\"/>{J}<mech:gravity xyz=\"0 0 -1\"/></robot>");
    let l = load_str(&text, "t.urdf", &ImportOptions::default()).unwrap();
    assert!(l.warnings.iter().any(|w| w.contains("mech")));
    assert_eq!(l.model.gravity().z, -1.0);
}

#[test]
fn foreign_elements_are_ignored_and_listed() {
    let text = with(&format!(
        "{J}\n<transmission name=\"t\"/><gazebo/><sensor name=\"s\"/>"
    ));
    let l = load_str(&text, "t.urdf", &ImportOptions::default()).unwrap();
    assert_eq!(l.ignored.len(), 1, "{:?}", l.ignored);
}

/// Prefixes and `${` inside comments are not markup: no warning, no error.
#[test]
fn comments_do_not_trigger_prefix_repair_or_xacro_errors() {
    let text = format!("<robot name=\"r\">\n<!-- see <drake:ball_constraint> and ${{x}} -->\n<link name=\"world\"/><link name=\"a\"/>{J}</robot>");
    let l = load_str(&text, "t.urdf", &ImportOptions::default()).unwrap();
    assert!(l.warnings.is_empty(), "{:?}", l.warnings);
    let e = load_str(&text.replace("<link name=\"a\"/>", "<link name=\"a\"><visual><geometry><box size=\"${s} 1 1\"/></geometry></visual></link>"), "t.urdf", &ImportOptions::default());
    assert!(e.unwrap_err().to_string().contains("xacro"));
}

/// Inside the `mech:` namespace the importer is strict: unknown names are errors with a
/// suggestion, booleans are `true|false|1|0`, limits are ordered.
#[test]
fn mech_namespace_is_strict() {
    let cases: Vec<(String, &str, &str)> = vec![
        (with(&format!("{J}\n<mech:joint_spring joint=\"j\" stiffness=\"1\" refrence=\"0.2\"/>")), "bad.urdf:5:", "<mech:joint_spring> has no attribute `refrence`: did you mean `reference`?"),
        (with(&format!("{J}\n<mech:sprng name=\"s\"/>")), "bad.urdf:5:", "unknown element <mech:sprng>: did you mean `spring`?"),
        (with(&format!("{J}\n<mech:spring name=\"s\" stiffness=\"1\" free_length=\"1\">\n<end link=\"a\"/><ends link=\"world\"/></mech:spring>")), "bad.urdf:6:", "has no child element <ends>: did you mean `end`?"),
        (with(&format!("{J}\n<mech:spring name=\"s\" stiffness=\"1\" free_length=\"1\">\n<end link=\"a\" xzy=\"0 0 0\"/><end link=\"world\"/></mech:spring>")), "bad.urdf:6:", "<end> of <mech:spring> has no attribute `xzy`: did you mean `xyz`?"),
        (with(&format!("{J}\n<link name=\"b\"><mech:spring name=\"s\"/></link>")), "bad.urdf:5:", "<mech:spring> must be a direct child of <robot>"),
        (with(&J.replace("type=", "mech:kind=\"x\" type=")), "bad.urdf:4:", "the `mech:` namespace defines no attribute `kind`"),
        (with(&format!("{J}\n<mech:link_gravity link=\"a\" enabled=\"False\"/>")), "bad.urdf:5:", "attribute `enabled` = \"False\" is not a boolean (true, false, 1 or 0)"),
        (with(&format!("{J}\n<mech:lock joint=\"j\" valeu=\"1\"/>")), "bad.urdf:5:", "did you mean `value`?"),
    ];
    for (text, at, what) in cases {
        let e = err(&text);
        assert!(e.starts_with(at), "expected position {at} in: {e}");
        assert!(e.contains(what), "expected `{what}` in: {e}");
    }
    // The canonical booleans are accepted.
    for b in ["true", "false", "1", "0"] {
        let t = with(&format!(
            "{J}\n<mech:link_gravity link=\"a\" enabled=\"{b}\"/>"
        ));
        assert!(
            load_str(&t, "t.urdf", &ImportOptions::default()).is_ok(),
            "{b}"
        );
    }
}

/// A `mech` prefix bound to another URI makes its elements foreign: a warning, not an error.
#[test]
fn mech_prefix_bound_elsewhere_is_a_warning() {
    let text = format!("<robot name=\"r\" xmlns:mech=\"http://example.com/mech\">\n<link name=\"world\"/><link name=\"a\"/>{J}\n<mech:gravity xyz=\"0 0 -1\"/></robot>");
    let l = load_str(&text, "t.urdf", &ImportOptions::default()).unwrap();
    assert!(
        l.warnings
            .iter()
            .any(|w| w.starts_with("t.urdf:3:")
                && w.contains("bound to \"http://example.com/mech\"")),
        "{:?}",
        l.warnings
    );
    assert_eq!(
        l.model.gravity().z,
        -9.81,
        "the foreign mech:gravity is ignored"
    );
}

/// Hostile nesting (100,000 levels) is refused with an error, not a stack overflow; the limit
/// is documented as `MAX_DEPTH`.
#[test]
fn deep_nesting_is_refused() {
    let n = 100_000;
    let text = format!(
        "<robot name=\"r\">{}{}</robot>",
        "<a>".repeat(n),
        "</a>".repeat(n)
    );
    let e = err(&text);
    assert!(e.starts_with("bad.urdf:1:"), "{e}");
    assert!(
        e.contains(&format!(
            "nested more than {} levels",
            restpose::urdf::MAX_DEPTH
        )),
        "{e}"
    );
    // Just under the limit parses (and fails later for a URDF reason, not a crash).
    let k = restpose::urdf::MAX_DEPTH - 2;
    let text = format!(
        "<robot name=\"r\"><link name=\"a\"/>{}{}</robot>",
        "<x>".repeat(k),
        "</x>".repeat(k)
    );
    assert!(load_str(&text, "t.urdf", &ImportOptions::default()).is_ok());
}

/// The line and column of an error far into a file: line feeds at every offset of the line
/// table's 32-byte blocks before it (and, in the second file, a non-ASCII comment, read by
/// `roxmltree`, on the error's line: the column counts characters).
#[test]
fn far_errors_name_their_line_and_column() {
    for tail in ["", "<!-- é -->"] {
        let pads: String = (0..300)
            .map(|i| format!("{}<!-- {} -->\n", " ".repeat(i % 41), "p".repeat(i % 67)))
            .collect();
        let text = with(&format!("{J}\n{pads}   {tail}<mech:spinner/>"));
        let at = text.find("<mech:spinner").unwrap();
        let line = text[..at].matches('\n').count() + 1;
        let col = text[..at].rsplit('\n').next().unwrap().chars().count() + 1;
        assert_eq!(line, 305);
        let e = err(&text);
        assert!(
            e.contains(&format!("bad.urdf:{line}:{col}:")),
            "expected line {line}, column {col}: {e}"
        );
    }
}
