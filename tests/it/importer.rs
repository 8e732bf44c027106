//! Foreign extensions, frames, automatic child origins and the joint graph.
use crate::common::*;
use approx::assert_abs_diff_eq;
use restpose::urdf::{load_str, ImportOptions};

fn robot_text(name: &str) -> String {
    std::fs::read_to_string(format!("{}/robots/{name}.urdf", env!("CARGO_MANIFEST_DIR"))).unwrap()
}

fn between<'a>(s: &'a str, a: &str, b: &str) -> &'a str {
    let i = s.find(a).unwrap();
    let j = s[i..].find(b).unwrap() + i + b.len();
    &s[i..j]
}

/// The slider-crank with its pin written as the foreign `<loop_joint>` gives the same rest pose.
#[test]
fn foreign_loop_joint_equals_mech_loop_joint() {
    let text = robot_text("slider_crank");
    let mech = between(&text, "<mech:loop_joint", "</mech:loop_joint>");
    let foreign = r#"<loop_joint name="wrist_pin" type="revolute"><link1 link="rod" xyz="0.3 0 0"/><link2 link="slider" xyz="0 0 0"/><axis xyz="0 0 1"/></loop_joint>"#;
    let m1 = model_from(&text);
    let m2 = model_from(&text.replace(mech, foreign));
    let (s1, r1) = solve(&m1);
    let (s2, r2) = solve(&m2);
    assert_abs_diff_eq!(r1.energy.total, r2.energy.total, epsilon = 1e-12);
    assert_abs_diff_eq!(
        s1.joint(&m1, "slide").unwrap()[0],
        s2.joint(&m2, "slide").unwrap()[0],
        epsilon = 1e-12
    );
}

/// The paper's pendulum with its spring written as `<drake:linear_spring_damper>` and its pivot
/// as a planar `<drake:ball_constraint>`-free model still reaches φ = −1.381577.
#[test]
fn drake_linear_spring_damper_is_a_spring() {
    let text = robot_text("pendulum");
    let spring = between(&text, "<mech:spring", "</mech:spring>");
    let drake = r#"<drake:linear_spring_damper>
        <drake:linear_spring_damper_body_A name="bar"/><drake:linear_spring_damper_p_AP value="2 0 0"/>
        <drake:linear_spring_damper_body_B name="world"/><drake:linear_spring_damper_p_BQ value="-1 -2 0"/>
        <drake:linear_spring_damper_free_length value="2"/><drake:linear_spring_damper_stiffness value="3"/>
        <drake:linear_spring_damper_damping value="0.5"/></drake:linear_spring_damper>"#;
    let text = text.replace(spring, drake);
    let l = load_str(&text, "p.urdf", &ImportOptions::default()).unwrap();
    assert!(
        l.warnings.iter().any(|w| w.contains("drake")),
        "undeclared drake prefix repaired: {:?}",
        l.warnings
    );
    let (s, r) = solve(&l.model);
    assert_abs_diff_eq!(
        s.joint(&l.model, "pivot").unwrap()[0],
        -1.381577,
        epsilon = 1e-6
    );
    assert_abs_diff_eq!(r.energy.total, -18.686957, epsilon = 1e-6);
}

/// `<gazebo reference><springStiffness>` is a joint spring: same rest pose as mech:joint_spring.
#[test]
fn gazebo_spring_stiffness_is_a_joint_spring() {
    let text = restpose::generate::chain(4, true);
    let mut gz = text.clone();
    for i in 0..4 {
        let k = 10.0 * ((4 - i) * (4 - i)) as f64;
        gz = gz.replace(
            &format!("<mech:joint_spring joint=\"joint{i}\" stiffness=\"{k}\" reference=\"0\"/>"),
            &format!("<gazebo reference=\"joint{i}\"><springStiffness>{k}</springStiffness><springReference>0</springReference><implicitSpringDamper>true</implicitSpringDamper></gazebo>"),
        );
    }
    assert_ne!(gz, text);
    let (m1, m2) = (model_from(&text), model_from(&gz));
    let (s1, _) = solve(&m1);
    let (s2, _) = solve(&m2);
    for i in 0..4 {
        let n = format!("joint{i}");
        assert_abs_diff_eq!(
            s1.joint(&m1, &n).unwrap()[0],
            s2.joint(&m2, &n).unwrap()[0],
            epsilon = 1e-12
        );
    }
}

