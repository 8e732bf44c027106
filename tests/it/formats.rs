//! The pose in other tools' terms: MuJoCo's `qpos` and Pinocchio's `q` (order and quaternion
//! conventions), the MuJoCo keyframe and SRDF files, the floating base in every written pose
//! (JSON, YAML, URDF) read back by `verify` and by a second `analyze` (0 iterations), the
//! Bullet/urdfdom limit conventions, and names escaped in the URDF write-back.
//!
//! The tools themselves read these files in `scripts/peers_check.sh` (CI).

use restpose::export::configuration::{configuration, values, Convention};
use restpose::state::State;
use restpose::urdf::{load_str, ImportOptions};
use std::collections::HashMap;
use std::process::Command;

/// A floating base with two arms whose `<joint>` element order (`right_s0` first) is not their
/// name order (`left_s0` first), as in Baxter; the right arm has a prismatic joint below it,
/// the left one is continuous; a fixed joint (no entry) on the base.
const TWO_ARMS: &str = r#"<robot name="two_arms">
  <link name="torso"><inertial><mass value="2"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <link name="right"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <link name="right_hand"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <link name="left"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <link name="head"/>
  <joint name="right_s0" type="revolute"><parent link="torso"/><child link="right"/><origin xyz="0 -0.3 0"/><axis xyz="0 0 -1"/><limit lower="-2" upper="2" effort="1" velocity="1"/></joint>
  <joint name="head_fixed" type="fixed"><parent link="torso"/><child link="head"/></joint>
  <joint name="right_e0" type="prismatic"><parent link="right"/><child link="right_hand"/><origin xyz="0.5 0 0"/><axis xyz="1 0 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="left_s0" type="continuous"><parent link="torso"/><child link="left"/><origin xyz="0 0.3 0"/><axis xyz="0 1 0"/></joint>
</robot>"#;

#[test]
fn q_vectors_follow_mujoco_and_pinocchio_orders_and_quaternions() {
    let opts = ImportOptions {
        floating_base: true,
        base_pose: Some(nalgebra::Isometry3::from_parts(
            nalgebra::Translation3::new(1.0, 2.0, 3.0),
            nalgebra::UnitQuaternion::from_euler_angles(0.1, -0.2, 0.3),
        )),
        ..Default::default()
    };
    let model = load_str(TWO_ARMS, "two_arms.urdf", &opts).unwrap().model;
    let values: HashMap<String, Vec<f64>> =
        [("right_s0", 0.4), ("right_e0", 0.25), ("left_s0", -2.5)]
            .into_iter()
            .map(|(n, v)| (n.to_string(), vec![v]))
            .collect();
    let state = State::from_joint_values(&model, &values);
    let base = opts.base_pose.unwrap();
    let (t, r) = (base.translation.vector, base.rotation);
    let mj = values_of(&model, &state, Convention::Mujoco);
    let expect_mj = [t.x, t.y, t.z, r.w, r.i, r.j, r.k, 0.4, 0.25, -2.5];
    let pin = values_of(&model, &state, Convention::Pinocchio);
    let expect_pin = [
        t.x,
        t.y,
        t.z,
        r.i,
        r.j,
        r.k,
        r.w,
        (-2.5f64).cos(),
        (-2.5f64).sin(),
        0.4,
        0.25,
    ];
    assert_close(&mj, &expect_mj);
    assert_close(&pin, &expect_pin);
    // The joints each entry belongs to.
    let names: Vec<Option<String>> = configuration(&model, &state, Convention::Mujoco)
        .unwrap()
        .into_iter()
        .map(|e| e.joint.map(|j| model.get_joint(j).unwrap().name.clone()))
        .collect();
    assert_eq!(names[..7], vec![None; 7][..]);
    assert_eq!(
        names[7..],
        ["right_s0", "right_e0", "left_s0"].map(|s| Some(s.to_string()))[..]
    );
}

fn values_of(model: &restpose::Model, state: &State, c: Convention) -> Vec<f64> {
    values(&configuration(model, state, c).unwrap())
}

fn assert_close(a: &[f64], b: &[f64]) {
    assert_eq!(a.len(), b.len(), "{a:?} vs {b:?}");
    for (x, y) in a.iter().zip(b) {
        // The quaternion may come back with the other sign: compare the rotation elsewhere.
        assert!((x - y).abs() < 1e-12, "{a:?} vs {b:?}");
    }
}

fn run(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_restpose"))
        .args(args)
        .output()
        .unwrap()
}

fn numbers(s: &str) -> Vec<f64> {
    s.split_whitespace().map(|x| x.parse().unwrap()).collect()
}

