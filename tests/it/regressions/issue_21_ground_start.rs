//! Regression (issue 21, item 5): `analyze a1.urdf --floating-base --ground` failed with
//! "cannot assemble … RL_foot.contact[595]@floor violated by 4.2e-1 … (check the loop geometry
//! or give mech:initial values …)": the floating base started at the world origin, its feet
//! 0.42 m inside the floor, and the message pointed at loops the robot does not have. Now,
//! with grounds and no base pose given, the mechanism starts translated against gravity so that
//! its lowest contact point touches the ground, and settles from there; an assembly that fails
//! on a contact names the real remedy, the base's start pose (`mech:base`; the CLI adds
//! `--base-xyz`).

use restpose::urdf::{load_file, ImportOptions};
use restpose::Options;

/// The Solo-12 of `robots/solo12/` with its ground moved from z = −0.2389 m (where the feet
/// touch with the base at the origin) to `z`.
fn solo_over(z: f64, base: Option<nalgebra::Isometry3<f64>>) -> restpose::Result<restpose::Model> {
    solo_turned(z, base, None)
}

/// As [`solo_over`], with only the base's orientation given (`--base-rpy` alone).
fn solo_turned(
    z: f64,
    base: Option<nalgebra::Isometry3<f64>>,
    orientation: Option<nalgebra::UnitQuaternion<f64>>,
) -> restpose::Result<restpose::Model> {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/robots/solo12/solo12_ground.urdf"
    );
    let text = std::fs::read_to_string(path).unwrap().replace(
        r#"<mech:ground name="floor" xyz="0 0 -0.238946146991093""#,
        &format!(r#"<mech:ground name="floor" xyz="0 0 {z}""#),
    );
    // Next to a link to the meshes, which the file names relative to itself.
    let dir = tempfile::tempdir().unwrap();
    let meshes = std::path::Path::new(path).parent().unwrap().join("meshes");
    std::os::unix::fs::symlink(meshes, dir.path().join("meshes")).unwrap();
    let file = dir.path().join("solo12_moved_ground.urdf");
    std::fs::write(&file, text).unwrap();
    let options = ImportOptions {
        floating_base: true,
        base_pose: base,
        base_orientation: orientation,
        ..Default::default()
    };
    let loaded = load_file(&file, &options);
    loaded.map(|l| l.model)
}

#[test]
fn with_no_base_pose_the_robot_starts_on_the_ground_and_settles() {
    // The published file: the ground where the feet touch with the base at the origin.
    let reference = solo_over(-0.238946146991093, Some(nalgebra::Isometry3::identity())).unwrap();
    let (s0, r0) = restpose::solve(&reference, &Options::default()).unwrap();
    assert!(r0.converged(), "{:?}", r0.termination);
    // The ground 0.5 m up and no base pose: the same rest pose, 0.7389 m higher.
    let lift = 0.5 + 0.238946146991093;
    let model = solo_over(0.5, None).unwrap();
    let (state, report) = restpose::solve(&model, &Options::default()).unwrap();
    assert!(report.converged(), "{:?}", report.termination);
    assert_eq!(report.contacts.len(), 4);
    let weight: f64 = model.bodies().iter().map(|b| b.gravity_mass).sum::<f64>() * 9.81;
    let total: f64 = report.contacts.iter().map(|c| c.normal_force).sum();
    assert!(
        (total - weight).abs() < 1e-8 * weight,
        "{total} N vs {weight} N"
    );
    for c in &report.contacts {
        assert!((c.point_world[2] - 0.5).abs() < 1e-9, "{:?}", c.point_world);
    }
    let z = |m: &restpose::Model, s: &restpose::State| {
        s.link_pose(m, "base_link").unwrap().translation.z
    };
    assert!(
        (z(&model, &state) - z(&reference, &s0) - lift).abs() < 1e-6,
        "base at {} vs {} + {lift}",
        z(&model, &state),
        z(&reference, &s0)
    );
    assert!(
        (report.energy.total - r0.energy.total - weight * lift).abs() < 1e-6,
        "V = {} vs {} + m g {lift}",
        report.energy.total,
        r0.energy.total
    );
}