const BALL: &str = r#"<robot name="drake" xmlns:drake="http://drake.mit.edu" xmlns:mech="urn:urdf-mech:1">
  <link name="world"/>
  <link name="bob"><inertial><origin xyz="0 0 -0.5"/><mass value="1"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
  <link name="nut"><inertial><mass value="0.2"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <drake:joint name="ball" type="ball"><parent link="world"/><child link="bob"/><origin xyz="0 0 2"/></drake:joint>
  <drake:joint name="screw" type="screw"><parent link="world"/><child link="nut"/><origin xyz="1 0 0"/><axis xyz="0 0 1"/><drake:screw_thread_pitch value="0.01"/></drake:joint>
  <mech:spring name="side" stiffness="20" free_length="0"><end link="bob" xyz="0 0 -0.5"/><end link="world" xyz="0.3 0 1.5"/></mech:spring>
  <mech:joint_spring joint="screw" stiffness="0.05"/>
</robot>"#;

/// Drake ball and screw joints: the bob hangs where gravity and the side spring balance (by
/// hand), and the nut descends its thread until the twist spring holds it: θ = m g h / k.
#[test]
fn drake_ball_and_screw_joints() {
    let m = model_from(BALL);
    let (s, r) = solve(&m);
    assert_eq!(r.dof, 4);
    assert_verified_minimum(&m, &s);
    // Screw: potential m g h θ/(2π)·… : V = m g (pitch θ) + ½ k θ², pitch = 0.01/(2π) m/rad.
    let pitch = 0.01 / (2.0 * std::f64::consts::PI);
    let theta = s.joint(&m, "screw").unwrap()[0];
    assert_abs_diff_eq!(theta, -0.2 * 9.81 * pitch / 0.05, epsilon = 1e-9);
    let nut = s.link_pose(&m, "nut").unwrap().translation.vector;
    assert_abs_diff_eq!(nut.z, pitch * theta, epsilon = 1e-12);
    // Ball: the bob's centre hangs 0.5 m from the pivot, pulled towards x = 0.3 by the spring.
    let c = s.link_pose(&m, "bob").unwrap() * nalgebra::Point3::new(0.0, 0.0, -0.5);
    let f =
        (nalgebra::Point3::new(0.3, 0.0, 1.5) - c) * 20.0 + nalgebra::Vector3::new(0.0, 0.0, -9.81);
    let r_arm = c - nalgebra::Point3::new(0.0, 0.0, 2.0);
    assert!(
        r_arm.cross(&f).norm() < 1e-8,
        "moment about the ball: {}",
        r_arm.cross(&f).norm()
    );
    assert_eq!(s.joint(&m, "ball").unwrap().len(), 4);
}

