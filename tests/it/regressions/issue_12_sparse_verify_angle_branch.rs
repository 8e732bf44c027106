//! Regression (issue 12, found while merging the sparse `verify` with unwrapped angles): the
//! sparse path of `verify` (models above 40 bodies) evaluated the springs and the lock rows on
//! the default angle branch, so a joint given at 3.5 rad had its spring read at 3.5 − 2π (effort
//! −27.8 N m instead of 35 N m on the last joint here). Here a 60-link chain without gravity
//! has only joint springs `k_i (θ_i − 0)`: the effort to hold joint `i` is exactly
//! `∂V/∂θ_i = k_i θ_i`, zero at every other joint.

use crate::common::builders::chain;
use restpose::verify::{parse_pose, pose_state, verify, Tolerances};

fn chain_without_gravity(n: usize) -> restpose::Model {
    let (mut b, _) = chain(n, false);
    b.set_gravity(nalgebra::Vector3::zeros());
    b.build().unwrap()
}

/// The stiffness of the spring on `joint{i}` of an `n`-link chain: `10 (n − i)²` N m/rad.
fn stiffness(n: usize, joint: &str) -> f64 {
    let i: usize = joint.trim_start_matches("joint").parse().unwrap();
    10.0 * ((n - i) * (n - i)) as f64
}

#[test]
fn sparse_verify_reads_angles_beyond_pi_on_their_branch() {
    let n = 60;
    let m = chain_without_gravity(n);
    for (joint, angle) in [("joint59", 3.5), ("joint30", -3.5), ("joint7", 5.0)] {
        let pose = parse_pose(&format!(r#"{{"{joint}": {angle}}}"#), "pose.json").unwrap();
        let (s, _) = pose_state(&m, &pose).unwrap();
        assert!((s.joint(&m, joint).unwrap()[0] - angle).abs() < 1e-12);
        let v = verify(&m, &s, &Tolerances::default()).unwrap();
        assert!(
            !v.passed,
            "{joint} = {angle}: a sprung joint off its reference is not at rest"
        );
        let k = stiffness(n, joint);
        for i in &v.imbalance {
            let expected = if i.joint == joint { k * angle } else { 0.0 };
            assert!(
                (i.effort - expected).abs() <= 1e-7 * (1.0 + k * angle.abs()),
                "{joint} = {angle}: effort at {} is {}, expected {expected}",
                i.joint,
                i.effort
            );
        }
    }
}
