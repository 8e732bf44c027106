//! A ladder whose loops border more pivots than the dense Schur complement takes: `Φ_u` by
//! super-nodes (module `merge`), block upper triangular, against the sparse factors (the
//! reference): multipliers, reduced gradient, tangent steps, corrector, and whole solves.
use super::merge::{phi_u_runs, MAX_NODE};
use super::phi_u::MAX_BORDER;
use crate::constraints::Constraints;
use crate::model::Model;
use crate::solver::system::{Backend, KktMatrix, System};
use crate::solver::{LinearAlgebra, Options};
use crate::urdf::{load_str, ImportOptions};
use nalgebra::DVector;

fn ladder(rungs: usize) -> Model {
    load_str(
        &crate::generate::ladder(rungs),
        "ladder.urdf",
        &ImportOptions::default(),
    )
    .expect("model loads")
    .model
}

fn close(a: &DVector<f64>, b: &DVector<f64>, tol: f64) -> bool {
    a.len() == b.len() && (a - b).amax() <= tol * (1.0 + a.amax())
}

/// The merged runs make `Φ_u` block upper triangular (every entry at or after its row's node),
/// where the runs alone border a loop's rows; a merged node stays within [`MAX_NODE`] and
/// is a union of consecutive runs.
#[test]
fn merged_runs_make_phi_u_block_triangular() {
    let model = ladder(30);
    let q0 = crate::solver::initial_state(&model).q;
    let q =
        crate::solver::assemble_only(&model, q0, &mut Default::default(), &[]).expect("assembles");
    let mut sys = System::new(&model, Constraints::new(&model, &[]), Backend::Sparse);
    let part = sys.partition(&q);
    sys.evaluate(&q, &part).expect("evaluates");
    let entries = &sys.work.jac.entries;
    let (m, n) = (sys.problem.cons.len(), q.len());
    let mut row_pos = vec![u32::MAX; m];
    for (k, &r) in part.rows.iter().enumerate() {
        row_pos[r] = k as u32;
    }
    let mut col_pos = vec![u32::MAX; n];
    for (k, &c) in part.dependent.iter().enumerate() {
        col_pos[c] = k as u32;
    }
    let below = |run_of: &[u32]| {
        entries
            .iter()
            .filter(|e| row_pos[e.0 as usize] != u32::MAX && col_pos[e.1 as usize] != u32::MAX)
            .filter(|e| {
                run_of[col_pos[e.1 as usize] as usize] < run_of[row_pos[e.0 as usize] as usize]
            })
            .count()
    };
    // The runs alone: a border of 7 pivots per rung, above the limit.
    let (runs_of, runs, bordered) = phi_u_runs(&part, m, n, entries, usize::MAX).expect("runs");
    let border: usize = (0..part.rows.len())
        .filter(|&k| bordered[runs_of[k] as usize])
        .count();
    assert!(border > MAX_BORDER, "border {border}");
    assert!(below(&runs_of) > 0);
    // Merged: nothing below the block diagonal, no border, fewer and bounded nodes.
    let (node_of, nodes, bordered) =
        phi_u_runs(&part, m, n, entries, MAX_BORDER).expect("super-nodes");
    assert!(bordered.iter().all(|&b| !b));
    assert_eq!(below(&node_of), 0);
    assert!(nodes < runs && nodes >= 30, "{nodes} nodes of {runs} runs");
    let mut size = vec![0usize; nodes];
    for k in 0..part.rows.len() {
        size[node_of[k] as usize] += 1;
        if k > 0 {
            // Consecutive positions: a node is an interval, and each run lies in one node.
            assert!(node_of[k] == node_of[k - 1] || node_of[k] == node_of[k - 1] + 1);
            if runs_of[k] == runs_of[k - 1] {
                assert_eq!(node_of[k], node_of[k - 1]);
            }
        }
    }
    assert!(
        size.iter().all(|&s| (1..=MAX_NODE).contains(&s)),
        "{size:?}"
    );
}

/// On a ladder of 30 rungs the tree factors (super-nodes, no border) give the sparse factors'
/// multipliers, reduced gradient, tangent step, corrector, KKT step and inertia to 10⁻¹⁰.
#[test]
fn long_ladder_phi_u_by_super_nodes_matches_the_sparse_factors() {
    let borders = super::tests::compare_with_sparse("ladder of 30", &ladder(30), &[], 1e-10);
    assert_eq!(borders, (0, 0), "(Φ_u, KKT) borders");
}

/// The KKT matrix of a ladder by super-nodes: with a negative curvature (the shift `−σ` above
/// the smallest eigenvalues of the reduced Hessian) the inertia still equals the sparse LDLᵀ's.
#[test]
fn long_ladder_kkt_inertia_by_super_nodes_matches_the_sparse_one() {
    let model = ladder(30);
    let q0 = crate::solver::initial_state(&model).q;
    let q =
        crate::solver::assemble_only(&model, q0, &mut Default::default(), &[]).expect("assembles");
    let mut sparse = System::new(&model, Constraints::new(&model, &[]), Backend::Sparse);
    let mut tree = System::new(&model, Constraints::new(&model, &[]), Backend::Tree);
    let part = sparse.partition(&q);
    let es = sparse.evaluate(&q, &part).expect("sparse evaluation");
    let et = tree.evaluate(&q, &part).expect("tree evaluation");
    for delta in [1e-3, 0.0, -1e-1, -10.0] {
        let fs = sparse.factor_kkt(&q, &part, &es, true, delta);
        let ft = tree.factor_kkt(&q, &part, &et, true, delta);
        assert!(matches!(tree.work.kkt, Some(KktMatrix::Tree(_))));
        assert_eq!(fs, ft, "δ = {delta}");
    }
}

/// The automatic choice takes the tree factors for a long ladder (no stops), with the same
/// iterations and the same rest as the sparse path to 10⁻¹⁰.
#[test]
fn long_ladder_solves_on_the_tree_factors_like_the_sparse_ones() {
    let model = ladder(80);
    let solve = |linear_algebra| {
        let options = Options {
            linear_algebra,
            ..Options::default()
        };
        crate::solver::solve(&model, &options).expect("solves")
    };
    let (ss, rs) = solve(LinearAlgebra::Sparse);
    let (st, rt) = solve(LinearAlgebra::Auto);
    assert_eq!(rt.diagnostics.linear_algebra, "tree");
    assert_eq!(rs.termination, rt.termination);
    assert_eq!(rs.iterations, rt.iterations);
    assert!(
        close(&ss.q, &st.q, 1e-10),
        "rest differs by {:e}",
        (&ss.q - &st.q).amax()
    );
    let v = rs.energy.total;
    assert!(
        (rt.energy.total - v).abs() <= 1e-13 * v.abs(),
        "{v} vs {}",
        rt.energy.total
    );
}