/// The value of attribute `name` in the first element `<tag …>` of `xml`.
fn attribute(xml: &str, tag: &str, name: &str) -> String {
    let doc = roxmltree::Document::parse(xml).unwrap();
    let n = doc
        .descendants()
        .find(|n| n.has_tag_name(tag))
        .unwrap_or_else(|| panic!("no <{tag}> in {xml}"));
    n.attribute(name).unwrap().to_string()
}

/// The Solo-12 standing on the ground (floating base, sticking feet): every written pose
/// carries the base, `verify` passes each of them, and `analyze` of the written URDF starts at
/// rest (0 iterations, same link poses). The keyframe holds `q_mujoco` and the SRDF the
/// joints' values and the base as `x y z qx qy qz qw`.
#[test]
fn floating_base_round_trips_through_every_written_pose() {
    let dir = env!("CARGO_MANIFEST_DIR");
    let file = format!("{dir}/robots/solo12/solo12_ground.urdf");
    let tmp = tempfile::tempdir().unwrap();
    let p = |n: &str| tmp.path().join(n).to_str().unwrap().to_string();
    let common = ["--floating-base", "--friction", "stick", "-q"];
    let mut args = vec!["analyze", file.as_str()];
    args.extend(common);
    let (json, yaml, urdf, key, srdf) = (
        p("rest.json"),
        p("rest.yaml"),
        p("rest.urdf"),
        p("rest_key.xml"),
        p("rest.srdf"),
    );
    args.extend([
        "--json",
        &json,
        "--write-joint-states",
        &yaml,
        "--write-urdf",
        &urdf,
        "--write-mujoco-key",
        &key,
        "--write-srdf",
        &srdf,
        "--group",
        "legs",
        "--state",
        "standing",
    ]);
    let a = run(&args);
    assert_eq!(
        a.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&a.stderr)
    );
    let result: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let root = result["links"]["base_link"].clone();
    let pos: Vec<f64> = serde_json::from_value(root["position"].clone()).unwrap();
    let wxyz: Vec<f64> = serde_json::from_value(root["orientation_wxyz"].clone()).unwrap();
    // The base is not where it started (it settled onto its feet).
    let q_mj: Vec<f64> = serde_json::from_value(result["q_mujoco"].clone()).unwrap();
    let q_pin: Vec<f64> = serde_json::from_value(result["q_pinocchio"].clone()).unwrap();
    assert_eq!(q_mj.len(), 7 + 12);
    assert_eq!(q_pin.len(), 7 + 12);
    let sign = if q_mj[3] * wxyz[0] < 0.0 { -1.0 } else { 1.0 };
    for i in 0..3 {
        assert!((q_mj[i] - pos[i]).abs() < 1e-12 && (q_pin[i] - pos[i]).abs() < 1e-12);
    }
    for i in 0..4 {
        assert!((sign * q_mj[3 + i] - wxyz[i]).abs() < 1e-12);
        assert!((sign * q_pin[3 + (i + 3) % 4] - wxyz[i]).abs() < 1e-12);
    }
    // Every joint value, from the JSON's joints, in one of the vectors.
    let joints = result["joints"].as_object().unwrap();
    for (name, j) in joints {
        if let Some(v) = j["position"]
            .as_array()
            .and_then(|a| a.first())
            .and_then(|v| v.as_f64())
        {
            assert!(q_mj[7..].iter().any(|x| (x - v).abs() < 1e-15), "{name}");
        }
    }
    // The keyframe: qpos = q_mujoco; it loads the written URDF (same folder: by name).
    let k = std::fs::read_to_string(&key).unwrap();
    assert_close(&numbers(&attribute(&k, "key", "qpos")), &q_mj);
    assert_eq!(attribute(&k, "model", "file"), "rest.urdf");
    assert!(k.contains("<freejoint"));
    // The SRDF: the virtual joint, the base as x y z qx qy qz qw, each joint's value.
    let s = std::fs::read_to_string(&srdf).unwrap();
    assert_eq!(attribute(&s, "virtual_joint", "child_link"), "base_link");
    assert_eq!(attribute(&s, "group_state", "group"), "legs");
    assert_eq!(attribute(&s, "group_state", "name"), "standing");
    let doc = roxmltree::Document::parse(&s).unwrap();
    let state = doc
        .descendants()
        .find(|n| n.has_tag_name("group_state"))
        .unwrap();
    let mut seen = 0;
    for j in state.children().filter(|n| n.has_tag_name("joint")) {
        let v = numbers(j.attribute("value").unwrap());
        let name = j.attribute("name").unwrap();
        if name == "root_joint" {
            assert_close(&v, &q_pin[..7]);
        } else {
            assert_close(&v, &[joints[name]["position"][0].as_f64().unwrap()]);
        }
        seen += 1;
    }
    assert_eq!(seen, 13);
    // verify passes each written pose: the JSON, the YAML (its `base`), the URDF's mech:base
    // and mech:initial (no --pose: the file's own initial values).
    let mut yaml_text = std::fs::read_to_string(&yaml).unwrap();
    assert!(
        yaml_text.contains("base:\n  link: \"base_link\""),
        "{yaml_text}"
    );
    for pose in [&json, &yaml] {
        let mut v = vec!["verify", file.as_str(), "--pose", pose];
        v.extend(common);
        let out = run(&v);
        assert_eq!(
            out.status.code(),
            Some(0),
            "{pose}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    // Without its base section the YAML does not pass (the base would be at the origin).
    let cut = yaml_text.find("# the floating base").unwrap();
    yaml_text.truncate(cut);
    let no_base = p("no_base.yaml");
    std::fs::write(&no_base, &yaml_text).unwrap();
    let mut v = vec!["verify", file.as_str(), "--pose", &no_base];
    v.extend(common);
    assert_eq!(run(&v).status.code(), Some(4));
    // The written URDF: analyze again starts at rest.
    let again = p("again.json");
    let mut v = vec!["analyze", urdf.as_str(), "--json", &again];
    v.extend(common);
    let out = run(&v);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let second: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&again).unwrap()).unwrap();
    assert_eq!(second["iterations"], 0, "{}", second["history"]);
    for (name, l) in result["links"].as_object().unwrap() {
        let a: Vec<f64> = serde_json::from_value(l["position"].clone()).unwrap();
        let b: Vec<f64> =
            serde_json::from_value(second["links"][name]["position"].clone()).unwrap();
        assert_close(&a, &b);
    }
}

