//! Regression (issue 21, the last done-when point: stops met one per iteration): a hand of four
//! two-link fingers (0.2 m links of 1 kg, centres of mass at mid-link, hinges about +y) hangs
//! from a fixed palm, started straight and horizontal. Each knuckle comes to rest on its upper
//! stop (0.1, 0.2, 0.3, 0.4 rad), each middle joint hangs freely. With the step cut where it
//! first reaches a stop (`StopSearch::Cut`, the default), the fall meets the knuckles one per
//! active-set round, one after another; the projected search (`StopSearch::Projected`, module
//! `inequality::bend`) holds each knuckle at its stop while the others move on, and the first
//! step that reaches them meets all four.
//!
//! Both are checked against the closed-form energy of each finger,
//! `V(θ₁, θ₂) = −m g ((L/2) sin θ₁ + L sin θ₁ + (L/2) sin(θ₁ + θ₂))`: the middle joints'
//! torques `∂V/∂θ₂` vanish, and each stop holds its knuckle with the effort `∂V/∂θ₁ < 0`
//! (central differences; an upper stop pushes towards lower angles).

use crate::common::model_from;
use approx::assert_abs_diff_eq;
use restpose::{Options, StopSearch, Termination};

const L: f64 = 0.2;
const G: f64 = 9.81;
const FINGERS: usize = 4;

/// The knuckle stop of finger `i` \[rad\].
fn stop(i: usize) -> f64 {
    0.1 * (i + 1) as f64
}

/// The hand: finger `i` has its knuckle limited to `[−3, stop(i)]`, its middle joint to
/// `[−3, 3]`; with `limits` false every joint is continuous.
fn hand(limits: bool) -> restpose::Model {
    let mut text = String::from("<robot name=\"hand\">\n  <link name=\"palm\"/>\n");
    let inertial = r#"<inertial><origin xyz="0.1 0 0"/><mass value="1"/>
    <inertia ixx="1e-3" ixy="0" ixz="0" iyy="4e-3" iyz="0" izz="4e-3"/></inertial>"#;
    for i in 0..FINGERS {
        text += &format!(
            r#"  <link name="proximal{i}">{inertial}</link>
  <joint name="knuckle{i}" type="revolute"><parent link="palm"/><child link="proximal{i}"/>
    <origin xyz="0 {y} 0"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="{upper}" effort="100" velocity="1"/></joint>
  <link name="distal{i}">{inertial}</link>
  <joint name="middle{i}" type="revolute"><parent link="proximal{i}"/><child link="distal{i}"/>
    <origin xyz="{L} 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="3" effort="100" velocity="1"/></joint>
"#,
            y = 0.1 * i as f64,
            upper = stop(i),
        );
    }
    if !limits {
        text = text.replace("type=\"revolute\"", "type=\"continuous\"");
    }
    model_from(&(text + "</robot>"))
}

/// The closed-form potential energy of one finger at `(θ₁, θ₂)`.
fn energy(t: [f64; 2]) -> f64 {
    -G * (0.5 * L * t[0].sin() + L * t[0].sin() + 0.5 * L * (t[0] + t[1]).sin())
}

/// `∂V/∂θ_k` of one finger by central differences of the closed form.
fn torque(t: [f64; 2], k: usize) -> f64 {
    let h = 1e-6;
    let (mut plus, mut minus) = (t, t);
    plus[k] += h;
    minus[k] -= h;
    (energy(plus) - energy(minus)) / (2.0 * h)
}

/// The direct solve (no load ramp) with `search`.
fn direct(search: StopSearch) -> Options {
    Options {
        load_steps: 1,
        stop_search: search,
        ..Default::default()
    }
}

/// Solves the hand with `search`, checks the rest against the closed form and returns the
/// iterations and active-set rounds it took.
fn solve_checked(search: StopSearch) -> (usize, usize) {
    let model = hand(true);
    let (state, report) = restpose::solve(&model, &direct(search)).unwrap();
    assert_eq!(report.termination, Termination::Converged, "{search:?}");
    let mut total = 0.0;
    for i in 0..FINGERS {
        let t = [
            state.joint(&model, &format!("knuckle{i}")).unwrap()[0],
            state.joint(&model, &format!("middle{i}")).unwrap()[0],
        ];
        total += energy(t);
        assert_abs_diff_eq!(t[0], stop(i), epsilon = 1e-9);
        let limit = report
            .active_limits
            .iter()
            .find(|a| a.joint == format!("knuckle{i}"))
            .unwrap_or_else(|| panic!("{search:?}: knuckle{i} is not on its stop"));
        assert_eq!(limit.bound, "upper");
        let dv = torque(t, 0);
        assert!(
            dv < -1.0,
            "{search:?}: knuckle{i}: the stop does not hold ({dv})"
        );
        assert_abs_diff_eq!(limit.effort, dv, epsilon = 1e-6 * dv.abs());
        let free = torque(t, 1);
        assert!(free.abs() <= 1e-6, "{search:?}: middle{i}: ∂V/∂θ = {free}");
        // The distal link hangs straight down.
        assert_abs_diff_eq!(t[0] + t[1], std::f64::consts::FRAC_PI_2, epsilon = 1e-7);
    }
    assert_eq!(report.active_limits.len(), FINGERS, "{search:?}");
    assert_abs_diff_eq!(report.energy.total, total, epsilon = 1e-9);
    let rounds = report.history.iter().map(|h| h.round).max().unwrap();
    (report.iterations, rounds)
}

#[test]
fn the_projected_search_meets_the_knuckle_stops_together() {
    let (cut_iterations, cut_rounds) = solve_checked(StopSearch::Cut);
    let (iterations, rounds) = solve_checked(StopSearch::Projected);
    // The cut meets the four stops in four rounds after the first; the projected step meets
    // them in one.
    assert!(cut_rounds > FINGERS, "cut: {cut_rounds} rounds");
    assert!(rounds <= 2, "projected: {rounds} rounds (cut {cut_rounds})");
    assert!(
        iterations < cut_iterations,
        "projected: {iterations} iterations, cut {cut_iterations}"
    );
}

/// Without joint stops the projected search is the cut: the same iterates to the last bit.
#[test]
fn without_stops_the_projected_search_changes_nothing() {
    let model = hand(false);
    let run = |search| {
        let (state, report) = restpose::solve(&model, &direct(search)).unwrap();
        assert_eq!(report.termination, Termination::Converged, "{search:?}");
        let history: Vec<(f64, f64)> = report
            .history
            .iter()
            .map(|h| (h.potential_energy, h.gradient_norm))
            .collect();
        (state.q, history)
    };
    let (q_cut, h_cut) = run(StopSearch::Cut);
    let (q, h) = run(StopSearch::Projected);
    assert!(h_cut.len() > 2, "{h_cut:?}");
    assert_eq!(h, h_cut);
    assert_eq!(q, q_cut);
}
