//! Every robot in `robots/` converges to a verified stable equilibrium.
use crate::common::*;
use approx::assert_abs_diff_eq;
use nalgebra::Point3;

#[test]
fn every_robot_loads_and_solves_to_a_verified_minimum() {
    let dir = format!("{}/robots", env!("CARGO_MANIFEST_DIR"));
    let mut count = 0;
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().and_then(|e| e.to_str()) != Some("urdf") {
            continue;
        }
        let name = path.file_stem().unwrap().to_str().unwrap().to_string();
        let m = robot(&name);
        let (s, r) = solve(&m);
        assert_eq!(
            r.stability.as_ref().map(|s| s.verdict.as_str()),
            Some("stable"),
            "{name}"
        );
        assert_verified_minimum(&m, &s);
        count += 1;
    }
    assert!(count >= 4);
}

#[test]
fn slider_crank_reports_redundant_rows_and_one_dof() {
    let m = robot("slider_crank");
    let (s, r) = solve(&m);
    assert_eq!(r.dof, 1);
    // A planar loop of four joints in 3-D: three out-of-plane rows are redundant.
    assert_eq!(
        r.redundant_constraints.len(),
        3,
        "{:?}",
        r.redundant_constraints
    );
    // The loop is closed: the slider's pin and the rod's end coincide.
    let rod_end = s.link_pose(&m, "rod").unwrap() * Point3::new(0.3, 0.0, 0.0);
    let slider = s.link_pose(&m, "slider").unwrap() * Point3::origin();
    assert!((rod_end - slider).norm() < 1e-10);
    // The slider stays on its line y = 0, z = 0.
    assert_abs_diff_eq!(slider.y, 0.0, epsilon = 1e-10);
    assert_abs_diff_eq!(slider.z, 0.0, epsilon = 1e-10);
}

#[test]
fn spatial_four_bar_has_one_dof_and_closes() {
    let m = robot("four_bar_spatial");
    let (s, r) = solve(&m);
    assert_eq!(r.dof, 1);
    assert!(r.redundant_constraints.is_empty());
    let a = s.link_pose(&m, "coupler").unwrap() * Point3::new(0.4272, 0.0, 0.0);
    let b = s.link_pose(&m, "rocker").unwrap() * Point3::new(0.15, 0.0, 0.0);
    assert!((a - b).norm() < 1e-10);
}

/// Independent check of the 20-link spatial chain: its potential energy as a function of the
/// joint angles, computed here by forward kinematics in joint coordinates, is stationary at
/// restpose's joint angles, and its Hessian there is positive definite.
#[test]
fn chain_matches_minimal_coordinate_energy() {
    let n = 20;
    let m = robot("chain20");
    let (s, r) = solve(&m);
    assert_eq!(r.dof, n);
    let theta: Vec<f64> = (0..n)
        .map(|i| s.joint(&m, &format!("joint{i}")).unwrap()[0])
        .collect();
    let energy = |th: &[f64]| energies::chain(n, th);
    assert_abs_diff_eq!(energy(&theta), r.energy.total, epsilon = 1e-9);
    let h = 1e-6;
    for i in 0..n {
        let mut tp = theta.clone();
        let mut tm = theta.clone();
        tp[i] += h;
        tm[i] -= h;
        let g = (energy(&tp) - energy(&tm)) / (2.0 * h);
        assert!(g.abs() < 1e-6, "∂V/∂θ{i} = {g}");
    }
    // Hessian by central differences: positive definite.
    let hh = 1e-4;
    let hess = nalgebra::DMatrix::from_fn(n, n, |i, j| {
        let f = |a: f64, b: f64| {
            let mut t = theta.clone();
            t[i] += a;
            t[j] += b;
            energy(&t)
        };
        (f(hh, hh) - f(hh, -hh) - f(-hh, hh) + f(-hh, -hh)) / (4.0 * hh * hh)
    });
    let eig = nalgebra::SymmetricEigen::new(hess).eigenvalues;
    assert!(
        eig.min() > 0.0,
        "minimal-coordinate Hessian not positive definite: {}",
        eig.min()
    );
}

