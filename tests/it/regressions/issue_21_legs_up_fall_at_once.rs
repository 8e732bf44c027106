//! Regression (issue 21, item 3 and "Done when"): robots that start on a maximum of the
//! energy left it far too slowly. pybullet_data's minitaurs hang from the zero pose with eight
//! legs straight up (‖∂V/∂v‖∞ = 1e-8): the dense Newton step moves along a direction of
//! curvature `λ < 0` by `−(vᵀ∇f)/|λ|`, which there doubles the distance to the top per
//! iteration (57–151 iterations, the legs falling one after another, ~27 iterations each);
//! example-robot-data's upright double pendulum took 36. Now, where the path keeps every row
//! and the magnitude step is short, every direction of negative curvature is left by a saddle
//! step at once (`step::escape`): minitaurs 6–8 iterations, the double pendulum 9.
//!
//! Here four legs stand straight up on a fixed base (`legs_up`): two two-link legs with
//! continuous joints about `y` and `x`, one one-link leg whose centre of mass is 1 nm off
//! the vertical (a gradient of 1e-8 J, like the minitaurs'), and one on a revolute joint with
//! stops at −2.5 and 0.3 rad. Main 603a9e6 took 64 iterations and rested the last leg on its
//! near stop (0.3 rad, 1.21 J higher); the escape falls toward the side with room.

use restpose::Termination;

const LEGS_UP: &str = r#"<?xml version="1.0"?>
<robot name="legs_up">
  <link name="base">
    <inertial><origin xyz="0 0 0"/><mass value="5"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="hip_a" type="continuous">
    <parent link="base"/><child link="thigh_a"/><origin xyz="0.2 0 0"/><axis xyz="0 1 0"/>
  </joint>
  <link name="thigh_a">
    <inertial><origin xyz="0 0 0.15"/><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="knee_a" type="continuous">
    <parent link="thigh_a"/><child link="shin_a"/><origin xyz="0 0 0.3"/><axis xyz="0 1 0"/>
  </joint>
  <link name="shin_a">
    <inertial><origin xyz="0 0 0.15"/><mass value="0.5"/><inertia ixx="0.005" iyy="0.005" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="hip_b" type="continuous">
    <parent link="base"/><child link="thigh_b"/><origin xyz="-0.2 0 0"/><axis xyz="1 0 0"/>
  </joint>
  <link name="thigh_b">
    <inertial><origin xyz="0 0 0.125"/><mass value="0.8"/><inertia ixx="0.01" iyy="0.01" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="knee_b" type="continuous">
    <parent link="thigh_b"/><child link="shin_b"/><origin xyz="0 0 0.25"/><axis xyz="1 0 0"/>
  </joint>
  <link name="shin_b">
    <inertial><origin xyz="0 0 0.125"/><mass value="0.4"/><inertia ixx="0.005" iyy="0.005" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="hip_c" type="continuous">
    <parent link="base"/><child link="thigh_c"/><origin xyz="0 0.2 0"/><axis xyz="0 1 0"/>
  </joint>
  <link name="thigh_c">
    <inertial><origin xyz="1e-9 0 0.2"/><mass value="1.2"/><inertia ixx="0.01" iyy="0.01" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="hip_d" type="revolute">
    <parent link="base"/><child link="thigh_d"/><origin xyz="0 -0.2 0"/><axis xyz="1 0 0"/>
    <limit lower="-2.5" upper="0.3" effort="10" velocity="1"/>
  </joint>
  <link name="thigh_d">
    <inertial><origin xyz="0 0 0.1"/><mass value="0.7"/><inertia ixx="0.01" iyy="0.01" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
</robot>"#;

#[test]
fn legs_straight_up_fall_at_once_to_the_lowest_rest() {
    let model = crate::common::model_from(LEGS_UP);
    let (state, report) = crate::common::solve_direct(&model);
    assert_eq!(report.termination, Termination::Converged);
    assert!(
        report.iterations <= 15,
        "{} iterations (64 on main 603a9e6)",
        report.iterations
    );
    // Start: every centre of mass above its joint, Σ m h = 0.935 kg m, so g = V₀ / 0.935.
    let v0 = report.history[0].potential_energy;
    let g = v0 / 0.935;
    assert!((g - 9.81).abs() < 0.01, "g = {g}");
    // Rest in closed form: the three free legs straight down (Σ m h = −0.865 kg m), the
    // fourth on its far stop at −2.5 rad (0.7 kg at 0.1 m: height 0.1 cos 2.5).
    let rest = g * (-0.865 + 0.07 * 2.5f64.cos());
    assert!(
        (report.energy.total - rest).abs() < 1e-9,
        "V = {} J, closed form {rest} J",
        report.energy.total
    );
    let hip_d = state.joint(&model, "hip_d").unwrap()[0];
    assert!((hip_d + 2.5).abs() < 1e-9, "hip_d = {hip_d}");
    // The stop holds: ∂V/∂θ = −m g l sin θ = m g l sin 2.5 > 0 pushes the leg onto it.
    let [stop] = &report.active_limits[..] else {
        panic!("{:?}", report.active_limits)
    };
    assert_eq!(
        (stop.joint.as_str(), stop.bound.as_str()),
        ("hip_d", "lower")
    );
    let dv = g * 0.07 * 2.5f64.sin();
    assert!(
        (stop.effort - dv).abs() < 1e-6,
        "{} against {dv}",
        stop.effort
    );
    // Every other leg straight down is the unique configuration with this energy; the
    // reduced gradient is zero and the Hessian positive definite there.
    assert!(report.diagnostics.gradient_norm <= 1e-8);
    assert_eq!(
        report.stability.as_ref().unwrap().verdict,
        restpose::solver::Verdict::Stable
    );
}
