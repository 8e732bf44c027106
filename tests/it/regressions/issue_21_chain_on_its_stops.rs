//! Regression (issue 21, item 3: stops met one at a time): a planar chain of six links
//! (0.2 m links of 1 kg, centres of mass at mid-link, hinges about +y) hangs from its base,
//! started horizontal. The first four joints come to rest on their
//! upper stops (0.3 rad), the last two hang freely. The active-set iteration meets the stops
//! one per round (a bent search path that takes several at once was tried on the branch
//! `h/bend` and not adopted: BENCHMARKS.md, "Convergence on the corpus"); the bound below is
//! today's count.
//!
//! The equilibrium is checked against the closed-form energy
//! `V(θ) = g Σ_i m z_i`, `z_i = −Σ_{j<i} L sin φ_j − (L/2) sin φ_i`, `φ_i = Σ_{j≤i} θ_j`:
//! the free joints' torques `∂V/∂θ` vanish (central differences), and each stop holds its
//! joint with the effort `∂V/∂θ ≤ 0` (an upper stop pushes towards lower angles).

use crate::common::model_from;
use approx::assert_abs_diff_eq;
use restpose::{Options, Termination};

const L: f64 = 0.2;
const G: f64 = 9.81;

/// The chain: joints 0–3 with the limit `[−3, 0.3]`, 4 and 5 with `[−3, 3]`.
fn chain() -> restpose::Model {
    let mut text = String::from("<robot name=\"stop_chain\">\n  <link name=\"base\"/>\n");
    for i in 0..6 {
        let parent = if i == 0 {
            "base".to_string()
        } else {
            format!("link{}", i - 1)
        };
        text += &format!(
            r#"  <link name="link{i}"><inertial><origin xyz="0.1 0 0"/><mass value="1"/>
    <inertia ixx="1e-3" ixy="0" ixz="0" iyy="4e-3" iyz="0" izz="4e-3"/></inertial></link>
  <joint name="joint{i}" type="revolute"><parent link="{parent}"/><child link="link{i}"/>
    <origin xyz="{x} 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="{upper}" effort="100" velocity="1"/></joint>
"#,
            x = if i == 0 { 0.0 } else { L },
            upper = if i < 4 { 0.3 } else { 3.0 },
        );
    }
    model_from(&(text + "</robot>"))
}

/// The closed-form potential energy of the chain at the joint angles `theta`.
fn energy(theta: &[f64]) -> f64 {
    let (mut phi, mut z, mut v) = (0.0, 0.0, 0.0);
    for t in theta {
        phi += t;
        v += G * (z - 0.5 * L * f64::sin(phi));
        z -= L * f64::sin(phi);
    }
    v
}

/// `∂V/∂θ_k` by central differences of the closed form.
fn torque(theta: &[f64], k: usize) -> f64 {
    let h = 1e-6;
    let (mut plus, mut minus) = (theta.to_vec(), theta.to_vec());
    plus[k] += h;
    minus[k] -= h;
    (energy(&plus) - energy(&minus)) / (2.0 * h)
}

#[test]
fn a_chain_hangs_onto_four_stops_in_balance() {
    let model = chain();
    let options = Options {
        load_steps: 1,
        ..Default::default()
    };
    let (state, report) = restpose::solve(&model, &options).unwrap();
    assert_eq!(report.termination, Termination::Converged);
    let theta: Vec<f64> = (0..6)
        .map(|i| state.joint(&model, &format!("joint{i}")).unwrap()[0])
        .collect();
    assert_abs_diff_eq!(report.energy.total, energy(&theta), epsilon = 1e-9);
    for k in 0..4 {
        assert_abs_diff_eq!(theta[k], 0.3, epsilon = 1e-9);
        let stop = report
            .active_limits
            .iter()
            .find(|a| a.joint == format!("joint{k}"))
            .unwrap_or_else(|| panic!("joint{k} is not on its stop: {:?}", report.active_limits));
        assert_eq!(stop.bound, "upper");
        let dv = torque(&theta, k);
        assert!(dv < -1.0, "joint{k}: the stop does not hold ({dv})");
        assert_abs_diff_eq!(stop.effort, dv, epsilon = 1e-6 * dv.abs().max(1.0));
    }
    assert_eq!(report.active_limits.len(), 4);
    for k in 4..6 {
        let dv = torque(&theta, k);
        assert!(dv.abs() <= 1e-6, "joint{k}: ∂V/∂θ = {dv}");
    }
    // The last link hangs straight down, the fifth joint turns it there.
    assert_abs_diff_eq!(theta[5], 0.0, epsilon = 1e-7);
    assert_abs_diff_eq!(theta[4], std::f64::consts::FRAC_PI_2 - 1.2, epsilon = 1e-7);
    let rounds = report.history.iter().map(|h| h.round).max().unwrap();
    assert!(rounds <= 5, "{rounds} rounds");
}
