//! Regression (issue 21, the classical simple humanoid's round 11): several stops that pull
//! with all of them held were released together, and the next Newton step turned one of them
//! straight back into its stop; the guard cut that step at `α = 0` (an iteration that did not
//! move the point) and the stop rejoined in another round. Now a release of several stops is
//! decided by the step (module `inequality::release_trial`): the step with the candidates
//! released is computed first, and a stop it pushes back stays held.
//!
//! A two-link arm (0.2 m links of 1 kg, centres of mass at mid-link, hinges about +y, gravity
//! −z) starts on two upper stops. With `φ` the angle from hanging straight down, the shoulder's
//! stop is at `φ₁ = 1`, the elbow's at `φ₂ = −0.3`, and
//! `V = −g (A cos φ₁ + B cos(φ₁ + φ₂))`, `A = m₁ r₁ + m₂ L₁ = 0.3`, `B = m₂ r₂ = 0.1`.
//! With both held each pulls (`∂V/∂φ₁ > 0`, `∂V/∂φ₂ = g B sin 0.7 > 0`, away from their upper
//! stops); with both free the Newton step from there is `(−1.56, +0.72)`: the elbow goes back
//! into its stop. The rest: the elbow on its stop, `tan φ₁ = B sin 0.3 / (A + B cos 0.3)`.

use crate::common::model_from;
use approx::assert_abs_diff_eq;
use restpose::{Options, Termination};

const G: f64 = 9.81;
const A: f64 = 0.3;
const B: f64 = 0.1;
/// The shoulder's stop and the elbow's, from hanging straight down \[rad\].
const SHOULDER: f64 = 1.0;
const ELBOW: f64 = -0.3;

/// The arm: each joint's zero is its upper stop (limits `[−3, 0]`).
fn arm() -> restpose::Model {
    let inertial = r#"<inertial><origin xyz="0.1 0 0"/><mass value="1"/>
    <inertia ixx="1e-3" ixy="0" ixz="0" iyy="4e-3" iyz="0" izz="4e-3"/></inertial>"#;
    model_from(&format!(
        r#"<robot name="arm">
  <link name="base"/>
  <link name="upper">{inertial}</link>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/>
    <origin rpy="0 {s} 0"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="0" effort="100" velocity="1"/></joint>
  <link name="lower">{inertial}</link>
  <joint name="elbow" type="revolute"><parent link="upper"/><child link="lower"/>
    <origin xyz="0.2 0 0" rpy="0 {ELBOW} 0"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="0" effort="100" velocity="1"/></joint>
</robot>"#,
        s = std::f64::consts::FRAC_PI_2 + SHOULDER,
    ))
}

/// The closed-form energy at the joint values `(θ₁, θ₂)` (`φ = θ + stop`).
fn energy(t: [f64; 2]) -> f64 {
    let (p1, p2) = (t[0] + SHOULDER, t[1] + ELBOW);
    -G * (A * p1.cos() + B * (p1 + p2).cos())
}

/// `∂V/∂θ_k` by central differences of the closed form.
fn torque(t: [f64; 2], k: usize) -> f64 {
    let h = 1e-6;
    let (mut plus, mut minus) = (t, t);
    plus[k] += h;
    minus[k] -= h;
    (energy(plus) - energy(minus)) / (2.0 * h)
}

#[test]
fn a_stop_the_step_pushes_back_is_not_released() {
    // Both pull with both held (the release's candidates).
    for k in 0..2 {
        assert!(torque([0.0, 0.0], k) > 0.1, "joint {k}");
    }
    let model = arm();
    let options = Options {
        load_steps: 1,
        ..Default::default()
    };
    let (state, report) = restpose::solve(&model, &options).unwrap();
    assert_eq!(report.termination, Termination::Converged);
    let t = [
        state.joint(&model, "shoulder").unwrap()[0],
        state.joint(&model, "elbow").unwrap()[0],
    ];
    // The closed-form rest: the elbow on its stop, the shoulder free.
    let phi = (B * (-ELBOW).sin() / (A + B * ELBOW.cos())).atan();
    assert_abs_diff_eq!(t[0], phi - SHOULDER, epsilon = 1e-8);
    assert_abs_diff_eq!(t[1], 0.0, epsilon = 1e-9);
    assert!(torque(t, 0).abs() <= 1e-7, "shoulder: {}", torque(t, 0));
    assert_eq!(report.active_limits.len(), 1);
    let elbow = &report.active_limits[0];
    assert_eq!(
        (elbow.joint.as_str(), elbow.bound.as_str()),
        ("elbow", "upper")
    );
    let dv = torque(t, 1);
    assert!(dv < -0.1, "the elbow's stop does not hold: {dv}");
    assert_abs_diff_eq!(elbow.effort, dv, epsilon = 1e-6);
    assert_abs_diff_eq!(report.energy.total, energy(t), epsilon = 1e-9);
    // The rule observed: one trial step found the elbow pushed back (it is counted), only the
    // shoulder left (the two stops active from the start, then one change: before, both left
    // and the elbow's came back, cut at `α = 0`, in a third round).
    assert_eq!(report.diagnostics.release_trials, 1);
    assert_eq!(report.active_set_changes, 3);
    let rounds = report.history.iter().map(|h| h.round).max().unwrap();
    assert_eq!(rounds, 2, "{:?}", report.history);
}
