//! Regression (issue 21, item 3: neutral directions must not stall the solve): the KUKA LBR
//! iiwa 14 R820 of rtb-data hanging from its zero pose, masses from its collision meshes
//! (`iiwa14_from_geometry.urdf`). Its base yaw `joint_a1` is vertical, so exactly neutral, and
//! once `joint_a6` is near 0 the links beyond `joint_a5` are nearly balanced about its axis: a
//! wrist whose energy is a sinusoid of amplitude ~10⁻⁵ J, the stiff joints following it along a
//! curved valley. Off the valley's floor the wrist's curvature read 10⁻³ instead of 10⁻⁵ (the
//! stiff gradient times the valley's bend), so the Newton step turned it 0.08 rad per iteration
//! from −0.58 to −2.95 rad: 33 iterations in one active-set round, 57 in all on main 4651169.
//! The valley watch (module `solver::valley`) was built for this but never turned on: `Ĥ`
//! mixes the neutral base yaw with the chart's curvature (−10⁻⁴) and `Valley::of` refuses a
//! spectrum with a non-positive eigenvalue. It now reads the Hessian along the path, on which
//! the base yaw is at rounding level, with the neutral directions set aside.

use restpose::Termination;

#[test]
fn a_wrist_balanced_beside_a_neutral_base_yaw_does_not_creep() {
    let model = crate::common::model_from(include_str!("iiwa14_from_geometry.urdf"));
    let (state, report) = crate::common::solve_direct(&model);
    assert_eq!(report.termination, Termination::Converged);
    assert!(
        report.iterations <= 35,
        "{} iterations (main 4651169: 57)",
        report.iterations
    );
    let v = restpose::verify::verify(&model, &state, &Default::default()).unwrap();
    assert!(v.passed, "{v:?}");

    // Independently, in joint coordinates: the rest main reaches after 57 iterations
    // (24.6627617716 J); joint_a2 on its upper stop (2.0942 rad) with the energy falling
    // beyond it, every other joint stationary and at a minimum along itself, joint_a1
    // exactly neutral.
    let values: restpose::state::JointValues = state.joint_values(&model).into_iter().collect();
    let energy =
        |joint: &str, delta: f64| crate::common::energy_moved(&model, &state, joint, delta);
    let v0 = energy("joint_a1", 0.0);
    assert!((v0 - 24.6627617716).abs() < 1e-9, "V = {v0}");
    assert!((values["joint_a2"][0] - 2.0942).abs() < 1e-9);
    let h = 1e-4;
    let pushes = (energy("joint_a2", 0.0) - energy("joint_a2", -h)) / h;
    assert!(pushes < -1.0, "joint_a2: dV/dθ = {pushes:e}");
    for joint in [
        "joint_a1", "joint_a3", "joint_a4", "joint_a5", "joint_a6", "joint_a7",
    ] {
        let (up, down) = (energy(joint, h), energy(joint, -h));
        let slope = (up - down) / (2.0 * h);
        assert!(slope.abs() < 1e-6, "{joint}: dV/dθ = {slope:e}");
        assert!(
            up >= v0 - 1e-12 && down >= v0 - 1e-12,
            "{joint}: {up} / {down} below {v0}"
        );
    }
}

/// The valley read beside a neutral direction acts on every arm hanging from a vertical base
/// yaw, and its corrections (stiff Newton steps after the line search's guard) carried the
/// PincherX 100 of rtb-data past an inactive stop: the iterate's energy fell to −0.12905 J,
/// the next round started on the stop at −0.09798 J, and the solve took 9 iterations instead of
/// main's 7. Such a valley's corrections now cross no inactive inequality: the energy never
/// rises from one iterate to the next, and the rest is main's.
#[test]
fn the_valley_beside_a_neutral_yaw_does_not_cross_a_stop() {
    let model = crate::common::model_from(include_str!("px100_inertial.urdf"));
    let (state, report) = crate::common::solve_direct(&model);
    assert_eq!(report.termination, Termination::Converged);
    assert!(report.iterations <= 7, "{} iterations", report.iterations);
    for w in report.history.windows(2) {
        assert!(
            w[1].potential_energy <= w[0].potential_energy + 1e-12,
            "iteration {}: V rose from {} to {}",
            w[1].iteration,
            w[0].potential_energy,
            w[1].potential_energy
        );
    }
    assert!((report.energy.total + 0.126282767937).abs() < 1e-11);
    let v = restpose::verify::verify(&model, &state, &Default::default()).unwrap();
    assert!(v.passed, "{v:?}");
}
