//! Issue 21 (items 1 and 7) and issue 25 (item 6). `verify` fitted the contact forces by least
//! squares over all coordinates, efforts included, instead of balancing the unactuated
//! floating base first: A1 standing held by locks got feet summing to 14 N for a 134.8 N
//! robot (dense) or 6 N (sparse), and holding torques unrelated to analyze's; the sparse path
//! refused poses with loops whose lock rows it could not separate (minitaur, two pendulums
//! joined by a distance rod). The stability eigenvalues were those of the partition's scaled
//! reduced Hessian: 2.1155e2 or 3.0956e2 for the same pendulum rest pose depending on the
//! start, whose `d²V/dθ²` is 31.42 N m/rad; a pendulum on its stop had no verdict.

use crate::common::{model_from, robot, solve};
use approx::assert_abs_diff_eq;
use restpose::model::Lock;
use restpose::state::{JointValues, State};
use restpose::urdf::{load_file, ImportOptions};
use restpose::verify::{verify_reporting, Eigenvalues, Tolerances, Unilaterals};
use restpose::{LinearAlgebra, Model, Options};

fn verify_on(m: &Model, s: &State, la: LinearAlgebra) -> restpose::verify::Verification {
    let tol = Tolerances::default();
    verify_reporting(
        m,
        s,
        &tol,
        &Unilaterals::default(),
        la,
        Eigenvalues::WhenCheap,
    )
    .unwrap()
}

/// The generalized force of joint `name`'s coordinate in `r.reactions`: the reaction torque
/// on the child about the joint's axis (world), for a revolute joint.
fn lock_effort(m: &Model, s: &State, r: &restpose::Report, name: &str) -> f64 {
    let j = m.get_joint(m.joint_id(name).unwrap()).unwrap();
    let child = j.bodies[1].unwrap().index();
    let q = &s.q;
    let p = nalgebra::Vector4::new(
        q[7 * child + 3],
        q[7 * child + 4],
        q[7 * child + 5],
        q[7 * child + 6],
    );
    let axis =
        restpose::math::rotation(&p) * (j.body_from_joint[1].rotation * nalgebra::Vector3::z());
    let t = &r.reactions.iter().find(|(n, _)| n == name).unwrap().1;
    nalgebra::Vector3::from(t.torque_world).dot(&axis)
}

/// Solo-12 standing on the ground with its hips locked away from their rest: `verify --lock`
/// (dense and sparse) gives analyze's holding efforts and foot forces; without the locks the
/// base is still balanced exactly (feet carry the weight, nothing unassigned), dense and sparse
/// give the same efforts and forces, and the pose fails, naming the efforts.
#[test]
fn verify_gives_analyzes_forces_on_a_floating_base() {
    let dir = env!("CARGO_MANIFEST_DIR");
    let opts = ImportOptions {
        floating_base: true,
        ..Default::default()
    };
    let free = load_file(format!("{dir}/robots/solo12/solo12_ground.urdf"), &opts)
        .unwrap()
        .model;
    let (rest, _) = restpose::solve(&free, &Options::default()).unwrap();
    let mut locked = free.clone();
    let values: JointValues = rest.joint_values(&free).into_iter().collect();
    let mut names = Vec::new();
    for j in free
        .joints()
        .iter()
        .filter(|j| j.tree && j.kind.scalar_coordinates() == 1)
    {
        let id = free.joint_id(&j.name).unwrap();
        let shift = if j.name.contains("HFE") { 0.3 } else { 0.0 };
        locked = locked
            .with_lock(Lock {
                joint: id,
                dof: 0,
                value: Some(values[&j.name][0] + shift),
            })
            .unwrap();
        names.push(j.name.clone());
    }
    assert_eq!(names.len(), 12);
    let (s, r) = restpose::solve_from(&locked, rest.clone(), &Options::default()).unwrap();
    assert!(r.converged(), "{:?}", r.termination);
    assert_eq!(r.contacts.len(), 4, "{:?}", r.contacts);
    let weight: f64 = free.bodies().iter().map(|b| b.gravity_mass).sum::<f64>() * 9.81;
    let total: f64 = r.contacts.iter().map(|c| c.normal_force).sum();
    assert_abs_diff_eq!(total, weight, epsilon = 1e-6 * weight);
    let knee = lock_effort(&locked, &s, &r, "FL_HFE");
    assert!(knee.abs() > 0.1, "{knee}");
    for la in [LinearAlgebra::Dense, LinearAlgebra::Sparse] {
        let v = verify_on(&locked, &s, la);
        assert!(v.passed, "{la:?}: {v:?}");
        for n in &names {
            let e = v.imbalance.iter().find(|i| &i.joint == n).unwrap();
            assert!(e.locked);
            assert_abs_diff_eq!(e.effort, lock_effort(&locked, &s, &r, n), epsilon = 1e-7);
        }
        for c in &v.unilateral.contacts {
            let a = r.contacts.iter().find(|a| a.link == c.link).unwrap();
            assert_abs_diff_eq!(c.normal_force, a.normal_force, epsilon = 1e-7);
        }
    }
    // Without the locks: the same pose needs efforts at the knees.
    let d = verify_on(&free, &s, LinearAlgebra::Dense);
    let sp = verify_on(&free, &s, LinearAlgebra::Sparse);
    for v in [&d, &sp] {
        assert!(!v.passed);
        assert!(v.unassigned <= v.effort_tolerance, "{}", v.unassigned);
        let total: f64 = v.unilateral.contacts.iter().map(|c| c.normal_force).sum();
        assert_abs_diff_eq!(total, weight, epsilon = 1e-6 * weight);
        assert!(v.max_imbalance.as_ref().unwrap().effort.abs() > 0.1);
        assert!(v
            .unilateral
            .failures
            .iter()
            .any(|f| f.contains("needs an effort")));
    }
    for (a, b) in d.imbalance.iter().zip(&sp.imbalance) {
        assert_abs_diff_eq!(a.effort, b.effort, epsilon = 1e-8);
    }
    for (a, b) in d.unilateral.contacts.iter().zip(&sp.unilateral.contacts) {
        assert_abs_diff_eq!(a.normal_force, b.normal_force, epsilon = 1e-8);
    }
}

