//! The tree factors against the sparse ones (the reference): multipliers, reduced gradient,
//! tangent steps, KKT solutions and inertia at the same points and partitions, on a chain,
//! a chain with locked joints (extra rows on bodies, like stops), a branched tree (Solo-12,
//! base welded), and loops (a spatial four-bar, a ladder: the border); and whole solves.
use crate::constraints::Constraints;
use crate::model::{JointId, Model};
use crate::solver::sparse::kkt::Factored;
use crate::solver::system::{Backend, Factors, KktMatrix, System};
use crate::solver::{LinearAlgebra, Options};
use crate::urdf::{load_file, load_str, ImportOptions};
use nalgebra::DVector;

fn from_text(text: &str) -> Model {
    load_str(text, "tree.urdf", &ImportOptions::default())
        .expect("model loads")
        .model
}

fn solo12() -> Model {
    solo12_with(ImportOptions::default())
}

fn solo12_with(options: ImportOptions) -> Model {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/robots/solo12/solo12_ground.urdf"
    );
    load_file(path, &options).expect("solo12 loads").model
}

/// Joint locks `(joint, coordinate, value)`.
type Locks = Vec<(JointId, usize, f64)>;

/// `(name, model, locks)`.
fn cases() -> Vec<(&'static str, Model, Locks)> {
    vec![
        (
            "chain",
            from_text(&crate::generate::chain(12, false)),
            vec![],
        ),
        (
            "chain with locks",
            from_text(&crate::generate::chain(9, false)),
            vec![(JointId(2), 0, 0.2), (JointId(6), 0, -0.1)],
        ),
        ("solo12", solo12(), vec![]),
        (
            "four-bar",
            from_text(include_str!("../../../robots/four_bar_spatial.urdf")),
            vec![],
        ),
        ("ladder", from_text(&crate::generate::ladder(3)), vec![]),
    ]
}

fn close(a: &DVector<f64>, b: &DVector<f64>, tol: f64) -> bool {
    a.len() == b.len() && (a - b).amax() <= tol * (1.0 + a.amax())
}

/// The tree factors of `model` with `locks` against the sparse ones at its assembled point
/// (corrected onto the locks): multipliers, reduced gradient, tangent step, corrector, KKT
/// solution by LDLᵀ and by LU, and inertia, to `tol`. Returns the borders `(Φ_u, KKT)` of
/// the tree factors.
pub(super) fn compare_with_sparse(
    name: &str,
    model: &Model,
    locks: &[(JointId, usize, f64)],
    tol: f64,
) -> (usize, usize) {
    let q0 = crate::solver::initial_state(model).q;
    let q =
        crate::solver::assemble_only(model, q0, &mut Default::default(), &[]).expect("assembles");
    let mut sparse = System::new(model, Constraints::new(model, locks), Backend::Sparse);
    let mut tree = System::new(model, Constraints::new(model, locks), Backend::Tree);
    let part = sparse.partition(&q);
    assert_eq!(part.dependent, tree.partition(&q).dependent, "{name}");
    // The locks move the point off the manifold: a corrector step first (both backends).
    let mut q = q;
    sparse
        .correct(&mut q, &part, 1e-12, 20)
        .unwrap_or_else(|_| panic!("{name}: corrector"));
    let es = sparse.evaluate(&q, &part).expect("sparse evaluation");
    let et = tree.evaluate(&q, &part).expect("tree evaluation");
    let Factors::Tree(f) = &et.factors else {
        panic!("{name}: tree factors");
    };
    let phi_u_border = f.border_size();
    assert!(
        close(&es.mu, &et.mu, tol),
        "{name}: μ {} vs {}",
        es.mu,
        et.mu
    );
    assert!(close(&es.grad_v, &et.grad_v, tol), "{name}: ∇f");
    let dv = DVector::from_fn(part.independent.len(), |i, _| (i as f64 + 0.5).sin());
    let (zs, zt) = (
        sparse.tangent_step(&part, &es, &dv),
        tree.tangent_step(&part, &et, &dv),
    );
    assert!(close(&zs, &zt, tol), "{name}: Z δv");
    // The corrector (Φ_u solves) from a perturbed point lands on the same q.
    let mut qs = &q + &zs * 1e-3;
    let mut qt = qs.clone();
    sparse
        .correct(&mut qs, &part, 1e-12, 20)
        .expect("sparse corrects");
    tree.correct(&mut qt, &part, 1e-12, 20)
        .expect("tree corrects");
    assert!(close(&qs, &qt, tol), "{name}: corrector");
    // KKT: same step and same inertia, LDLᵀ and LU.
    let fs = sparse.factor_kkt(&q, &part, &es, true, 1e-3);
    let ft = tree.factor_kkt(&q, &part, &et, true, 1e-3);
    let Some(KktMatrix::Tree(k)) = &tree.work.kkt else {
        panic!("{name}: tree KKT");
    };
    let kkt_border = k.border_size();
    assert_eq!(fs, ft, "{name}: factored (inertia)");
    assert!(matches!(ft, Factored::Ldlt { .. }), "{name}: {ft:?}");
    let b = DVector::from_fn(q.len(), |i, _| (0.3 * i as f64).cos());
    let xs = sparse.kkt_solve(&b).expect("sparse KKT solve");
    let xt = tree.kkt_solve(&b).expect("tree KKT solve");
    assert!(close(&xs, &xt, tol), "{name}: KKT solution");
    assert_eq!(tree.kkt_fall_back_to_lu(), Factored::Lu, "{name}");
    let xl = tree.kkt_solve(&b).expect("tree KKT solve by LU");
    assert!(close(&xs, &xl, tol), "{name}: KKT solution by LU");
    (phi_u_border, kkt_border)
}