/// A `drake:ball_constraint` closing a loop, a `mech:frame` as a spring end, and
/// `<child_origin auto="initial"/>`: the loop starts closed, with no assembly to do.
#[test]
fn ball_constraint_frames_and_auto_child_origin() {
    let text = r#"<robot name="loop" xmlns:drake="http://drake.mit.edu" xmlns:mech="urn:urdf-mech:1">
      <link name="world"/>
      <link name="a"><inertial><origin xyz="0.5 0 0"/><mass value="1"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
      <link name="b"><inertial><origin xyz="0.5 0 0"/><mass value="1"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
      <joint name="ja" type="revolute"><parent link="world"/><child link="a"/><axis xyz="0 1 0"/></joint>
      <joint name="jb" type="revolute"><parent link="world"/><child link="b"/><origin xyz="0 0.4 0"/><axis xyz="0 1 0"/></joint>
      <mech:frame name="a_tip" link="a" xyz="1 0 0"/>
      <mech:loop_joint name="tie" type="spherical"><parent link="a_tip"/><child link="b"/><child_origin auto="initial"/></mech:loop_joint>
      <mech:spring name="s" stiffness="40" free_length="0.2"><end link="a_tip"/><end link="world" xyz="1 0 1"/></mech:spring>
      <mech:initial joint="ja" value="0.2"/><mech:initial joint="jb" value="0.2"/>
    </robot>"#;
    let m = model_from(text);
    let start = restpose::solver::initial_state(&m);
    let b = restpose::verify::balance(&m, &start).unwrap();
    assert!(
        b.constraint_residual < 1e-12,
        "auto child origin closes the loop at the start: {b:?}"
    );
    let (s, r) = solve(&m);
    assert_eq!(r.dof, 1);
    assert_verified_minimum(&m, &s);
    // The spring end is the frame: 1 m along a's x axis.
    let tip = s.link_pose(&m, "a").unwrap() * nalgebra::Point3::new(1.0, 0.0, 0.0);
    let l = (nalgebra::Point3::new(1.0, 0.0, 1.0) - tip).norm();
    assert_abs_diff_eq!(
        r.energy.springs,
        0.5 * 40.0 * (l - 0.2).powi(2),
        epsilon = 1e-9
    );

    let ball = text.replace(
        r#"<mech:loop_joint name="tie" type="spherical"><parent link="a_tip"/><child link="b"/><child_origin auto="initial"/></mech:loop_joint>"#,
        r#"<drake:ball_constraint><drake:ball_constraint_body_A name="a"/><drake:ball_constraint_p_AP value="1 0 0"/><drake:ball_constraint_body_B name="b"/><drake:ball_constraint_p_BQ value="1 -0.4 0"/></drake:ball_constraint>"#,
    );
    let m = model_from(&ball);
    assert!(m
        .joints()
        .iter()
        .any(|j| j.name == "ball_constraint_0" && !j.tree));
    let (s, r) = solve(&m);
    assert_eq!(r.dof, 1);
    assert_verified_minimum(&m, &s);
}

/// A link reached only through a loop element: the importer makes that element a tree edge.
#[test]
fn loop_element_becomes_a_tree_edge_when_needed() {
    let text = r#"<robot name="g" xmlns:mech="urn:urdf-mech:1"><link name="world"/>
      <link name="p"><inertial><origin xyz="0 0 -1"/><mass value="1"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
      <mech:loop_joint name="hinge" type="revolute"><parent link="world"/><child link="p"/><axis xyz="0 1 0"/></mech:loop_joint>
      <mech:joint_spring joint="hinge" stiffness="5" reference="0.5"/></robot>"#;
    let m = model_from(text);
    assert!(m.get_joint(m.joint_id("hinge").unwrap()).unwrap().tree);
    let (s, _) = solve(&m);
    let th = s.joint(&m, "hinge").unwrap()[0];
    // 5 (θ − 0.5) = −m g sin θ · 1 m (a rotation about +y moves the bob towards +x, up).
    assert_abs_diff_eq!(5.0 * (th - 0.5), -9.81 * th.sin(), epsilon = 1e-9);
}

/// A point mass written as an inertia tensor of rounding-level entries of either sign (as
/// icub-models' exporter writes it: `ixz="2.40741e-35"`, `ixx="-5.42101e-20"`) is no invalid
/// inertia, while a tensor negative beyond the mass within a micrometre still is.
#[test]
fn a_point_mass_s_rounding_zeros_are_no_invalid_inertia() {
    let robot = |tensor: &str| {
        format!(
            r#"<robot name="r"><link name="base"/>
      <link name="arm"><inertial><origin xyz="0.5 0 0"/><mass value="1.33687"/><inertia {tensor}/></inertial></link>
      <joint name="j" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 1 0"/></joint></robot>"#
        )
    };
    let invalid = |tensor: &str| {
        load_str(&robot(tensor), "p.urdf", &ImportOptions::default())
            .unwrap()
            .warnings
            .iter()
            .any(|w| w.contains("inertia tensor is not physically valid"))
    };
    assert!(!invalid(
        r#"ixx="0" ixy="0" ixz="2.40741e-35" iyy="0" iyz="0" izz="0""#
    ));
    assert!(!invalid(
        r#"ixx="-5.42101e-20" ixy="0" ixz="0" iyy="-5.42101e-20" iyz="0" izz="0""#
    ));
    assert!(!invalid(
        r#"ixx="2.71051e-20" ixy="-1.69407e-21" ixz="1.35525e-20" iyy="5.42101e-20" iyz="3.38813e-21" izz="1.35525e-20""#
    ));
    // −10⁻⁹ kg m² on a 1.3 kg link: its mass within 30 µm, not a rounding zero.
    assert!(invalid(
        r#"ixx="-1e-9" ixy="0" ixz="0" iyy="0" iyz="0" izz="0""#
    ));
}

