//! Regression (issue 21, item 1: robots hanging onto many stops): a humanoid hanging from its
//! base starts with a dozen joint limits touching at 0, most of them pulling. The active-set
//! iteration released one stop per round and solved every round to ‖∂V/∂v‖∞ ≤ 1e-8 first:
//! Talos took 86–108 iterations in 19–32 rounds. Now every stop pulling at a stationary point
//! leaves at once the first time (module `inequality::release`), and a round ends early when a
//! stop pulls hard relative to the reduced gradient (MINOS's subspace tolerance).
//!
//! The bars of these tests hang on their own hinges, so the answer is known in closed form: a
//! bar of mass `m` with its centre of mass 1 m from its hinge, `θ` from +x, gravity −y, has
//! `V = m g sin θ`; with the stop at `θ = 0` above it (limit `[−3, 0]`) it hangs at `θ = −π/2`.

use crate::common::model_from;
use approx::assert_abs_diff_eq;
use restpose::{Options, Termination};

const G: f64 = 9.81;

/// `masses.len()` bars on hinges about z, each with the limit `[−3, 0]` and starting at
/// `initial[i]`.
fn bars(masses: &[f64], initial: &[f64]) -> restpose::Model {
    let mut text = String::from(
        r#"<robot name="bars" xmlns:mech="urn:urdf-mech:1">
  <link name="world"/>
  <mech:gravity xyz="0 -9.81 0"/>
"#,
    );
    for (i, (m, q)) in masses.iter().zip(initial).enumerate() {
        text += &format!(
            r#"  <link name="bar{i}"><inertial><origin xyz="1 0 0"/><mass value="{m}"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.6" iyz="0" izz="0.6"/></inertial></link>
  <joint name="pivot{i}" type="revolute"><parent link="world"/><child link="bar{i}"/>
    <origin xyz="0 0 {z}"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="0" effort="100" velocity="1"/></joint>
  <mech:initial joint="pivot{i}" value="{q}"/>
"#,
            z = 0.5 * i as f64
        );
    }
    model_from(&(text + "</robot>"))
}

fn direct() -> Options {
    Options {
        load_steps: 1,
        ..Default::default()
    }
}

/// The rest pose (every bar at −π/2, `V = −g Σ m`, no stop active) and the number of rounds.
fn hangs(model: &restpose::Model, masses: &[f64]) -> (restpose::Report, usize) {
    let (state, report) = restpose::solve(model, &direct()).unwrap();
    assert_eq!(report.termination, Termination::Converged);
    for i in 0..masses.len() {
        let th = state.joint(model, &format!("pivot{i}")).unwrap()[0];
        assert_abs_diff_eq!(th, -std::f64::consts::FRAC_PI_2, epsilon = 1e-9);
    }
    assert_abs_diff_eq!(
        report.energy.total,
        -G * masses.iter().sum::<f64>(),
        epsilon = 1e-9
    );
    assert!(report.active_limits.is_empty());
    let rounds = report.history.iter().map(|h| h.round).max().unwrap();
    (report, rounds)
}

/// Five bars pinned at the start on stops that all pull (different efforts `m g`): the first
/// round is stationary at once (no degree of freedom), all five leave together, and the second
/// round is the last (one per stop, six rounds, before).
#[test]
fn stops_that_all_pull_at_a_stationary_point_leave_together() {
    let masses = [1.0, 1.5, 2.0, 2.5, 3.0];
    let (report, rounds) = hangs(&bars(&masses, &[0.0; 5]), &masses);
    assert_eq!(rounds, 2, "{:?}", report.history);
}

/// One bar swinging freely from 0.5 rad and one pinned on a stop that pulls with `m g`: the
/// first round ends before it is stationary (its last gradient is above the tolerance) because
/// the stop pulls harder than the reduced gradient; the answer is the same.
#[test]
fn a_round_ends_early_when_a_stop_pulls_hard() {
    let masses = [2.0, 2.0];
    let (report, rounds) = hangs(&bars(&masses, &[-0.5, 0.0]), &masses);
    assert!(rounds >= 2);
    let first_round_end = report.history.iter().rfind(|h| h.round == 1).unwrap();
    assert!(
        first_round_end.gradient_norm > 1e-3,
        "the first round was solved to {:e}",
        first_round_end.gradient_norm
    );
}