#[test]
fn tree_factors_match_the_sparse_ones() {
    for (name, model, locks) in cases() {
        let (phi_u_border, kkt_border) = compare_with_sparse(name, &model, &locks, 1e-9);
        let loops = matches!(name, "four-bar" | "ladder");
        assert_eq!(phi_u_border > 0, loops, "{name}: Φ_u border {phi_u_border}");
        assert_eq!(kkt_border > 0, loops, "{name}: border {kkt_border}");
    }
}

#[test]
fn tree_solves_match_the_sparse_ones() {
    use crate::model::Friction::{None as Frictionless, Stick};
    let standing = solo12_with(ImportOptions {
        floating_base: true,
        ground: true,
        ..ImportOptions::default()
    });
    let models = [
        (
            "chain",
            from_text(&crate::generate::chain(60, false)),
            Frictionless,
        ),
        (
            "ladder",
            from_text(&crate::generate::ladder(6)),
            Frictionless,
        ),
        ("rope", from_text(&crate::generate::rope(30)), Frictionless),
        ("solo12", solo12(), Frictionless),
        // Sticking feet: a unique rest pose (frictionless, the base could slide).
        ("solo12 standing on the ground", standing, Stick),
        // 60 loops: a border too large for the dense Schur complement, so super-nodes (module
        // `merge`).
        (
            "long ladder",
            from_text(&crate::generate::ladder(60)),
            Frictionless,
        ),
    ];
    for (name, model, friction) in models {
        let solve = |linear_algebra| {
            let options = Options {
                linear_algebra,
                friction,
                ..Options::default()
            };
            crate::solver::solve(&model, &options).expect("solves")
        };
        let (ss, rs) = solve(LinearAlgebra::Sparse);
        let (st, rt) = solve(LinearAlgebra::Tree);
        assert_eq!(rt.diagnostics.linear_algebra, "tree");
        assert_eq!(rs.termination, rt.termination, "{name}");
        assert_eq!(rs.iterations, rt.iterations, "{name}");
        assert!(
            close(&ss.q, &st.q, 1e-9),
            "{name}: final pose differs by {:e}",
            (&ss.q - &st.q).amax()
        );
        assert!(
            (rs.energy.total - rt.energy.total).abs() <= 1e-9 * (1.0 + rs.energy.total.abs()),
            "{name}"
        );
    }
}