/// Massless dummy frames and a long fixed chain cost no coordinates; an invalid inertia is a
/// warning.
#[test]
fn massless_fixed_chains_and_inertia_warning() {
    let mut text = String::from(
        r#"<robot name="flange" xmlns:mech="urn:urdf-mech:1"><link name="base"/>
      <link name="arm"><inertial><origin xyz="0.5 0 0"/><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
      <joint name="j" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 1 0"/></joint>
      <mech:joint_spring joint="j" stiffness="30"/>"#,
    );
    let mut parent = "arm".to_string();
    for k in 0..10 {
        text += &format!(
            r#"<link name="f{k}"/><joint name="fj{k}" type="fixed"><parent link="{parent}"/><child link="f{k}"/><origin xyz="0.1 0 0"/></joint>"#
        );
        parent = format!("f{k}");
    }
    text += "</robot>";
    let l = load_str(&text, "f.urdf", &ImportOptions::default()).unwrap();
    assert_eq!(l.model.bodies().len(), 1);
    assert!(
        l.warnings
            .iter()
            .any(|w| w.contains("inertia tensor is not physically valid")),
        "{:?}",
        l.warnings
    );
    let (s, r) = solve(&l.model);
    assert_eq!(r.dof, 1);
    let th = s.joint(&l.model, "j").unwrap()[0];
    let tip = s.link_pose(&l.model, "f9").unwrap().translation.vector;
    assert_abs_diff_eq!(tip.x, 1.0 * th.cos(), epsilon = 1e-12);
    assert_abs_diff_eq!(tip.z, -th.sin(), epsilon = 1e-12);
}

/// `mech:link_gravity enabled="false"` takes a link out of gravity; a `distance` loop joint
/// (massless rod) and a `point_on_line` joint hold their geometry at rest.
#[test]
fn link_gravity_distance_and_point_on_line() {
    let text = r#"<robot name="g" xmlns:mech="urn:urdf-mech:1"><link name="world"/>
      <link name="a"><inertial><origin xyz="1 0 0"/><mass value="1"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
      <link name="b"><inertial><origin xyz="1 0 0"/><mass value="3"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
      <joint name="ja" type="revolute"><parent link="world"/><child link="a"/><axis xyz="0 1 0"/></joint>
      <joint name="jb" type="revolute"><parent link="world"/><child link="b"/><origin xyz="0 0.5 0"/><axis xyz="0 1 0"/></joint>
      <mech:loop_joint name="rod" type="distance" length="0.5"><parent link="a"/><origin xyz="1 0 0"/><child link="b"/><child_origin xyz="1 0 0"/></mech:loop_joint>
      <mech:joint_spring joint="ja" stiffness="30"/>
      <mech:link_gravity link="b" enabled="false"/></robot>"#;
    let m = model_from(text);
    assert_eq!(
        m.bodies()
            .iter()
            .find(|b| b.name == "b")
            .unwrap()
            .gravity_mass,
        0.0
    );
    let (s, r) = solve(&m);
    assert_eq!(r.dof, 1);
    assert_verified_minimum(&m, &s);
    let pa = s.link_pose(&m, "a").unwrap() * nalgebra::Point3::new(1.0, 0.0, 0.0);
    let pb = s.link_pose(&m, "b").unwrap() * nalgebra::Point3::new(1.0, 0.0, 0.0);
    assert_abs_diff_eq!((pa - pb).norm(), 0.5, epsilon = 1e-10);
    // Only a's 1 kg feels gravity: the rod is parallel to y, carrying no moment about y, and
    // 30 θ = 9.81 cos θ.
    let th = s.joint(&m, "ja").unwrap()[0];
    assert_abs_diff_eq!(30.0 * th, 9.81 * th.cos(), epsilon = 1e-8);

    let pol = text.replace(
        r#"<mech:loop_joint name="rod" type="distance" length="0.5"><parent link="a"/><origin xyz="1 0 0"/><child link="b"/><child_origin xyz="1 0 0"/></mech:loop_joint>"#,
        r#"<mech:loop_joint name="rail" type="point_on_line"><parent link="a"/><origin xyz="1 0 0"/><child link="b"/><child_origin xyz="1 0 0"/><axis xyz="0 1 0"/></mech:loop_joint>"#,
    );
    let m = model_from(&pol);
    let (s, _) = solve(&m);
    assert_verified_minimum(&m, &s);
    let pa = s.link_pose(&m, "a").unwrap() * nalgebra::Point3::new(1.0, 0.0, 0.0);
    let pb = s.link_pose(&m, "b").unwrap() * nalgebra::Point3::new(1.0, 0.0, 0.0);
    assert_abs_diff_eq!((pa - pb).x, 0.0, epsilon = 1e-10);
    assert_abs_diff_eq!((pa - pb).z, 0.0, epsilon = 1e-10);
}

