//! Regression (issue 21): a balanced point that only the critical cone shows unstable is left.
//! pybullet_data's Spirit 40 hanging from its fixed base stopped with its four lower legs
//! balanced straight up against their knee stops at 0 (touching without force), `converged`
//! with the verdict `unstable` and exit 0: the minimizer leaves saddles whose negative
//! curvature lies in the tangent space of the rows it holds, and this one needs the knee stop
//! let go. Now the cone's direction of negative curvature is followed with the stops it opens
//! released (module `stability::cone`, `leave`), and Spirit 40 hangs its lower legs down
//! (−2.871693 J, stable, 26 iterations). The smallest case: a link balanced straight up on a
//! knee whose lower stop holds it at the top, `V = m g ℓ cos θ`, `θ ∈ [0, 3.5]`, started there.

use restpose::solver::Verdict;
use restpose::{Options, Termination};

const INVERTED: &str = r#"<robot name="inverted"><link name="base"/>
  <link name="arm"><inertial><origin xyz="0 0 0.5"/><mass value="1"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <joint name="knee" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 1 0"/>
    <limit lower="0" upper="3.5" effort="10" velocity="1"/></joint></robot>"#;

#[test]
fn a_link_balanced_on_its_stop_falls_to_hang() {
    let model = crate::common::model_from(INVERTED);
    let direct = Options {
        load_steps: 1,
        ..Default::default()
    };
    let (state, report) = restpose::solve(&model, &direct).unwrap();
    assert_eq!(report.termination, Termination::Converged);
    let theta = state.joint(&model, "knee").unwrap()[0];
    // Closed form: V = m g ℓ cos θ is least at θ = π (inside the range), hanging down.
    assert!((theta - std::f64::consts::PI).abs() < 1e-6, "θ = {theta}");
    let v = report.history.last().unwrap().potential_energy;
    assert!((v + 9.81 * 0.5).abs() < 1e-9, "V = {v}");
    let stability = report.stability.expect("a verdict");
    assert_eq!(stability.verdict, Verdict::Stable, "{stability:?}");

    // Asked to stop at unstable points, it stays on the stop, and says so.
    let allow = Options {
        allow_unstable: true,
        ..direct
    };
    let (state, report) = restpose::solve(&model, &allow).unwrap();
    assert_eq!(report.termination, Termination::Converged);
    assert!(state.joint(&model, "knee").unwrap()[0].abs() < 1e-9);
    assert_eq!(report.stability.map(|s| s.verdict), Some(Verdict::Unstable));
}
