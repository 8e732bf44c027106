//! Regression (issue 21, "first time right"): the fingers of a hand with a fixed palm are
//! decoupled (the reduced Hessian is block diagonal, one block per finger, up to rounding),
//! but the escape from maxima was decided for the whole step: a finger straight up (on its
//! maximum, slope exactly 0) waited while another finger fell, and a decomposition of the whole
//! Hessian mixed identical fingers within their degenerate eigenspace. The Allegro hands of
//! example-robot-data took 40 iterations (23 active-set rounds). Now the Hessian is decomposed
//! per decoupled block (`stability::blocks`) and a block at rest by itself is escaped while the
//! rest of the step is long (`step::newton`): the Allegro hands take 23.
//!
//! Here a palm holds a thumb starting horizontal (falling through a long step) and three
//! identical one-link fingers straight up, each on a knuckle with stops at −2.5 and 0.3 rad.
//! Main bfeddf8 let the fingers leave the top only once the thumb had come to rest
//! (iteration 4 of 7); now they leave it together in the thumb's first steps.

use restpose::Termination;

const HAND: &str = r#"<?xml version="1.0"?>
<robot name="hand">
  <link name="palm">
    <inertial><origin xyz="0 0 0"/><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="thumb" type="continuous">
    <parent link="palm"/><child link="thumb"/><origin xyz="0.1 0 0"/><axis xyz="0 1 0"/>
  </joint>
  <link name="thumb">
    <inertial><origin xyz="0.1 0 0"/><mass value="0.3"/><inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="finger_a" type="revolute">
    <parent link="palm"/><child link="finger_a"/><origin xyz="-0.05 0 0.02"/><axis xyz="1 0 0"/>
    <limit lower="-2.5" upper="0.3" effort="10" velocity="1"/>
  </joint>
  <link name="finger_a">
    <inertial><origin xyz="0 0 0.04"/><mass value="0.1"/><inertia ixx="0.0001" iyy="0.0001" izz="0.00001" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="finger_b" type="revolute">
    <parent link="palm"/><child link="finger_b"/><origin xyz="0 0 0.02"/><axis xyz="1 0 0"/>
    <limit lower="-2.5" upper="0.3" effort="10" velocity="1"/>
  </joint>
  <link name="finger_b">
    <inertial><origin xyz="0 0 0.04"/><mass value="0.1"/><inertia ixx="0.0001" iyy="0.0001" izz="0.00001" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="finger_c" type="revolute">
    <parent link="palm"/><child link="finger_c"/><origin xyz="0.05 0 0.02"/><axis xyz="1 0 0"/>
    <limit lower="-2.5" upper="0.3" effort="10" velocity="1"/>
  </joint>
  <link name="finger_c">
    <inertial><origin xyz="0 0 0.04"/><mass value="0.1"/><inertia ixx="0.0001" iyy="0.0001" izz="0.00001" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
</robot>"#;

#[test]
fn identical_fingers_leave_their_maximum_together_while_the_thumb_falls() {
    let model = crate::common::model_from(HAND);
    let options = restpose::Options {
        load_steps: 1,
        record_iterates: true,
        ..Default::default()
    };
    let (state, report) = restpose::solve(&model, &options).unwrap();
    assert_eq!(report.termination, Termination::Converged);
    assert!(
        report.iterations <= 6,
        "{} iterations (7 on main bfeddf8)",
        report.iterations
    );
    // The first recorded iterate where a finger has left the top: all three together, by
    // the same angle (identical fingers), within the thumb's fall (main: iteration 4).
    let fingers = ["finger_a", "finger_b", "finger_c"];
    let angle = |s: &restpose::State, j: &str| s.joint(&model, j).unwrap()[0];
    let first = report
        .iterates
        .iter()
        .position(|s| fingers.iter().any(|j| angle(s, j).abs() > 0.1))
        .expect("the fingers never left the top");
    let at = &report.iterates[first];
    let a = angle(at, "finger_a");
    for j in fingers {
        assert!(
            (angle(at, j) - a).abs() < 1e-9 && a.abs() > 0.1,
            "{j} at {} where finger_a is at {a}",
            angle(at, j)
        );
    }
    let iteration = report.history[first].iteration;
    assert!(
        iteration <= 2,
        "the fingers left the top at iteration {iteration}"
    );
    // The thumb was still falling then: the energy fell further after it.
    assert!(report.history[first].potential_energy > report.energy.total + 0.1);
    // Start: the fingers' centres of mass 0.06 m above the palm, the thumb's level with it:
    // V₀ = 0.018 g.
    let g = report.history[0].potential_energy / 0.018;
    assert!((g - 9.81).abs() < 1e-9, "g = {g}");
    // Rest in closed form: the thumb straight down (0.3 kg, 0.1 m below its joint), each
    // finger on its far stop at −2.5 rad (0.1 kg at 0.02 + 0.04 cos 2.5 m).
    let rest = g * (-0.03 + 0.3 * (0.02 + 0.04 * 2.5f64.cos()));
    assert!(
        (report.energy.total - rest).abs() < 1e-9,
        "V = {} J, closed form {rest} J",
        report.energy.total
    );
    for j in fingers {
        assert!(
            (angle(&state, j) + 2.5).abs() < 1e-9,
            "{j} = {}",
            angle(&state, j)
        );
    }
    assert!(report.diagnostics.gradient_norm <= 1e-8);
    assert_eq!(
        report.stability.as_ref().unwrap().verdict,
        restpose::solver::Verdict::Stable
    );
}