/// Issue 25, item 6: two pendulums joined by a distance rod (the importer test's) pass on both
/// paths with the same efforts.
#[test]
fn two_pendulums_joined_by_a_rod_pass_on_both_paths() {
    let m = model_from(
        r#"<robot name="g" xmlns:mech="urn:urdf-mech:1"><link name="world"/>
      <link name="a"><inertial><origin xyz="1 0 0"/><mass value="1"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
      <link name="b"><inertial><origin xyz="1 0 0"/><mass value="3"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
      <joint name="ja" type="revolute"><parent link="world"/><child link="a"/><axis xyz="0 1 0"/></joint>
      <joint name="jb" type="revolute"><parent link="world"/><child link="b"/><origin xyz="0 0.5 0"/><axis xyz="0 1 0"/></joint>
      <mech:loop_joint name="rod" type="distance" length="0.5"><parent link="a"/><origin xyz="1 0 0"/><child link="b"/><child_origin xyz="1 0 0"/></mech:loop_joint>
      <mech:joint_spring joint="ja" stiffness="30"/>
      <mech:link_gravity link="b" enabled="false"/></robot>"#,
    );
    let (s, _) = solve(&m);
    let d = verify_on(&m, &s, LinearAlgebra::Dense);
    let sp = verify_on(&m, &s, LinearAlgebra::Sparse);
    assert!(d.passed && sp.passed, "{d:?}\n{sp:?}");
    let (ed, es) = (&d.stability.unwrap(), &sp.stability.unwrap());
    assert_abs_diff_eq!(ed.eigenvalues[0], es.eigenvalues[0], epsilon = 1e-8);
}

/// `d²V/dθ²` by central differences of the energy through forward kinematics (the pose from
/// joint values), `h` the step.
fn energy_at(m: &Model, values: &JointValues) -> f64 {
    let (s, _) = restpose::verify::pose_state(m, values).unwrap();
    restpose::verify::potential_energy(m, &s).unwrap()
}

/// The pendulum's reported eigenvalue is `d²V/dθ²` at its rest pose (31.42 N m/rad), the
/// same from every start, in analyze and in verify (dense and sparse).
#[test]
fn pendulum_eigenvalue_is_d2v_dtheta2_from_any_start() {
    let m = robot("pendulum");
    let mut seen = Vec::new();
    for start in [None, Some(3.0), Some(-2.0), Some(1.2)] {
        let s0 = match start {
            None => restpose::solver::initial_state(&m),
            Some(t) => State::from_joint_values(&m, &[("pivot".to_string(), vec![t])].into()),
        };
        let (s, r) = restpose::solve_from(&m, s0, &Options::default()).unwrap();
        assert!(r.converged());
        let th = s.joint(&m, "pivot").unwrap()[0];
        let h = 1e-4;
        let at = |x: f64| energy_at(&m, &[("pivot".to_string(), vec![x])].into());
        let d2 = (at(th + h) - 2.0 * at(th) + at(th - h)) / (h * h);
        let e = r.stability.as_ref().unwrap().eigenvalues[0];
        assert_abs_diff_eq!(e, d2, epsilon = 1e-5 * d2);
        assert_abs_diff_eq!(e, 31.42, epsilon = 0.01);
        assert_abs_diff_eq!(r.stability.unwrap().modes[0]["pivot"][0].abs(), 1.0);
        for la in [LinearAlgebra::Dense, LinearAlgebra::Sparse] {
            let v = verify_on(&m, &s, la);
            assert_abs_diff_eq!(v.stability.unwrap().eigenvalues[0], e, epsilon = 1e-8 * e);
        }
        seen.push(e);
    }
    for e in &seen {
        assert_abs_diff_eq!(*e, seen[0], epsilon = 1e-9 * seen[0]);
    }
}

