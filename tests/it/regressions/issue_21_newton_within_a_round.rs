//! Regression (issue 21, item 3, "easy robots converge the hard way"): example-robot-data's
//! `double_pendulum_continuous.urdf` starts upright, at a maximum (gradient 6e-6 J), and took
//! 38 iterations to hang with `--load-steps 1`. The dense Newton step replaced each
//! eigenvalue of the reduced Hessian by its magnitude, so along a direction of negative
//! curvature it moved by `−(vᵀ∇f)/|λ|`: at a maximum `x → 2x`, the gradient doubling for 16
//! iterations, then again from a saddle. The step now adds a saddle-sized step along the
//! directions of negative curvature of the Hessian along the search path (`step::newton`,
//! `step::path_hessian`). The model below is that file's kinematics and masses (BSD-3,
//! meshes left out); the rest energy is checked against its closed form.

use restpose::urdf::{load_str, ImportOptions};
use restpose::{Options, Termination};

/// `double_pendulum_continuous.urdf` of example-robot-data 6.0.0 (two continuous joints about
/// x, all joints at 0: both links upright).
const DOUBLE_PENDULUM: &str = r#"<robot name="2dof_planar">
  <link name="base_link"><inertial><origin xyz="0.0030299 2.6279E-13 0.02912"/><mass value="0.10159"/>
    <inertia ixx="2.636E-05" ixy="-1.007E-16" ixz="-2.3835E-06" iyy="1.8042E-05" iyz="-4.6617E-09" izz="1.8795E-05"/></inertial></link>
  <link name="link1"><inertial><origin xyz="0.0086107 2.1727E-06 0.036012"/><mass value="0.26703"/>
    <inertia ixx="0.00040827" ixy="1.2675E-09" ixz="1.8738E-05" iyy="0.00038791" iyz="3.5443E-08" izz="3.6421E-05"/></inertial></link>
  <joint name="joint1" type="continuous"><origin xyz="0.0060872 0 0.035"/><parent link="base_link"/>
    <child link="link1"/><axis xyz="1 0 0"/><limit lower="0" upper="0" effort="0" velocity="0"/></joint>
  <link name="link2"><inertial><origin xyz="-0.0050107 1.9371E-10 0.10088"/><mass value="0.33238"/>
    <inertia ixx="0.0011753" ixy="-3.854E-13" ixz="-2.9304E-08" iyy="0.0011666" iyz="-5.2365E-12" izz="1.4553E-05"/></inertial></link>
  <joint name="joint2" type="continuous"><origin xyz="0.023 0 0.1"/><parent link="link1"/>
    <child link="link2"/><axis xyz="1 0 0"/><limit lower="0" upper="0" effort="0" velocity="0"/></joint>
</robot>"#;

/// The hanging energy in closed form: with `z = 0.035 + p_y sin θ₁ + p_z cos θ₁` for a point
/// `p` of link 1 (joint 1 about x), `V = g m·0.035 + A cos(θ₁ − φ₁) + B cos(θ₁ + θ₂ − φ₂)`,
/// `A = g |m₁ c₁ + m₂ o₂|` (the `(y, z)` parts: link 1's centre of mass and joint 2's
/// origin), `B = g m₂ |c₂|`; `θ₁` and `θ₁ + θ₂` are independent, so `V_min = g m·0.035 − A − B`.
fn hanging_energy() -> f64 {
    let g: f64 = 9.81;
    let (m1, m2): (f64, f64) = (0.26703, 0.33238);
    let (c1, o2, c2): ([f64; 2], [f64; 2], [f64; 2]) =
        ([2.1727e-6, 0.036012], [0.0, 0.1], [1.9371e-10, 0.10088]);
    let a = g * (m1 * c1[0] + m2 * o2[0]).hypot(m1 * c1[1] + m2 * o2[1]);
    let b = g * m2 * c2[0].hypot(c2[1]);
    g * (m1 + m2) * 0.035 - a - b
}

#[test]
fn the_upright_double_pendulum_falls_in_few_newton_steps() {
    let model = load_str(
        DOUBLE_PENDULUM,
        "double_pendulum_continuous.urdf",
        &ImportOptions::default(),
    )
    .unwrap()
    .model;
    let direct = Options {
        load_steps: 1,
        ..Default::default()
    };
    let (state, report) = restpose::solve(&model, &direct).unwrap();
    assert_eq!(report.termination, Termination::Converged);
    assert!(
        report.iterations <= 10,
        "{} iterations (38 when negative curvature was stepped along by |λ|)",
        report.iterations
    );
    assert!(report.diagnostics.negative_curvature_steps >= 1);
    let v = report.energy.total;
    assert!(
        (v - hanging_energy()).abs() < 1e-9,
        "V = {v} against {}",
        hanging_energy()
    );
    crate::common::assert_verified_minimum(&model, &state);
}