/// A pendulum about y (mass 1 kg at x = 0.5 m, torsion spring 10 N m/rad) hung from `mount`,
/// which a fixed joint written by `fixed` welds to the world; `extra` goes before `</robot>`.
fn pendulum(fixed: &str, extra: &str) -> String {
    format!(
        r#"<robot name="p">
<link name="world"/>
<link name="mount"/>
<link name="arm"><inertial><origin xyz="0.5 0 0"/><mass value="1"/><inertia ixx="1e-3" ixy="0" ixz="0" iyy="1e-3" iyz="0" izz="1e-3"/></inertial></link>
{fixed}
<joint name="hinge" type="revolute"><parent link="mount"/><child link="arm"/><axis xyz="0 1 0"/></joint>
<gazebo reference="hinge"><springStiffness>10</springStiffness></gazebo>
{extra}
</robot>"#
    )
}

const FIXED: &str =
    r#"<joint name="weld" type="fixed"><parent link="world"/><child link="mount"/></joint>"#;

/// The closed form of [`pendulum`]: V = k θ²/2 − m g L sin θ, so k θ = m g L cos θ.
fn pendulum_angle() -> f64 {
    let (k, mgl) = (10.0, 9.81 * 0.5);
    let mut t: f64 = 0.0;
    for _ in 0..50 {
        t -= (k * t - mgl * t.cos()) / (k + mgl * t.sin());
    }
    t
}

/// urdfdom does not read the axis of fixed, floating (and restpose's spherical) joints: CAD
/// exporters write `0 0 0` there. It is ignored with a located warning, and the rest pose is
/// the closed form; a zero axis on a revolute joint stays an error.
#[test]
fn zero_axis_on_fixed_joint_is_ignored() {
    let fixed = FIXED.replace("</joint>", "<axis xyz=\"0 0 0\"/></joint>");
    let l = load_str(&pendulum(&fixed, ""), "t.urdf", &ImportOptions::default()).unwrap();
    assert!(
        l.warnings
            .iter()
            .any(|w| w.starts_with("t.urdf:5:") && w.contains("axis") && w.contains("ignored")),
        "{:?}",
        l.warnings
    );
    assert_eq!(l.model.bodies().len(), 1, "mount is welded to the world");
    let (s, _) = solve(&l.model);
    assert_abs_diff_eq!(
        s.joint(&l.model, "hinge").unwrap()[0],
        pendulum_angle(),
        epsilon = 1e-8
    );
    // A nonzero axis on a fixed joint is just as meaningless, but harmless: no warning.
    let fixed = FIXED.replace("</joint>", "<axis xyz=\"1 0 0\"/></joint>");
    let l = load_str(&pendulum(&fixed, ""), "t.urdf", &ImportOptions::default()).unwrap();
    assert!(l.warnings.is_empty(), "{:?}", l.warnings);
    let bad = pendulum(FIXED, "").replace("<axis xyz=\"0 1 0\"/>", "<axis xyz=\"0 0 0\"/>");
    let e = load_str(&bad, "t.urdf", &ImportOptions::default()).unwrap_err();
    assert!(e.to_string().contains("zero-length axis"), "{e}");
}

