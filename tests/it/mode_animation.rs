//! Poses along a mode shape (`solver::mode_animation`): what the viewer's `mode` timeline shows.
use crate::common::*;

#[test]
fn poses_along_the_softest_mode_stay_assembled_and_follow_the_mode() {
    let m = robot("slider_crank");
    let (rest, report) = restpose::solve(&m, &Default::default()).unwrap();
    let mode = &report.stability.as_ref().unwrap().modes[0];
    let frames = restpose::solver::mode_animation(&m, &rest, mode, 12, 0.15);
    assert_eq!(
        frames.len(),
        12,
        "every pose along the mode closes its loop"
    );
    // Frame 0 is the rest pose (sin 0 = 0).
    assert!((&frames[0].q - &rest.q).amax() < 1e-9);
    // The joint that moves most in the mode moves by the amplitude at the quarter period
    // (sin(π/2) = 1), to first order in the amplitude, and every pose is closed.
    let (name, d) = mode
        .iter()
        .max_by(|a, b| a.1[0].abs().total_cmp(&b.1[0].abs()))
        .unwrap();
    assert!((d[0].abs() - 1.0).abs() < 1e-12, "modes are scaled to 1");
    let moved = frames[3].joint(&m, name).unwrap()[0] - rest.joint(&m, name).unwrap()[0];
    assert!(
        (moved - 0.15 * d[0]).abs() < 0.15 * 0.15,
        "{name} moved {moved}, expected about {}",
        0.15 * d[0]
    );
    for (k, f) in frames.iter().enumerate() {
        let b = restpose::verify::balance(&m, f).unwrap();
        assert!(
            b.constraint_residual < 1e-9,
            "frame {k}: ‖Φ‖ = {}",
            b.constraint_residual
        );
    }
    // Off the rest pose the mechanism is not balanced: the frames really move.
    let b = restpose::verify::balance(&m, &frames[3]).unwrap();
    assert!(b.projected_gradient > 1e-3, "{}", b.projected_gradient);
}
