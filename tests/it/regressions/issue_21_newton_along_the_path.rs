//! Regression (issue 21, item 3, "easy robots converge the hard way"): the dense Newton step
//! used the reduced Hessian `Ĥ` in the partition's Cartesian coordinates while the line search
//! moves along the joints (`step::retraction`). `Ĥ` carries a term proportional to the
//! gradient (the chart's curvature) that the path does not see: the bare UR5 falling from
//! straight out had eigenvalues of −14 … −30 J in `Ĥ` where the Hessian along the path has
//! none below −10⁻⁶, and its capped steps took 14 iterations (iCub, example-robot-data: 155,
//! 97 of them in one active-set round where the near-neutral leg modes' eigenvalues followed
//! the gradient norm). The step now uses `Ĥ + C`, `dᵀC d = ∇fᵀ c(d)` the path's curvature
//! (`step::path_hessian`): 4 iterations here, iCub 59.

use restpose::Termination;

/// The same solve as `issue_21_free_arm_converges_directly`, which checks its rest pose
/// (verified minimum, the 8-step ramp's energy); here the count of Newton steps.
#[test]
fn the_bare_ur5_falls_in_four_newton_steps() {
    let model = super::issue_21_free_arm_converges_directly::bare_ur5();
    let (_, report) = crate::common::solve_direct(&model);
    assert_eq!(report.termination, Termination::Converged);
    assert!(
        report.iterations <= 5,
        "{} iterations (14 with the Hessian in the partition's coordinates)",
        report.iterations
    );
    assert_eq!(report.diagnostics.corrector_failures, 0);
}
