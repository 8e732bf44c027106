//! Robots written from published data of real machines, and files as ROS and Drake users
//! write them.
use crate::common::*;
use approx::assert_abs_diff_eq;

/// Drake tags: a four-bar closed by `drake:ball_constraint`, with a `drake:joint` universal and
/// a `drake:linear_spring_damper`. The rest angles agree with an independent minimization of
/// the same mechanism in joint coordinates (Python, when the file was written).
#[test]
fn drake_closed_chain_rests_where_an_independent_minimization_says() {
    let m = robot("drake_closed_chain");
    let (s, r) = solve(&m);
    assert_eq!(r.dof, 1);
    assert!(r.redundant_constraints.is_empty());
    assert_abs_diff_eq!(
        s.joint(&m, "crank_joint").unwrap()[0],
        -0.344564,
        epsilon = 2e-6
    );
    assert_abs_diff_eq!(
        s.joint(&m, "rocker_joint").unwrap()[0],
        0.236069,
        epsilon = 2e-6
    );
    assert_abs_diff_eq!(r.energy.total, -0.509301583, epsilon = 1e-8);
}

/// A ROS-style file: `<gazebo>` joint springs, `<transmission>`, `<safety_controller>`,
/// `<limit>` without velocity, and `package://` meshes found by walking up from the file.
#[test]
fn gazebo_transmission_file_loads_its_springs_and_meshes() {
    let path = format!(
        "{}/robots/gazebo_transmission.urdf",
        env!("CARGO_MANIFEST_DIR")
    );
    let l = restpose::urdf::load_file(&path, &Default::default()).unwrap();
    assert!(l.warnings.is_empty(), "{:?}", l.warnings);
    assert_eq!(l.model.joint_springs().len(), 3);
    let meshes = l
        .model
        .links()
        .iter()
        .flat_map(|k| k.visuals.iter().chain(&k.collisions))
        .filter(|g| {
            matches!(
                &g.shape,
                restpose::geometry::ShapeKind::Mesh { path: Some(_), .. }
            )
        });
    assert!(meshes.count() >= 3);
    let (s, r) = solve(&l.model);
    assert_eq!(
        r.stability.unwrap().verdict,
        restpose::solver::Verdict::Stable
    );
    // The same springs written as mech:joint_spring give the same rest pose (0.3170, 0.3188).
    assert_abs_diff_eq!(
        s.joint(&l.model, "shoulder_joint").unwrap()[0],
        0.3170,
        epsilon = 1e-4
    );
    assert_abs_diff_eq!(
        s.joint(&l.model, "elbow_joint").unwrap()[0],
        0.3188,
        epsilon = 1e-4
    );
}

/// Panda-class arm: the mimic finger follows the driven one.
#[test]
fn panda_mimic_finger_follows() {
    let m = robot("panda_class");
    let (s, r) = solve(&m);
    assert_eq!(r.dof, 8);
    let f1 = s.joint(&m, "panda_finger_joint1").unwrap()[0];
    let f2 = s.joint(&m, "panda_finger_joint2").unwrap()[0];
    assert_abs_diff_eq!(f1, f2, epsilon = 1e-12);
}

/// UR5-class arm: the springs of shoulder and elbow carry the gravity torques, which
/// `verify` computes independently as the efforts needed without those springs.
#[test]
fn ur5_spring_torques_equal_gravity_torques() {
    let m = robot("ur5_class");
    let (s, _) = solve(&m);
    let no_springs = m.without_joint_springs();
    let v = restpose::verify::verify(&no_springs, &s, &Default::default()).unwrap();
    for js in m.joint_springs() {
        let j = m.get_joint(js.joint).unwrap();
        let theta = s.joint(&m, &j.name).unwrap()[0];
        let restpose::model::ForceLaw::Linear { stiffness, .. } = js.law else {
            continue;
        };
        let spring = -stiffness * (theta - js.reference);
        let e = v.imbalance.iter().find(|i| i.joint == j.name).unwrap();
        // Without its spring, the joint must exert what the spring exerted, −k (θ − θ_ref).
        assert_abs_diff_eq!(e.effort, spring, epsilon = 1e-6);
    }
}
