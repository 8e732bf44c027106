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
