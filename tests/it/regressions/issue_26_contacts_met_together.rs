//! Regression (issues 21 and 26: contacts met one per Newton step): four balls (radius
//! `r = 0.05` m, 1 kg) on vertical sliders hung from the world at heights `h_i = 0.3 + 0.1 i`
//! m above a frictionless ground, each pulled down by a spring of stiffness `k_i = 100 (i + 1)`
//! N/m whose rest would put the ball's centre on the ground. The energy is quadratic, so the
//! Newton step goes straight to the springs' rest below the ground, and the balls reach the
//! ground at four different fractions of it. With the step cut where it first reaches a
//! boundary (`StopSearch::Cut`) they are met one per round; the projected search (module
//! `inequality::hold`) holds each ball on the ground where the step reaches it and meets all
//! four in one step.
//!
//! Closed form, per ball (slider coordinate `s`, centre height `z = h + s`, spring reference
//! `−h`): `V = m g z + ½ k (s + h)²`; at rest `z = r`, `V = m g r + ½ k r²`, and the ground
//! pushes with `∂V/∂s = m g + k r`.

use crate::common::model_from;
use approx::assert_abs_diff_eq;
use restpose::{Options, StopSearch, Termination};

const R: f64 = 0.05;
const G: f64 = 9.81;
const BALLS: usize = 4;

fn height(i: usize) -> f64 {
    0.3 + 0.1 * i as f64
}

fn stiffness(i: usize) -> f64 {
    100.0 * (i + 1) as f64
}

fn balls() -> restpose::Model {
    let mut text = String::from(
        "<robot name=\"balls\" xmlns:mech=\"urn:urdf-mech:1\">\n  <link name=\"world\"/>\n",
    );
    for i in 0..BALLS {
        text += &format!(
            r#"  <link name="ball{i}"><inertial><mass value="1"/>
    <inertia ixx="1e-3" ixy="0" ixz="0" iyy="1e-3" iyz="0" izz="1e-3"/></inertial>
    <collision><geometry><sphere radius="{R}"/></geometry></collision></link>
  <joint name="slider{i}" type="prismatic"><parent link="world"/><child link="ball{i}"/>
    <origin xyz="{x} 0 {h}"/><axis xyz="0 0 1"/>
    <limit lower="-2" upper="2" effort="100" velocity="1"/></joint>
  <mech:joint_spring joint="slider{i}" stiffness="{k}" reference="{reference}"/>
"#,
            x = 0.2 * i as f64,
            h = height(i),
            k = stiffness(i),
            reference = -height(i),
        );
    }
    model_from(&(text + "  <mech:ground/>\n</robot>"))
}

/// Solves with `search` (direct solve), checks the rest against the closed form and returns
/// the iterations and active-set rounds it took.
fn solve_checked(search: StopSearch) -> (usize, usize) {
    let model = balls();
    let options = Options {
        load_steps: 1,
        stop_search: search,
        ..Default::default()
    };
    let (state, report) = restpose::solve(&model, &options).unwrap();
    assert_eq!(report.termination, Termination::Converged, "{search:?}");
    let mut total = 0.0;
    for i in 0..BALLS {
        let s = state.joint(&model, &format!("slider{i}")).unwrap()[0];
        assert_abs_diff_eq!(s, R - height(i), epsilon = 1e-9);
        total += G * R + 0.5 * stiffness(i) * R * R;
        let c = report
            .contacts
            .iter()
            .find(|c| c.link == format!("ball{i}"))
            .unwrap_or_else(|| panic!("{search:?}: ball{i} does not touch"));
        let force = G + stiffness(i) * R;
        assert_abs_diff_eq!(c.normal_force, force, epsilon = 1e-7 * force);
        assert_abs_diff_eq!(c.point_world[2], 0.0, epsilon = 1e-9);
    }
    assert_eq!(report.contacts.len(), BALLS, "{search:?}");
    assert_abs_diff_eq!(report.energy.total, total, epsilon = 1e-9);
    let rounds = report.history.iter().map(|h| h.round).max().unwrap();
    (report.iterations, rounds)
}

#[test]
fn the_projected_search_meets_the_balls_on_the_ground_together() {
    let (cut_iterations, cut_rounds) = solve_checked(StopSearch::Cut);
    let (iterations, rounds) = solve_checked(StopSearch::Projected);
    assert!(cut_rounds >= BALLS, "cut: {cut_rounds} rounds");
    assert!(rounds <= 2, "projected: {rounds} rounds (cut {cut_rounds})");
    assert!(
        iterations < cut_iterations,
        "projected: {iterations} iterations, cut {cut_iterations}"
    );
}
