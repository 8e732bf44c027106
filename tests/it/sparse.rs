//! The sparse large-scale path (`LinearAlgebra::Sparse`): the same equilibria as the dense path
//! on every robot, and verified equilibria of chains and ladders too large for the dense path,
//! checked against energies written here in joint coordinates.
use crate::common::*;
use restpose::{LinearAlgebra, Model, Options};

fn solve_with(model: &Model, la: LinearAlgebra) -> (restpose::State, restpose::Report) {
    let options = Options {
        linear_algebra: la,
        ..Default::default()
    };
    let (s, r) = restpose::solve(model, &options).unwrap_or_else(|e| panic!("{e}"));
    assert!(
        r.converged(),
        "{} ({la:?}): {:?}",
        model.name(),
        r.termination
    );
    (s, r)
}

#[test]
fn sparse_and_dense_paths_agree_on_every_robot_and_generated_family() {
    let dir = format!("{}/robots", env!("CARGO_MANIFEST_DIR"));
    let mut models: Vec<Model> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().and_then(|e| e.to_str()) == Some("urdf"))
        .map(|p| robot(p.file_stem().unwrap().to_str().unwrap()))
        .collect();
    models.push(model_from(&restpose::generate::chain(12, false)));
    models.push(model_from(&restpose::generate::chain(8, true)));
    models.push(model_from(&restpose::generate::ladder(6)));
    assert!(models.len() >= 14);
    for m in &models {
        let (sd, rd) = solve_with(m, LinearAlgebra::Dense);
        let (ss, rs) = solve_with(m, LinearAlgebra::Sparse);
        assert_eq!(rd.diagnostics.linear_algebra, "dense");
        assert_eq!(rs.diagnostics.linear_algebra, "sparse");
        let v = rd.energy.total;
        assert!(
            (rs.energy.total - v).abs() <= 1e-9 * (1.0 + v.abs()),
            "{}: V dense {v} sparse {}",
            m.name(),
            rs.energy.total
        );
        assert_eq!(rs.dof, rd.dof, "{}", m.name());
        assert_eq!(
            rs.redundant_constraints.len(),
            rd.redundant_constraints.len(),
            "{}",
            m.name()
        );
        assert_eq!(
            rs.stability.as_ref().map(|s| &s.verdict),
            rd.stability.as_ref().map(|s| &s.verdict),
            "{}",
            m.name()
        );
        let jd = sd.joint_values(m);
        let js = ss.joint_values(m);
        for ((name, a), (_, b)) in jd.iter().zip(&js) {
            for (x, y) in a.iter().zip(b) {
                assert!(
                    (x - y).abs() < 1e-6,
                    "{}: {name} dense {x} sparse {y}",
                    m.name()
                );
            }
        }
        assert_verified_minimum(m, &ss);
    }
}

/// A 300-link spatial chain (300 degrees of freedom: the stability verdict comes from the KKT
/// inertia, or from Lanczos when eigenvalues are asked for): restpose's joint angles are a
/// stationary point of the chain's energy written here in joint coordinates, with the same
/// energy, and the verdict is `stable`. The eigenvalues asked for change nothing else: the
/// same iterates, pose, verdict and tolerance.
#[test]
fn long_chain_is_a_minimum_of_its_joint_space_energy() {
    let n = 300;
    let m = model_from(&restpose::generate::chain(n, false));
    let (s, r) = solve_with(&m, LinearAlgebra::Sparse);
    assert_eq!(r.dof, n);
    assert_eq!(r.diagnostics.eigenvalues_by, "inertia");
    let options = Options {
        linear_algebra: LinearAlgebra::Sparse,
        eigenvalues: true,
        ..Default::default()
    };
    let (se, re) = restpose::solve(&m, &options).unwrap();
    assert_eq!(re.diagnostics.eigenvalues_by, "lanczos");
    assert_eq!(se.q, s.q);
    assert_eq!(re.history, r.history);
    let (st, ste) = (
        r.stability.as_ref().unwrap(),
        re.stability.as_ref().unwrap(),
    );
    assert!(st.eigenvalues.is_empty() && st.modes.is_empty());
    assert_eq!(st.verdict, restpose::solver::Verdict::Stable);
    assert_eq!(ste.verdict, st.verdict);
    assert_eq!(ste.tolerance, st.tolerance);
    assert!(ste.eigenvalues[0] > ste.tolerance);
    let theta: Vec<f64> = (0..n)
        .map(|i| s.joint(&m, &format!("joint{i}")).unwrap()[0])
        .collect();
    let energy = |th: &[f64]| energies::chain(n, th);
    let v = energy(&theta);
    assert!(
        (v - r.energy.total).abs() < 1e-9 * v.abs(),
        "{v} vs {}",
        r.energy.total
    );
    // Joint-space gradient by central differences, to their rounding error `ε |V| / h`.
    let h = 1e-5;
    for i in (0..n).step_by(7) {
        let (mut tp, mut tm) = (theta.clone(), theta.clone());
        tp[i] += h;
        tm[i] -= h;
        let g = (energy(&tp) - energy(&tm)) / (2.0 * h);
        assert!(g.abs() < 1e-13 * v.abs() / h + 1e-6, "∂V/∂θ{i} = {g}");
    }
    assert_verified_minimum(&m, &s);
}

/// A ladder of 250 closed loops (750 redundant rows; the dense path needs minutes): the posts'
/// angles are stationary for the ladder's energy written in those angles.
#[test]
fn long_ladder_is_stationary_for_its_loop_angle_energy() {
    let n = 250;
    let m = model_from(&restpose::generate::ladder(n));
    let (s, r) = solve_with(&m, LinearAlgebra::Auto);
    // The tree factors (by super-nodes: a loop per rung).
    assert_eq!(r.diagnostics.linear_algebra, "tree");
    assert_eq!(r.dof, n);
    assert_eq!(r.redundant_constraints.len(), 3 * n);
    assert_eq!(
        r.stability.as_ref().unwrap().verdict,
        restpose::solver::Verdict::Stable
    );
    assert!(r.diagnostics.constraint_residual < 1e-10);
    let phi: Vec<f64> = (0..n)
        .map(|k| s.joint(&m, &format!("hang_left{k}")).unwrap()[0])
        .collect();
    let energy = |phi: &[f64]| energies::ladder(n, phi);
    let v = energy(&phi);
    assert!(
        (v - r.energy.total).abs() < 1e-9 * v.abs(),
        "{v} vs {}",
        r.energy.total
    );
    // Gradient by central differences, to their rounding error `ε |V| / h`.
    let h = 1e-5;
    for k in (0..n).step_by(5) {
        let (mut p, mut q) = (phi.clone(), phi.clone());
        p[k] += h;
        q[k] -= h;
        let g = (energy(&p) - energy(&q)) / (2.0 * h);
        assert!(g.abs() < 1e-13 * v.abs() / h + 1e-6, "∂V/∂φ{k} = {g}");
    }
}