/// Generated planar chain: closed-form balance k_i θ_i = Σ_{j ≥ i} torque of link j's weight.
#[test]
fn planar_chain_joint_torques_balance_by_hand() {
    let n = 8;
    let m = model_from(&restpose::generate::chain(n, true));
    let (s, _) = solve(&m);
    let theta: Vec<f64> = (0..n)
        .map(|i| s.joint(&m, &format!("joint{i}")).unwrap()[0])
        .collect();
    // Joint i at x_i; link j's centre of mass at c_j (in the x-z plane).
    let mut pts = Vec::new();
    let mut ang: f64 = 0.0;
    let mut p = nalgebra::Vector2::new(0.0, 0.0);
    for i in 0..n {
        if i > 0 {
            p += nalgebra::Vector2::new(ang.cos(), -ang.sin()) * 0.2;
        }
        ang += theta[i];
        let c = p + nalgebra::Vector2::new(ang.cos(), -ang.sin()) * 0.1;
        pts.push((p, c));
    }
    for i in 0..n {
        let k = 10.0 * ((n - i) * (n - i)) as f64;
        // Gravity (−z) torque about +y at joint i of links j ≥ i: (c − p)_x · m g.
        let t: f64 = (i..n).map(|j| (pts[j].1.x - pts[i].0.x) * 9.81).sum();
        assert_abs_diff_eq!(k * theta[i], t, epsilon = 1e-8);
    }
}

fn solve_with_initial(
    name: &str,
    initial: &[(&str, usize, f64)],
) -> (restpose::Model, restpose::State, restpose::Report) {
    solve_with_initial_options(name, initial, &Default::default())
}

fn solve_with_initial_options(
    name: &str,
    initial: &[(&str, usize, f64)],
    options: &restpose::Options,
) -> (restpose::Model, restpose::State, restpose::Report) {
    let path = format!("{}/robots/{name}.urdf", env!("CARGO_MANIFEST_DIR"));
    let opts = restpose::urdf::ImportOptions {
        initial: initial
            .iter()
            .map(|(j, d, v)| (j.to_string(), *d, *v))
            .collect(),
        ..Default::default()
    };
    let m = restpose::urdf::load_file(&path, &opts).unwrap().model;
    let (s, r) = restpose::solve(&m, options).unwrap();
    assert!(
        r.converged(),
        "{name} from {initial:?}: {:?}",
        r.termination
    );
    (m, s, r)
}

fn max_link_distance(m: &restpose::Model, a: &restpose::State, b: &restpose::State) -> f64 {
    m.links()
        .iter()
        .map(|l| {
            let (pa, pb) = (
                a.link_pose(m, &l.name).unwrap(),
                b.link_pose(m, &l.name).unwrap(),
            );
            (pa.translation.vector - pb.translation.vector).norm()
                + pa.rotation.angle_to(&pb.rotation)
        })
        .fold(0.0, f64::max)
}

/// The paper's tractor-semitrailer (rebuilt): 17 bodies, 77 independent constraints, 25
/// degrees of freedom; converges from starts about 0.01 m and 0.3 m off equilibrium to the
/// same stable rest pose.
#[test]
fn tractor_trailer_converges_from_near_and_far_starts() {
    let (m, rest, r) = solve_with_initial("tractor_trailer", &[]);
    assert_eq!(r.sizes.bodies, 17);
    assert_eq!(r.dof, 25);
    assert!(r.redundant_constraints.is_empty());
    assert_eq!(
        r.sizes.constraint_rows - 17,
        77,
        "joint rows besides the 17 normalization rows"
    );
    assert_eq!(
        r.stability.as_ref().unwrap().verdict,
        restpose::solver::Verdict::Stable
    );
    for start in [
        [("fifth_wheel_pitch", 0, 0.0017)],
        [("fifth_wheel_pitch", 0, 0.054)],
        [("tractor_trunnion_left", 0, 0.0154)],
        [("front_leaf_left_eye", 0, 0.429)],
        [("trailer_trunnion_left", 0, 0.46)],
    ] {
        let (_, s, r) = solve_with_initial("tractor_trailer", &start);
        let d = max_link_distance(&m, &rest, &s);
        assert!(
            d < 1e-7,
            "from {start:?}: {} iterations, ends {d:e} away",
            r.iterations
        );
    }
    // From the left tractor trunnion at −0.46 rad the Newton step along the search path
    // (`step::path_hessian`) comes in 12 iterations to another stable equilibrium, 3,253 J
    // lower (the step in the partition's coordinates reached the rest above in 9): a verified
    // minimum below that rest.
    let start = [("tractor_trunnion_left", 0, -0.46)];
    let (far, s, r) = solve_with_initial("tractor_trailer", &start);
    assert!(r.converged(), "{:?}", r.termination);
    assert!(r.iterations <= 15, "{} iterations", r.iterations);
    let rest_energy = solve_with_initial("tractor_trailer", &[]).2.energy.total;
    assert!(r.energy.total <= rest_energy + 1e-6 * rest_energy.abs());
    assert_eq!(
        r.stability.as_ref().unwrap().verdict,
        restpose::solver::Verdict::Stable
    );
    crate::common::assert_verified_minimum(&far, &s);
}