#[test]
fn a_base_placed_inside_the_ground_names_base_xyz() {
    // The base given at the origin with the floor 1 m above it: every foot 1.24 m inside.
    let model = solo_over(1.0, Some(nalgebra::Isometry3::identity())).unwrap();
    match restpose::solve(&model, &Options::default()) {
        Err(e) => {
            let text = e.to_string();
            assert!(text.contains("mech:base"), "{text}");
            assert!(!text.contains("loop geometry"), "{text}");
        }
        Ok((_, r)) => {
            // Pushed out together with the joints: then it must have come to rest above.
            assert!(r.converged(), "{:?}", r.termination);
        }
    }
}

/// Regression (pybullet_data's laikago, a y-up file stood with `--base-rpy 1.5708 0 3.1416`):
/// the ground start was skipped when only the base's orientation was given, so the robot started
/// at the world origin with its feet 0.48 m inside the floor ("cannot assemble"). Now the
/// orientation given, the height is found: the Solo-12 turned by a yaw of 0.7 rad stands as the
/// unturned reference does, 0.7389 m higher (energy `+ m g Δz`), its yaw kept; turned upside
/// down (a roll of π) it starts with its lowest contact point (now on its back) on the floor
/// 0.5 m up: the lift follows the turned geometry.
#[test]
fn with_only_the_base_orientation_the_height_is_found() {
    let sticking = Options {
        friction: restpose::model::Friction::Stick,
        ..Options::default()
    };
    let reference = solo_over(-0.238946146991093, Some(nalgebra::Isometry3::identity())).unwrap();
    let (s0, r0) = restpose::solve(&reference, &sticking).unwrap();
    assert!(r0.converged(), "{:?}", r0.termination);
    let lift = 0.5 + 0.238946146991093;
    let yaw = nalgebra::UnitQuaternion::from_euler_angles(0.0, 0.0, 0.7);
    let model = solo_turned(0.5, None, Some(yaw)).unwrap();
    assert!(model.base_pose().is_some());
    let (state, report) = restpose::solve(&model, &sticking).unwrap();
    assert!(report.converged(), "{:?}", report.termination);
    assert_eq!(report.contacts.len(), 4);
    let weight: f64 = model.bodies().iter().map(|b| b.gravity_mass).sum::<f64>() * 9.81;
    assert!(
        (report.energy.total - r0.energy.total - weight * lift).abs() < 1e-6,
        "V = {} vs {} + m g {lift}",
        report.energy.total,
        r0.energy.total
    );
    let base = state.link_pose(&model, "base_link").unwrap();
    let base0 = s0.link_pose(&reference, "base_link").unwrap();
    assert!((base.translation.z - base0.translation.z - lift).abs() < 1e-6);
    // The yaw given is kept: the feet stick (on a frictionless floor yaw is neutral, and where
    // a search leaves a neutral coordinate is not the ground start's to say).
    let (_, _, turned) = base.rotation.euler_angles();
    let (_, _, own) = base0.rotation.euler_angles();
    assert!(
        (turned - 0.7).abs() < 1e-3 && own.abs() < 1e-3,
        "yaw {turned}, {own}"
    );
    // Upside down: the start touches the floor with the highest point of the upright robot.
    let flipped = nalgebra::UnitQuaternion::from_euler_angles(std::f64::consts::PI, 0.0, 0.0);
    let model = solo_turned(0.5, None, Some(flipped)).unwrap();
    let start = restpose::solve(
        &model,
        &Options {
            max_iterations: 0,
            ..Default::default()
        },
    );
    let (state, _) = start.unwrap();
    let lowest = model
        .contact_points()
        .iter()
        .map(|c| (state.body_pose(c.body) * nalgebra::Point3::from(c.point)).z - c.radius)
        .fold(f64::INFINITY, f64::min);
    assert!((lowest - 0.5).abs() < 1e-9, "lowest contact at {lowest}");
}
