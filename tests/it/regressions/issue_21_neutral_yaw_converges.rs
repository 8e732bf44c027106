//! Regression (issue 21, item 3): SO-101 (example-robot-data 6.0.0, copied into
//! `robots/so101/`) hanging freely by the direct solve ended at `max_iterations` (200), and
//! did not converge with the automatic load ramp either. Its base yaw (`shoulder_pan`, axis
//! along gravity) is near-neutral: 3.6·10⁻⁶ N m/rad. The partition took Cartesian coordinates
//! of the wrist as independent, in which the yaw is a circle; the line search stepped along
//! straight lines in them, each step stretched the arm radially (the corrector puts the
//! departure from the circle into the stiff joints), and the yaw advanced by about 0.01 rad per
//! iteration, 1.6 rad in 200 iterations, through an energy change of 1.5·10⁻⁶ J. The trial
//! points now move the bodies rigidly along the spanning tree (module `solver::retraction`):
//! every joint turns from `θ` to `θ + α θ̇`, and the yaw is reached in a few Newton steps.

use restpose::Termination;

fn so101() -> restpose::Model {
    crate::common::robot("so101/so101")
}

#[test]
fn so101_hangs_by_the_direct_solve_in_few_iterations() {
    let model = so101();
    let (state, report) = crate::common::solve_direct(&model);
    assert_eq!(report.termination, Termination::Converged);
    assert!(
        report.iterations <= 25,
        "{} iterations (was 200, max_iterations)",
        report.iterations
    );
    assert_eq!(report.diagnostics.corrector_failures, 0);
    // The shoulder lift rests on its upper stop; every other joint is free.
    let on_stop: Vec<&str> = report
        .active_limits
        .iter()
        .map(|a| a.joint.as_str())
        .collect();
    assert_eq!(on_stop, ["shoulder_lift"]);
    assert_eq!(report.active_limits[0].bound, "upper");

    // Independent check in joint space: central differences of the energy over each joint
    // coordinate, the others held, by forward kinematics from the rest's joint values.
    let energy =
        |joint: &str, delta: f64| crate::common::energy_moved(&model, &state, joint, delta);
    let v0 = report.energy.total;
    assert!((energy("shoulder_pan", 0.0) - v0).abs() < 1e-12);
    let h = 1e-4;
    for joint in [
        "shoulder_pan",
        "shoulder_lift",
        "elbow_flex",
        "wrist_flex",
        "wrist_roll",
        "gripper",
    ] {
        let (up, down) = (energy(joint, h), energy(joint, -h));
        let slope = (up - down) / (2.0 * h);
        if joint == "shoulder_lift" {
            // Gravity pushes it into its upper stop: the energy falls as it rises.
            assert!(slope < -0.1, "{joint}: dV/dθ = {slope}");
            assert!(
                (slope - report.active_limits[0].effort).abs() < 1e-6,
                "{joint}: dV/dθ = {slope}, stop effort {}",
                report.active_limits[0].effort
            );
        } else {
            assert!(slope.abs() < 1e-7, "{joint}: dV/dθ = {slope:e}");
            // A minimum along each free joint: no lower neighbour.
            assert!(
                up >= v0 - 1e-12 && down >= v0 - 1e-12,
                "{joint}: {up} / {down} below {v0}"
            );
        }
    }
    // The base yaw is nearly neutral: its curvature is tiny, which is what made the crawl.
    let yaw_curvature =
        (energy("shoulder_pan", 0.1) + energy("shoulder_pan", -0.1) - 2.0 * v0) / 0.01;
    assert!(
        yaw_curvature > 0.0 && yaw_curvature < 1e-4,
        "d²V/dψ² = {yaw_curvature:e} N m/rad"
    );
}
