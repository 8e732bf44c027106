//! Regression: the tree factors never left a folded chart. Main b17dd2c took the tree factors
//! automatically for small open models; on pybullet_data's hanging minitaurs the tree
//! partition takes one Euler parameter of each motor body as independent (`e3 = sin(θ/2)`
//! about the joint's axis at the start), and the legs turn by π, from straight up to straight
//! down, where `sin(θ/2)` has its extremum: the chart folds, `Φ_u` is nearly singular, and the
//! reduced gradient in it stays large (0.46 J at the minimum's energy) or, once the steps are
//! tiny, sits at 2.3e-8 J (tolerance 1e-8 J) with no step, halving or re-partition:
//! `max_iterations`. The dense factors watch their pivots and re-partition; the tree factors
//! told no pivot ratio. Now they do (the smallest pivot of their diagonal blocks over the
//! largest, `tree::phi_u`), and the minimizer's drift test re-partitions the tree path too.
//!
//! Here two legs stand straight up on continuous joints whose axes are horizontal (`z` of a
//! frame turned by π/2 about `x`, like the minitaurs' motors), one of two links: main b17dd2c
//! (and 101d79d) reached the minimum's energy with ‖∂V/∂v‖∞ ≈ 3 J, converged only two
//! iterations later and called the rest neutral.

use restpose::Termination;

const TURNED_LEGS: &str = r#"<?xml version="1.0"?>
<robot name="turned_legs">
  <link name="base">
    <inertial><origin xyz="0 0 0"/><mass value="5"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="motor_a" type="continuous">
    <parent link="base"/><child link="thigh_a"/><origin rpy="1.5707963267948966 0 0" xyz="0.2 0 0"/><axis xyz="0 0 1"/>
  </joint>
  <link name="thigh_a">
    <inertial><origin xyz="1e-9 0.1 0"/><mass value="0.5"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="knee_a" type="continuous">
    <parent link="thigh_a"/><child link="shin_a"/><origin xyz="0 0.2 0.01"/><axis xyz="0 0 1"/>
  </joint>
  <link name="shin_a">
    <inertial><origin xyz="0 0.1 0"/><mass value="0.05"/><inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="motor_b" type="continuous">
    <parent link="base"/><child link="thigh_b"/><origin rpy="1.5707963267948966 0 0" xyz="-0.2 0 0"/><axis xyz="0 0 1"/>
  </joint>
  <link name="thigh_b">
    <inertial><origin xyz="-1e-9 0.1 0"/><mass value="0.5"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
</robot>"#;

#[test]
fn legs_turning_by_pi_on_the_tree_factors_leave_the_folded_chart() {
    let model = crate::common::model_from(TURNED_LEGS);
    let (state, report) = crate::common::solve_direct(&model);
    // The automatic choice for this small open model.
    assert_eq!(report.diagnostics.linear_algebra, "tree");
    assert_eq!(report.termination, Termination::Converged);
    assert!(report.iterations <= 15, "{} iterations", report.iterations);
    // Start: every centre of mass above its joint, Σ m h = 0.5·0.1 + 0.05·0.3 + 0.5·0.1 =
    // 0.115 kg m, so g = V₀ / 0.115; rest in closed form: both legs straight down, −0.115 g.
    let v0 = report.history[0].potential_energy;
    let g = v0 / 0.115;
    assert!((g - 9.81).abs() < 0.01, "g = {g}");
    assert!(
        (report.energy.total + 0.115 * g).abs() < 1e-9,
        "V = {} J, closed form {} J",
        report.energy.total,
        -0.115 * g
    );
    // Straight down: the motors turned by π, the knee straight (angles modulo 2π).
    for (joint, turn) in [
        ("motor_a", std::f64::consts::PI),
        ("motor_b", std::f64::consts::PI),
        ("knee_a", 0.0),
    ] {
        let a = state.joint(&model, joint).unwrap()[0];
        let off = crate::common::angle_distance(a, turn);
        assert!(off < 1e-6, "{joint} at {a} rad");
    }
    let d = &report.diagnostics;
    assert!(
        d.constraint_residual < 1e-10,
        "‖Φ‖∞ = {}",
        d.constraint_residual
    );
    assert!(
        d.gradient_norm <= d.gradient_tolerance,
        "‖∂V/∂v‖∞ = {} J",
        d.gradient_norm
    );
    // The last iterations in a sound chart: the gradient falls with the energy (main b17dd2c
    // showed ‖∂V/∂v‖∞ ≈ 3 J at the minimum's energy).
    let at_rest = report
        .history
        .iter()
        .filter(|h| (h.potential_energy - report.energy.total).abs() < 1e-9)
        .map(|h| h.gradient_norm)
        .fold(0.0f64, f64::max);
    assert!(at_rest < 1e-3, "‖∂V/∂v‖∞ = {at_rest} J at the rest energy");
    assert_eq!(
        report.stability.as_ref().unwrap().verdict,
        restpose::solver::Verdict::Stable
    );
}