/// `<mimic>` in a fixed joint (Talos grippers) is ignored with a warning.
#[test]
fn mimic_in_fixed_joint_is_ignored() {
    let fixed = FIXED.replace(
        "</joint>",
        "<mimic joint=\"hinge\" multiplier=\"2\"/></joint>",
    );
    let l = load_str(&pendulum(&fixed, ""), "t.urdf", &ImportOptions::default()).unwrap();
    assert!(l.model.mimics().is_empty());
    assert!(
        l.warnings.iter().any(|w| w.starts_with("t.urdf:5:")
            && w.contains("`weld` (fixed) has no scalar coordinate; <mimic> ignored")),
        "{:?}",
        l.warnings
    );
}

/// `<mimic joint="X">` naming a joint that does not exist (Psyonic hands): the joint is
/// independent, with a warning naming file and line; it solves as the plain pendulum.
#[test]
fn mimic_of_missing_joint_leaves_the_joint_independent() {
    let text = pendulum(FIXED, "").replace(
        "<axis xyz=\"0 1 0\"/></joint>",
        "<axis xyz=\"0 1 0\"/>\n<mimic joint=\"ghost\"/></joint>",
    );
    let l = load_str(&text, "t.urdf", &ImportOptions::default()).unwrap();
    assert!(l.model.mimics().is_empty());
    assert!(
        l.warnings
            .iter()
            .any(|w| w.starts_with("t.urdf:7:") && w.contains("mimics an unknown joint `ghost`")),
        "{:?}",
        l.warnings
    );
    let (s, _) = solve(&l.model);
    assert_abs_diff_eq!(
        s.joint(&l.model, "hinge").unwrap()[0],
        pendulum_angle(),
        epsilon = 1e-8
    );
}

/// An XML declaration after leading whitespace or a comment (TinyXML2 accepts it) is read;
/// line numbers in later messages are still those of the file.
#[test]
fn late_xml_declaration_is_accepted() {
    let text = format!(
        "\n  <!-- exported -->\n<?xml version=\"1.0\" encoding=\"utf-8\"?>\n{}",
        pendulum(FIXED, "")
    );
    let l = load_str(&text, "t.urdf", &ImportOptions::default()).unwrap();
    assert!(
        l.warnings
            .iter()
            .any(|w| w.contains("XML declaration is not at the start")),
        "{:?}",
        l.warnings
    );
    assert_eq!(l.model.bodies().len(), 1);
    let bad = text.replace("<mass value=\"1\"/>", "<mass value=\"-1\"/>");
    let e = load_str(&bad, "t.urdf", &ImportOptions::default()).unwrap_err();
    assert!(e.to_string().starts_with("t.urdf:7:"), "{e}");
}

/// A file declaring `encoding="ISO-8859-1"` is decoded as Latin-1 (é is byte 0xE9).
#[test]
fn latin1_file_is_decoded() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("latin.urdf");
    let mut bytes =
        b"<?xml version=\"1.0\" encoding=\"ISO-8859-1\"?>\n<!-- \xE9paule -->\n".to_vec();
    bytes.extend(
        pendulum(FIXED, "")
            .replace("\"arm\"", "\"bras_\u{e9}\"")
            .chars()
            .map(|c| c as u8),
    );
    std::fs::write(&file, &bytes).unwrap();
    let l = restpose::urdf::load_file(&file, &ImportOptions::default()).unwrap();
    assert!(l.model.link("bras_\u{e9}").is_some());
    // Without the declaration the same bytes are not UTF-8: a located error.
    std::fs::write(
        &file,
        &bytes[bytes.iter().position(|&b| b == b'\n').unwrap() + 1..],
    )
    .unwrap();
    let e = restpose::urdf::load_file(&file, &ImportOptions::default()).unwrap_err();
    assert!(
        e.to_string().contains("latin.urdf:1:6:") && e.to_string().contains("0xE9"),
        "{e}"
    );
}