/// A factor buffer of `Φ_u` reused from the pool (the factors of another point in place)
/// gives the multipliers and steps of a fresh buffer bit for bit: every slot is stored anew
/// by its first triplet or zeroed (module `phi_u`), on trees, with locks and with a border.
#[test]
fn reused_phi_u_buffers_equal_fresh_ones_bit_for_bit() {
    let bits = |a: &DVector<f64>, b: &DVector<f64>| {
        a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
    };
    for (name, model, locks) in cases() {
        let q0 = crate::solver::initial_state(&model).q;
        let q = crate::solver::assemble_only(&model, q0, &mut Default::default(), &[])
            .expect("assembles");
        let mut used = System::new(&model, Constraints::new(&model, &locks), Backend::Tree);
        let part = used.partition(&q);
        let mut q = q;
        used.correct(&mut q, &part, 1e-12, 20)
            .unwrap_or_else(|_| panic!("{name}: corrector"));
        // Another point under the same partition, factored first and dropped: its buffer
        // returns to the pool and takes the factors at `q`.
        let e0 = used.evaluate(&q, &part).expect("evaluates");
        let dv = DVector::from_fn(part.independent.len(), |i, _| (i as f64 + 0.5).sin());
        let mut other = &q + used.tangent_step(&part, &e0, &dv) * 0.2;
        used.correct(&mut other, &part, 1e-12, 20)
            .unwrap_or_else(|_| panic!("{name}: corrector at the other point"));
        drop(e0);
        drop(
            used.evaluate(&other, &part)
                .expect("evaluates the other point"),
        );
        let reused = used.evaluate(&q, &part).expect("evaluates again");
        let mut fresh_sys = System::new(&model, Constraints::new(&model, &locks), Backend::Tree);
        let fresh = fresh_sys.evaluate(&q, &part).expect("evaluates fresh");
        assert!(matches!(reused.factors, Factors::Tree(_)), "{name}");
        assert!(bits(&reused.mu, &fresh.mu), "{name}: μ");
        assert!(bits(&reused.grad_v, &fresh.grad_v), "{name}: ∇f");
        let (zr, zf) = (
            used.tangent_step(&part, &reused, &dv),
            fresh_sys.tangent_step(&part, &fresh, &dv),
        );
        assert!(bits(&zr, &zf), "{name}: Z δv");
    }
}

/// The tree route of an open mechanism (each run of pivots on one body a node, one pass over
/// the triplets) builds the split of `Φ_u` that the general construction (the border test
/// over the triplets, module `merge`) builds, to the last slot: on chains, with locks (extra
/// rows on bodies), on a branched tree; where a row reaches an earlier node (the loops) it
/// gives way to the general construction, with its border or super-nodes.
#[test]
fn tree_route_split_is_the_general_one() {
    use crate::solver::tree::phi_u::TreeSplit;
    let long_ladder = from_text(&crate::generate::ladder(30));
    for (name, model, locks) in cases()
        .into_iter()
        .chain([("long ladder", long_ladder, vec![])])
    {
        let q0 = crate::solver::initial_state(&model).q;
        let q = crate::solver::assemble_only(&model, q0, &mut Default::default(), &[])
            .expect("assembles");
        let mut sys = System::new(&model, Constraints::new(&model, &locks), Backend::Tree);
        let part = sys.partition(&q);
        sys.evaluate(&q, &part).expect("evaluates");
        let entries = &sys.work.jac.entries;
        let (m, n) = (sys.problem.cons.len(), q.len());
        let tree = TreeSplit::new(&part, m, n, entries, true).expect(name);
        let general = TreeSplit::new(&part, m, n, entries, false).expect(name);
        assert_eq!(tree.layout(), general.layout(), "{name}");
        let (_, (off, _, border, v_at), _) = tree.layout();
        assert!(!off.is_empty() && !v_at.is_empty(), "{name}");
        let loops = matches!(name, "four-bar" | "ladder");
        assert_eq!(!border.is_empty(), loops, "{name}");
    }
}
