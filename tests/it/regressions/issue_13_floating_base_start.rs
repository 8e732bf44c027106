//! Regression (issue 13, found validating the Solo-12 on the ground): with `--floating-base`
//! the root body has no tree joint, and forward kinematics placed only bodies whose parent was
//! placed, so nothing below a floating base was placed: the start violated every joint of the
//! robot (0.19 m at the Solo-12's hips), and the assembly closed them by moving the base (to
//! 0.21 m and 25° away from the origin), so a sticking foot was not held where it stood. Now a
//! body that is no tree joint's child stays at the origin and places its subtree.

use restpose::urdf::{load_file, ImportOptions};
use restpose::State;

#[test]
fn the_start_of_a_floating_base_robot_is_assembled_with_the_base_at_the_origin() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/robots/solo12/solo12_ground.urdf"
    );
    let opts = ImportOptions {
        floating_base: true,
        ..Default::default()
    };
    let m = load_file(path, &opts).unwrap().model;
    let start = State::initial(&m);
    let b = restpose::verify::balance(&m, &start).unwrap();
    assert!(
        b.constraint_residual < 1e-12,
        "‖Φ‖∞ = {:e} at the start",
        b.constraint_residual
    );
    let base = start.link_pose(&m, "base_link").unwrap();
    assert!(base.translation.vector.norm() < 1e-15);
    assert!(base.rotation.angle() < 1e-15);
    // The initial joint values are those of the file.
    assert!((start.joint(&m, "FL_KFE").unwrap()[0] + 1.6).abs() < 1e-12);
}
