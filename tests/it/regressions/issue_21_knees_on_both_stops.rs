//! Regression (issue 21, pybullet_data's minitaur hanging): knees whose `<limit>` has no bounds
//! (urdfdom's reading: `[0, 0]`) touch both of their stops without a force when the shin's
//! centre of mass lies on the knee axis. Each such pair holds its knee both ways
//! (`a · d ≥ 0` and `−a · d ≥ 0`), but with more than ten touching stops the critical-cone
//! enumeration gave up and judged on the strong rows alone, where the knees were free: the
//! minitaur was reported "neutral" with six zero eigenvalues.
//!
//! Here six legs hang from a fixed base: a hip about `y` (thigh 1 kg, centre 0.25 m below the
//! hip), a knee 0.5 m below it with no bounds, a 1 kg shin centred on the knee. Twelve stops
//! touch; the rest is stable, and each hip's curvature is
//! `d²V/dθ² = g (m₁ 0.25 + m₂ 0.5) = 9.81 · 0.75 = 7.3575 N m/rad` (closed form).

use crate::common::model_from;
use restpose::solver::Verdict;
use restpose::Options;

fn legs() -> restpose::Model {
    let mut text = String::from("<robot name=\"six_legs\">\n  <link name=\"base\"/>\n");
    for i in 0..6 {
        text += &format!(
            r#"  <link name="thigh{i}"><inertial><origin xyz="0 0 -0.25"/><mass value="1"/>
    <inertia ixx="1e-3" ixy="0" ixz="0" iyy="1e-3" iyz="0" izz="1e-3"/></inertial></link>
  <joint name="hip{i}" type="revolute"><parent link="base"/><child link="thigh{i}"/>
    <origin xyz="{x} 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-2" upper="2" effort="10" velocity="1"/></joint>
  <link name="shin{i}"><inertial><origin xyz="0 0 0"/><mass value="1"/>
    <inertia ixx="1e-3" ixy="0" ixz="0" iyy="1e-3" iyz="0" izz="1e-3"/></inertial></link>
  <joint name="knee{i}" type="revolute"><parent link="thigh{i}"/><child link="shin{i}"/>
    <origin xyz="0 0 -0.5"/><axis xyz="0 1 0"/><limit effort="10" velocity="1"/></joint>
"#,
            x = 0.3 * i as f64,
        );
    }
    model_from(&(text + "</robot>"))
}

#[test]
fn knees_held_by_both_stops_are_judged_stable() {
    let model = legs();
    let (_, report) = restpose::solve(&model, &Options::default()).unwrap();
    assert!(report.converged(), "{:?}", report.termination);
    let s = report.stability.expect("a verdict");
    assert_eq!(s.verdict, Verdict::Stable, "{s:?}");
    let hip = 9.81 * 0.75;
    assert_eq!(s.eigenvalues.len(), 6, "{:?}", s.eigenvalues);
    for l in &s.eigenvalues {
        assert!((l - hip).abs() < 1e-6 * hip, "{l} vs {hip}");
    }
}