/// Mesh `scale` with extra components: the first three are used, with a warning; one
/// component is a uniform scale.
#[test]
fn mesh_scale_with_extra_components() {
    let visual = |scale: &str| {
        format!(
            "<link name=\"tool\"><visual><geometry><mesh filename=\"m.stl\" scale=\"{scale}\"/></geometry></visual></link>\n<joint name=\"t\" type=\"fixed\"><parent link=\"arm\"/><child link=\"tool\"/></joint>"
        )
    };
    let scale_of = |scale: &str| {
        let l = load_str(
            &pendulum(FIXED, &visual(scale)),
            "t.urdf",
            &ImportOptions::default(),
        )
        .unwrap();
        let g = &l.model.link("tool").unwrap().visuals[0];
        let restpose::geometry::ShapeKind::Mesh { scale, .. } = &g.shape else {
            panic!("not a mesh")
        };
        (*scale, l.warnings)
    };
    let (s, w) = scale_of("0.001 0.002 0.003 1");
    assert_eq!((s.x, s.y, s.z), (0.001, 0.002, 0.003));
    assert!(
        w.iter()
            .any(|w| w.starts_with("t.urdf:8:") && w.contains("more than 3 components")),
        "{w:?}"
    );
    let (s, w) = scale_of("0.5");
    assert_eq!((s.x, s.y, s.z), (0.5, 0.5, 0.5));
    assert!(w.iter().any(|w| w.contains("uniform")), "{w:?}");
    let e = load_str(
        &pendulum(FIXED, &visual("1 1")),
        "t.urdf",
        &ImportOptions::default(),
    )
    .unwrap_err();
    assert!(e.to_string().contains("must be 3 finite numbers"), "{e}");
}

/// A namespace prefix used without a declaration in foreign content (old Gazebo sensor
/// blocks): TinyXML2 does not know namespaces, so it is declared with a warning.
#[test]
fn undeclared_foreign_prefix_is_declared() {
    let extra = "<gazebo reference=\"arm\"><sensor:camera name=\"c\"><sensor:fov>1</sensor:fov></sensor:camera></gazebo>";
    let l = load_str(&pendulum(FIXED, extra), "t.urdf", &ImportOptions::default()).unwrap();
    assert!(
        l.warnings
            .iter()
            .any(|w| w.contains("`sensor:` prefix is used but not declared")),
        "{:?}",
        l.warnings
    );
    assert_eq!(l.model.bodies().len(), 1);
}

/// A continuous joint has no position limits (urdfdom and ROS ignore them): a `<limit>` with
/// bounds is ignored with a warning instead of reporting violations.
#[test]
fn continuous_joint_position_limits_are_ignored() {
    let text = pendulum(FIXED, "").replace(
        "type=\"revolute\"><parent link=\"mount\"/><child link=\"arm\"/><axis xyz=\"0 1 0\"/>",
        "type=\"continuous\"><parent link=\"mount\"/><child link=\"arm\"/><axis xyz=\"0 1 0\"/><limit lower=\"-0.1\" upper=\"0.1\" effort=\"1\" velocity=\"1\"/>",
    );
    let l = load_str(&text, "t.urdf", &ImportOptions::default()).unwrap();
    let j = l.model.joint_id("hinge").unwrap();
    assert_eq!(l.model.get_joint(j).unwrap().limits, None);
    assert!(l
        .warnings
        .iter()
        .any(|w| w.contains("continuous joint has no position limits")));
    // Effort and velocity only (the usual form) say nothing.
    let plain = text.replace("lower=\"-0.1\" upper=\"0.1\" ", "");
    assert!(load_str(&plain, "t.urdf", &ImportOptions::default())
        .unwrap()
        .warnings
        .is_empty());
}

/// A lock or initial value naming a joint the model lacks gets a suggestion; the library's
/// message names no command-line flag.
#[test]
fn unknown_joint_in_options_gets_a_suggestion() {
    let opts = ImportOptions {
        locks: vec![("hinj".into(), 0, Some(0.0))],
        ..Default::default()
    };
    let e = load_str(&pendulum(FIXED, ""), "t.urdf", &opts)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("lock `hinj`") && e.contains("did you mean `hinge`?"),
        "{e}"
    );
    assert!(!e.contains("--"), "{e}");
    let opts = ImportOptions {
        initial: vec![("zzzzzz".into(), 0, 1.0)],
        ..Default::default()
    };
    let e = load_str(&pendulum(FIXED, ""), "t.urdf", &opts)
        .unwrap_err()
        .to_string();
    assert!(
        // No close name: no suggestion, and no list (models have thousands of joints).
        e.contains("initial value `zzzzzz`") && !e.contains("did you mean"),
        "{e}"
    );
}
