//! Regression (issue 21, item 7: the stability verdict): the PincherX 100 of rtb-data
//! (`px100_inertial.urdf`) hangs from its fixed base with a vertical waist, exactly neutral,
//! and its gripper fingers (a prismatic mimic pair) touch their stops without a force (weak
//! rows, efforts ~10⁻⁹ N of either sign). Main 768466d said `unstable` (and `verify` with it):
//! on the critical cone the reduced Hessian `Ĥ` of the strong rows put the neutral directions
//! at −1.9·10⁻¹⁰ J, beyond the tolerance 10⁻¹⁰, because at a point stationary to
//! `‖∂V/∂v‖ = 2·10⁻⁹` a neutral direction's eigenvalue of `Ĥ` is the gradient times the chart's
//! curvature, of either sign. The verdict is now judged on the Hessian along the search path
//! `Ĥ + C` (the Hessian in the joint coordinates), where both neutral directions are at
//! rounding (10⁻¹⁷).

use restpose::solver::Verdict;
use restpose::Termination;

#[test]
fn a_neutral_waist_beside_weak_finger_stops_is_neutral() {
    let model = crate::common::model_from(include_str!("px100_inertial.urdf"));
    let (state, report) = crate::common::solve_direct(&model);
    assert_eq!(report.termination, Termination::Converged);
    let stability = report.stability.expect("a verdict");
    assert_eq!(stability.verdict, Verdict::Neutral, "{stability:?}");
    let v = restpose::verify::verify(&model, &state, &Default::default()).unwrap();
    assert_eq!(
        v.stability.map(|s| s.verdict),
        Some(Verdict::Neutral),
        "verify disagrees with analyze"
    );

    // Independently: the waist turns the hanging arm about the vertical, the energy the same to
    // rounding over large turns: a neutral direction, so `stable` would be wrong too.
    let v0 = crate::common::energy_moved(&model, &state, "waist", 0.0);
    for delta in [-2.0, -0.5, 0.5, 2.0] {
        let moved = crate::common::energy_moved(&model, &state, "waist", delta);
        assert!(
            (moved - v0).abs() < 1e-14,
            "waist +{delta}: {moved} vs {v0}"
        );
    }
}
