//! How a user's project checks rest poses in its own test suite.
//!
//! `cargo run --example rest_pose_test` prints the check for the slider-crank;
//! `cargo test --example rest_pose_test` runs the tests below, as a user's crate would.

use restpose::verify::{verify, Tolerances};

fn main() -> Result<(), restpose::Error> {
    let model = restpose::urdf::load_file("robots/slider_crank.urdf", &Default::default())?.model;
    let (rest, report) = restpose::solve(&model, &Default::default())?;
    println!(
        "converged: {}, V = {:.9} J",
        report.converged(),
        report.energy.total
    );
    let check = verify(&model, &rest, &Tolerances::default())?;
    println!(
        "rest pose verified: {} (stability {:?})",
        check.passed,
        check.stability.map(|s| s.verdict)
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use restpose::verify::pose_state;

    /// The solver's answer is a rest pose, and it is stable.
    #[test]
    fn slider_crank_rests_where_restpose_says() {
        let model = restpose::urdf::load_file("robots/slider_crank.urdf", &Default::default())
            .unwrap()
            .model;
        let (rest, report) = restpose::solve(&model, &Default::default()).unwrap();
        assert!(report.converged());
        let check = verify(&model, &rest, &Tolerances::default()).unwrap();
        assert!(check.passed, "{check:?}");
        assert_eq!(
            check.stability.unwrap().verdict,
            restpose::solver::Verdict::Stable
        );
    }

    /// A "home" keyframe at the rest angle passes (the example of `docs/verify.md`).
    #[test]
    fn home_keyframe_is_a_rest_pose() {
        let model = restpose::urdf::load_file("robots/pendulum.urdf", &Default::default())
            .unwrap()
            .model;
        let home = [("pivot".to_string(), vec![-1.381577080])]
            .into_iter()
            .collect();
        let (state, _) = pose_state(&model, &home).unwrap();
        let tol = Tolerances {
            force: 1e-6,
            constraint: 1e-8,
            ..Default::default()
        };
        let check = verify(&model, &state, &tol).unwrap();
        assert!(check.passed, "largest imbalance: {:?}", check.max_imbalance);
    }

    /// A "home" keyframe that is not a rest pose fails, and names the joint out of balance.
    #[test]
    fn pendulum_home_keyframe_is_not_at_rest() {
        let model = restpose::urdf::load_file("robots/pendulum.urdf", &Default::default())
            .unwrap()
            .model;
        let home = [("pivot".to_string(), vec![0.0])].into_iter().collect();
        let (state, _) = pose_state(&model, &home).unwrap();
        let check = verify(&model, &state, &Tolerances::default()).unwrap();
        assert!(!check.passed);
        let worst = check.max_imbalance.unwrap();
        assert_eq!(worst.joint, "pivot");
        assert!(
            worst.effort.abs() > 1.0,
            "holding the bar level takes newton-metres: {}",
            worst.effort
        );
    }
}
