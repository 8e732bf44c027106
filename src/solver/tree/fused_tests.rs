//! The fused assembly against the general one (block Hessian, augmentation, scatter: the
//! reference), entry by entry and bit for bit, at random poses of models with every joint
//! kind the tree path takes (continuous, revolute with springs, prismatic, fixed, spherical
//! and universal in a loop, locks as extra rows, a border).
use crate::constraints::Constraints;
use crate::model::{JointId, Model};
use crate::solver::system::{Backend, KktMatrix, System};
use crate::urdf::{load_file, load_str, ImportOptions};
use nalgebra::DVector;

fn from_text(text: &str) -> Model {
    load_str(text, "fused.urdf", &ImportOptions::default())
        .expect("model loads")
        .model
}

fn robot(name: &str) -> Model {
    let path = format!("{}/robots/{name}", env!("CARGO_MANIFEST_DIR"));
    load_file(&path, &ImportOptions::default())
        .expect("robot loads")
        .model
}

/// Joint locks `(joint, coordinate, value)`.
type Locks = Vec<(JointId, usize, f64)>;

/// `(name, model, locks)`.
fn cases() -> Vec<(&'static str, Model, Locks)> {
    vec![
        (
            "chain",
            from_text(&crate::generate::chain(8, false)),
            vec![],
        ),
        (
            "planar chain with locks",
            from_text(&crate::generate::chain(7, true)),
            vec![(JointId(2), 0, 0.2), (JointId(5), 0, -0.1)],
        ),
        ("rope", from_text(&crate::generate::rope(12)), vec![]),
        ("slider-crank", robot("slider_crank.urdf"), vec![]),
        ("quadruped leg", robot("quadruped_leg.urdf"), vec![]),
        ("solo12", robot("solo12/solo12_ground.urdf"), vec![]),
        ("four-bar", robot("four_bar_spatial.urdf"), vec![]),
        ("ladder", from_text(&crate::generate::ladder(3)), vec![]),
    ]
}

/// The tree KKT matrix's values after the last assembly.
fn values(sys: &System) -> Vec<f64> {
    match &sys.work.kkt {
        Some(KktMatrix::Tree(k)) => k.values.clone(),
        _ => panic!("tree KKT matrix"),
    }
}

#[test]
fn fused_blocks_equal_the_general_assembly_bit_for_bit() {
    let mut lcg = crate::lcg::Lcg::new(7);
    let mut fused_cases = 0;
    for (name, model, locks) in cases() {
        let q0 = crate::solver::initial_state(&model).q;
        let mut sys = System::new(&model, Constraints::new(&model, &locks), Backend::Tree);
        let part = sys.partition(&q0);
        let mut q = q0.clone();
        // Off the manifold is fine for an assembly; multipliers from a nearby evaluation.
        let _ = sys.correct(&mut q, &part, 1e-12, 20);
        let Some(eval) = sys.evaluate(&q, &part) else {
            panic!("{name}: evaluates");
        };
        // The structure from a general assembly (no fused one before it).
        assert!(
            !sys.assemble_fused(&q, &part, &eval),
            "{name}: no structure yet"
        );
        assert!(
            sys.assemble_kkt(&q, &part, &eval),
            "{name}: general assembly"
        );
        if !matches!(sys.work.kkt, Some(KktMatrix::Tree(_))) {
            continue;
        }
        fused_cases += 1;
        for pose in 0..4 {
            let qr = DVector::from_fn(q.len(), |i, _| q[i] + 0.2 * lcg.signed());
            let mu = eval.mu.map(|m| m * (1.0 + 0.5 * lcg.signed()));
            let mut ev = eval.clone();
            ev.mu = mu;
            assert!(sys.assemble_kkt(&qr, &part, &ev), "{name}");
            let general = values(&sys);
            // Shifts left in the values by a factorization must not survive either.
            if let Some(k) = sys.work.kkt.as_mut() {
                k.shift_independent(&part.independent, 0.3);
                k.factor(1e-3);
            }
            assert!(sys.assemble_fused(&qr, &part, &ev), "{name}: fused");
            // The compact blocks were laid in the block Hessian's buffer, given back empty
            // with its room (the next general assembly, below, restores the values).
            let hess = &sys.work.hess;
            assert!(hess.values.is_empty(), "{name}: values lent back empty");
            assert!(
                hess.values.capacity() >= hess.keys.len(),
                "{name}: room kept"
            );
            let fused = values(&sys);
            assert_eq!(general.len(), fused.len());
            let nonzero = general.iter().filter(|v| **v != 0.0).count();
            assert!(nonzero > 0, "{name}");
            for (s, (a, b)) in general.iter().zip(&fused).enumerate() {
                assert!(
                    a.to_bits() == b.to_bits(),
                    "{name}, pose {pose}: slot {s}: general {a:e}, fused {b:e}"
                );
            }
            assert_eq!(
                sys.kkt_scale(),
                {
                    assert!(sys.assemble_kkt(&qr, &part, &ev));
                    sys.kkt_scale()
                },
                "{name}"
            );
        }
    }
    assert!(fused_cases >= 6, "{fused_cases} models on the tree path");
}