/// pybullet's `lower="1" upper="-1"` (Bullet's "no limit") loads as an unlimited joint with a
/// located warning; `<limit effort velocity/>` without bounds is urdfdom's `[0, 0]`, with a
/// located warning naming the joint.
#[test]
fn bullet_and_urdfdom_limit_conventions() {
    let j = |limit: &str| {
        format!(
            r#"<robot name="r"><link name="base"/><link name="arm"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
<joint name="j" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
{limit}</joint></robot>"#
        )
    };
    let bullet = load_str(
        &j(r#"<limit lower="1" upper="-1" effort="1" velocity="1"/>"#),
        "b.urdf",
        &Default::default(),
    )
    .unwrap();
    assert_eq!(bullet.model.joints()[0].limits, None);
    assert_eq!(bullet.warnings.len(), 1);
    assert!(
        bullet.warnings[0].starts_with("b.urdf:3:1: joint `j`")
            && bullet.warnings[0].contains("unlimited"),
        "{:?}",
        bullet.warnings
    );
    let bare = load_str(
        &j(r#"<limit effort="1" velocity="1"/>"#),
        "u.urdf",
        &Default::default(),
    )
    .unwrap();
    assert_eq!(bare.model.joints()[0].limits, Some([0.0, 0.0]));
    assert!(
        bare.warnings[0].starts_with("u.urdf:3:1: joint `j`")
            && bare.warnings[0].contains("[0, 0]"),
        "{:?}",
        bare.warnings
    );
    let fine = load_str(
        &j(r#"<limit lower="-1" upper="1" effort="1" velocity="1"/>"#),
        "f.urdf",
        &Default::default(),
    )
    .unwrap();
    assert!(fine.warnings.is_empty());
    assert_eq!(fine.model.joints()[0].limits, Some([-1.0, 1.0]));
}

/// Joint names with `&`, `<` and `"` survive the URDF write-back: the written file reads back
/// with the same initial values.
#[test]
fn write_back_escapes_joint_names() {
    let text = r#"<robot name="r"><link name="base"/><link name="arm"><inertial><origin xyz="1 0 0"/><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
<joint name="a&amp;b&lt;&quot;c" type="continuous"><parent link="base"/><child link="arm"/><axis xyz="0 1 0"/></joint></robot>"#;
    let model = load_str(text, "e.urdf", &Default::default()).unwrap().model;
    assert_eq!(model.joints()[0].name, "a&b<\"c");
    let values: HashMap<String, Vec<f64>> = [("a&b<\"c".to_string(), vec![0.7])].into();
    let state = State::from_joint_values(&model, &values);
    let out = restpose::urdf::with_initial_pose(text, "e.urdf", &model, &state).unwrap();
    let again =
        load_str(&out, "out.urdf", &Default::default()).unwrap_or_else(|e| panic!("{e}\n{out}"));
    let s = State::initial(&again.model);
    assert!((s.joint(&again.model, "a&b<\"c").unwrap()[0] - 0.7).abs() < 1e-15);
}
