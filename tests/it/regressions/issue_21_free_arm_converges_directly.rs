//! Regression (issue 21, item 3): a UR5 hanging freely (fixed base, no springs, no contact)
//! with `--load-steps 1` stalled for 200 iterations at a reduced gradient of 1e-2 with 360
//! corrector failures. The partition chosen at the start (Cartesian coordinates of the wrist
//! bodies as independent coordinates) lost its hold as the arm swung down: the pivots of `Φ_u`
//! fell to 1e-7 of the largest long before the re-partition threshold (1e-8), the reduced
//! Hessian's eigenvalues spread to 1e12, its floor (1e-8 of the largest) swallowed the
//! physical curvatures (0.7 … 123) and the steps shrank to nothing. Now a partition whose pivot
//! ratio has fallen below a fraction of its value when it was made is compared with a fresh
//! full pivoting at the current point and replaced when that one differs. The arm of
//! `robots/ur5_class.urdf` without its springs (the published UR5's kinematics and masses) has
//! a base pan axis along gravity and wrist axes through their loads: neutral directions that
//! must not stall the solve.

use restpose::urdf::{load_str, ImportOptions};
use restpose::{Options, Termination};

/// `robots/ur5_class.urdf` without its springs and initial values: the bare arm, starting
/// straight out (q = 0) and hanging freely under gravity.
pub(super) fn bare_ur5() -> restpose::Model {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/robots/ur5_class.urdf");
    let text: String = std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .filter(|l| !l.contains("mech:joint_spring") && !l.contains("mech:initial"))
        .collect::<Vec<_>>()
        .join("\n");
    load_str(&text, "ur5_bare.urdf", &ImportOptions::default())
        .unwrap()
        .model
}

#[test]
fn the_bare_ur5_hangs_by_the_direct_solve_in_few_iterations() {
    let model = bare_ur5();
    let (state, report) = crate::common::solve_direct(&model);
    assert_eq!(report.termination, Termination::Converged);
    assert!(
        report.iterations <= 30,
        "{} iterations (was 121 with 294 corrector failures)",
        report.iterations
    );
    assert!(
        report.diagnostics.corrector_failures <= 20,
        "{} corrector failures",
        report.diagnostics.corrector_failures
    );
    // An independent check of the rest pose: feasible, balanced, no lower neighbour.
    crate::common::assert_verified_minimum(&model, &state);
    // The same minimum as the 8-step load ramp reaches (the energy is that of the arm hanging
    // straight down, whatever the neutral base pan and wrist angles).
    let ramped = Options {
        load_steps: 8,
        ..Default::default()
    };
    let (_, r8) = restpose::solve(&model, &ramped).unwrap();
    assert!(r8.converged());
    assert!(
        (report.energy.total - r8.energy.total).abs() < 1e-9,
        "direct {} J, ramped {} J",
        report.energy.total,
        r8.energy.total
    );
}