/// A 20-link spatial chain: the reported eigenvalues are the lowest of the joint-space Hessian
/// `∂²V/∂θ_i∂θ_j`, computed here by central differences of the energy over the 20 joint
/// coordinates.
#[test]
fn chain_eigenvalues_are_those_of_the_joint_space_hessian() {
    let m = robot("chain20");
    let (s, r) = solve(&m);
    let rest: JointValues = s.joint_values(&m).into_iter().collect();
    let names: Vec<String> = (0..20).map(|i| format!("joint{i}")).collect();
    let n = names.len();
    let h = 1e-4;
    let at = |di: Option<(usize, f64)>, dj: Option<(usize, f64)>| {
        let mut v = rest.clone();
        for (k, d) in [di, dj].into_iter().flatten() {
            v.get_mut(&names[k]).unwrap()[0] += d;
        }
        energy_at(&m, &v)
    };
    let mut hess = nalgebra::DMatrix::zeros(n, n);
    for i in 0..n {
        for j in i..n {
            let x = (at(Some((i, h)), Some((j, h)))
                - at(Some((i, h)), Some((j, -h)))
                - at(Some((i, -h)), Some((j, h)))
                + at(Some((i, -h)), Some((j, -h))))
                / (4.0 * h * h);
            hess[(i, j)] = x;
            hess[(j, i)] = x;
        }
    }
    let mut expected: Vec<f64> = hess.symmetric_eigenvalues().iter().copied().collect();
    expected.sort_by(f64::total_cmp);
    let st = r.stability.unwrap();
    assert_eq!(st.eigenvalues.len(), 6);
    for (e, x) in st.eigenvalues.iter().zip(&expected) {
        assert_abs_diff_eq!(*e, *x, epsilon = 1e-4 * x.abs());
    }
    // Modes list the joints in file order.
    let keys: Vec<&String> = st.modes[0].iter().map(|(k, _)| k).collect();
    assert_eq!(keys, names.iter().collect::<Vec<_>>());
}

/// A pendulum resting on its stop: the verdict is `stable` (no feasible motion is left at
/// first order), in analyze and in verify.
#[test]
fn a_pendulum_on_its_stop_has_a_verdict() {
    let m = model_from(
        r#"<robot name="stop"><link name="world"/>
      <link name="arm"><inertial><origin xyz="1 0 0"/><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
      <joint name="pivot" type="revolute"><parent link="world"/><child link="arm"/><axis xyz="0 1 0"/>
        <limit lower="-0.5" upper="0.5" effort="10" velocity="1"/></joint></robot>"#,
    );
    let (s, r) = solve(&m);
    assert_eq!(r.active_limits.len(), 1);
    assert_eq!(
        r.stability.as_ref().map(|s| s.verdict),
        Some(restpose::solver::Verdict::Stable)
    );
    for la in [LinearAlgebra::Dense, LinearAlgebra::Sparse] {
        let v = verify_on(&m, &s, la);
        assert!(v.passed);
        assert_eq!(
            v.stability.map(|s| s.verdict),
            Some(restpose::solver::Verdict::Stable)
        );
    }
}

/// Issue 21, item 8: `verify -q` prints the verdict line (and nothing else on standard
/// output), the JSON names the robot and lists why the pose fails, standard error shows the
/// failures.
#[test]
fn verify_quiet_prints_the_verdict_and_the_json_names_the_failures() {
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("v.json");
    let file = format!("{}/robots/pendulum.urdf", env!("CARGO_MANIFEST_DIR"));
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_restpose"))
        .args(["verify", &file, "--joint", "pivot=-1.3", "-q", "--json"])
        .arg(&json)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(4));
    assert_eq!(
        String::from_utf8_lossy(&out.stdout),
        "robot `pendulum`: pose FAILS\n"
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("`pivot` (dof 0) needs an effort of"), "{err}");
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(v["robot"], "pendulum");
    let failures = v["failures"].as_array().unwrap();
    assert_eq!(failures.len(), 1, "{failures:?}");
    assert!(failures[0].as_str().unwrap().contains("needs an effort"));
    assert_eq!(v["imbalance"][0]["locked"], false);
}