/// Where the tree structure does not fit (a hub closing a loop onto each of nine links, all
/// hanging from the world: a border of 8 nodes above its limit, and a super-node of 9, module
/// `merge`, too; the general sparse KKT matrix), the fused pass declines and leaves that
/// matrix in place.
#[test]
fn fused_pass_leaves_a_sparse_kkt_matrix_in_place() {
    let inertial = "<inertial><origin xyz=\"0.1 0 0\"/><mass value=\"1\"/><inertia ixx=\"1e-4\" \
                    ixy=\"0\" ixz=\"0\" iyy=\"3.4e-3\" iyz=\"0\" izz=\"3.4e-3\"/></inertial>";
    let mut hub = String::from(
        "<?xml version=\"1.0\"?>\n<robot name=\"hub\" xmlns:mech=\"urn:urdf-mech:1\">\n  <link name=\"world\"/>\n",
    );
    // The hub last: the elimination takes it first (equal depths, higher index first).
    for (name, k) in (0..9)
        .map(|k| (format!("spoke{k}"), k))
        .chain([("hub".into(), 9)])
    {
        hub += &format!(
            "  <link name=\"{name}\">{inertial}</link>\n  <joint name=\"hang_{name}\" \
             type=\"continuous\"><parent link=\"world\"/><child link=\"{name}\"/><origin \
             xyz=\"0 {k} 0\"/><axis xyz=\"0 1 0\"/></joint>\n"
        );
    }
    for k in 0..9 {
        hub += &format!(
            "  <mech:loop_joint name=\"close{k}\" type=\"revolute\"><parent link=\"hub\"/>\
             <origin xyz=\"0.2 0 0\"/><child link=\"spoke{k}\"/><child_origin xyz=\"0.2 0 0\"/>\
             <axis xyz=\"0 1 0\"/></mech:loop_joint>\n"
        );
    }
    hub += "  <mech:gravity xyz=\"0 0 -9.81\"/>\n</robot>\n";
    let model = from_text(&hub);
    assert_eq!(model.joints.iter().filter(|j| !j.tree).count(), 9);
    let mut sys = System::new(&model, Constraints::new(&model, &[]), Backend::Tree);
    let q = crate::solver::initial_state(&model).q;
    let part = sys.partition(&q);
    let eval = sys.evaluate(&q, &part).expect("evaluates");
    assert!(sys.assemble_kkt(&q, &part, &eval));
    assert!(matches!(sys.work.kkt, Some(KktMatrix::Sparse(_))));
    assert!(!sys.assemble_fused(&q, &part, &eval));
    assert!(matches!(sys.work.kkt, Some(KktMatrix::Sparse(_))));
}