/// Stewart platform under a payload: 13 bodies, 6 degrees of freedom, back to the same pose
/// from a leg stretched by 0.3 m and a tilted base joint. The stretched starts are outside the
/// legs' limits (±0.15 m), so limits are ignored here: this tests the unconstrained iteration
/// from far away (with limits enforced the start is first put on the stop, another path).
#[test]
fn stewart_platform_converges_from_far_starts() {
    let ignore = restpose::Options {
        limits: restpose::Limits::Ignore,
        ..Default::default()
    };
    let (m, rest, r) = solve_with_initial_options("stewart_platform", &[], &ignore);
    assert_eq!(r.sizes.bodies, 13);
    assert_eq!(r.dof, 6);
    for start in [
        [("leg1_slide", 0, 0.3)],
        [("leg3_slide", 0, -0.3)],
        [("leg1_base", 1, -0.5)],
    ] {
        let (_, s, r) = solve_with_initial_options("stewart_platform", &start, &ignore);
        let d = max_link_distance(&m, &rest, &s);
        assert!(
            d < 1e-7,
            "from {start:?}: {} iterations, ends {d:e} away",
            r.iterations
        );
    }
    // The floating joint reports the platform's own displacement.
    let pf = rest.joint(&m, "platform_float").unwrap();
    let link = rest.link_pose(&m, "platform").unwrap();
    let origin = restpose::State::from_joint_values(&m, &Default::default())
        .link_pose(&m, "platform")
        .unwrap();
    for k in 0..3 {
        assert!(
            (pf[k] - (link.translation.vector[k] - origin.translation.vector[k])).abs() < 1e-12
        );
    }
}

/// From a start with the fifth wheel pitched by 0.3 rad, the direct Newton iteration needs 27
/// iterations; with a budget of 15 per solve it stops short (`load_steps = 1`), and the default
/// options fall back to load stepping, whose eight stages each fit in the budget and end at the
/// rest pose.
#[test]
fn a_far_tractor_start_reaches_the_rest_directly_and_by_load_steps() {
    // This start needed the automatic 8-step ramp before the partition was renewed as its
    // pivots drift (issue 21): the direct solve stalled within 15 iterations. Now it takes
    // 12, and an explicit ramp comes to a verified rest within the whole-solve budget.
    let (m, rest, _) = solve_with_initial("tractor_trailer", &[]);
    let path = format!("{}/robots/tractor_trailer.urdf", env!("CARGO_MANIFEST_DIR"));
    let opts = restpose::urdf::ImportOptions {
        initial: vec![("fifth_wheel_pitch".into(), 0, 0.3)],
        ..Default::default()
    };
    let far = restpose::urdf::load_file(&path, &opts).unwrap().model;
    // The start is on the fifth wheel's stop (0.3 rad); this is about load stepping, so limits
    // are ignored (with them enforced this start ends in another, higher stable equilibrium).
    let budget = restpose::Options {
        max_iterations: 15,
        limits: restpose::Limits::Ignore,
        ..Default::default()
    };
    let direct = restpose::Options {
        load_steps: 1,
        ..budget.clone()
    };
    let (s, r) = restpose::solve(&far, &direct).unwrap();
    assert!(r.converged(), "{:?}", r.termination);
    let d = max_link_distance(&m, &rest, &s);
    assert!(d < 1e-7, "{d:e}");
    let ramped = restpose::Options {
        load_steps: 8,
        max_iterations: 200,
        ..budget.clone()
    };
    let (s, r) = restpose::solve(&far, &ramped).unwrap();
    assert!(r.converged(), "{:?}", r.termination);
    assert_eq!(r.diagnostics.load_steps, 8);
    assert!(r.iterations <= 200);
    // The ramp follows the load from the far start and may end in another stable equilibrium
    // of the articulated vehicle: a verified minimum, not necessarily the same one.
    crate::common::assert_verified_minimum(&far, &s);
}

/// Generated ladder of parallelogram loops: one degree of freedom and three redundant rows
/// per loop, and the rest angles are stationary for the ladder's energy written here
/// independently in the posts' absolute angles (rungs stay horizontal).
#[test]
fn ladder_matches_minimal_coordinate_energy() {
    let n = 6;
    let m = model_from(&restpose::generate::ladder(n));
    let (s, r) = solve(&m);
    assert_eq!(r.dof, n);
    assert_eq!(r.redundant_constraints.len(), 3 * n);
    let phi: Vec<f64> = (0..n)
        .map(|k| s.joint(&m, &format!("hang_left{k}")).unwrap()[0])
        .collect();
    let energy = |phi: &[f64]| energies::ladder(n, phi);
    assert_abs_diff_eq!(energy(&phi), r.energy.total, epsilon = 1e-9);
    for k in 0..n {
        let (mut p, mut q) = (phi.clone(), phi.clone());
        p[k] += 1e-6;
        q[k] -= 1e-6;
        let g = (energy(&p) - energy(&q)) / 2e-6;
        assert!(g.abs() < 1e-6, "∂V/∂φ{k} = {g}");
    }
}
