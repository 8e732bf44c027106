//! Regression (issue 21, item 3, "easy robots converge the hard way"): the dense Newton step
//! used the reduced Hessian `Ĥ` in the partition's Cartesian coordinates while the line search
//! moves along the joints (`step::retraction`). `Ĥ` carries a term proportional to the
//! gradient (the chart's curvature) that the path does not see: the bare UR5 falling from
//! straight out had eigenvalues of −14 … −30 J in `Ĥ` where the Hessian along the path has
//! none below −10⁻⁶, and its capped steps took 14 iterations (iCub, example-robot-data: 155,
//! 97 of them in one active-set round where the near-neutral leg modes' eigenvalues followed
//! the gradient norm). The step now uses `Ĥ + C`, `dᵀC d = ∇fᵀ c(d)` the path's curvature
//! (`step::path_hessian`): 4 iterations here, iCub 59.

use restpose::urdf::{load_str, ImportOptions};
use restpose::{Options, Termination};

#[test]
fn the_bare_ur5_falls_in_four_newton_steps() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/robots/ur5_class.urdf");
    let text: String = std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .filter(|l| !l.contains("mech:joint_spring") && !l.contains("mech:initial"))
        .collect::<Vec<_>>()
        .join("\n");
    let model = load_str(&text, "ur5_bare.urdf", &ImportOptions::default())
        .unwrap()
        .model;
    let direct = Options {
        load_steps: 1,
        ..Default::default()
    };
    let (state, report) = restpose::solve(&model, &direct).unwrap();
    assert_eq!(report.termination, Termination::Converged);
    assert!(
        report.iterations <= 5,
        "{} iterations (14 with the Hessian in the partition's coordinates)",
        report.iterations
    );
    assert_eq!(report.diagnostics.corrector_failures, 0);
    // The arm hangs straight down: the 8-step ramp's energy, and a verified minimum.
    let ramped = Options {
        load_steps: 8,
        ..Default::default()
    };
    let (_, r8) = restpose::solve(&model, &ramped).unwrap();
    assert!(r8.converged());
    assert!(
        (report.energy.total - r8.energy.total).abs() < 1e-9,
        "{} against {}",
        report.energy.total,
        r8.energy.total
    );
    crate::common::assert_verified_minimum(&model, &state);
}
