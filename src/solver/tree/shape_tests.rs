//! The KKT structure built fast (`Shape::new`) against the reference construction
//! (`Shape::build` with `fast` false: each triplet coupled and located on its own, the border
//! completed before its size is tested, both slots of a triplet flagged on their own, the bare
//! diagonal from every block slot): every field equal (nodes, parents, widths, slots, first
//! flags, border) on chains, a chain with locks (extra rows on bodies), a branched tree, a rope,
//! loops (a spatial four-bar and a short ladder: the border) and long ladders (super-nodes,
//! the border abandoned as soon as it overflows).
use super::shape::Shape;
use crate::constraints::Constraints;
use crate::model::{JointId, Model};
use crate::solver::system::{Backend, System};
use crate::urdf::{load_file, load_str, ImportOptions};

/// Joint locks `(joint, coordinate, value)`.
type Locks = Vec<(JointId, usize, f64)>;

fn from_text(text: &str) -> Model {
    load_str(text, "shape.urdf", &ImportOptions::default())
        .expect("model loads")
        .model
}

/// The structure of `model` (with `locks`) at its assembled point, by both constructions;
/// returns the border size and the node count.
fn compare(name: &str, model: &Model, locks: &[(JointId, usize, f64)]) -> (usize, usize) {
    let q0 = crate::solver::initial_state(model).q;
    let q =
        crate::solver::assemble_only(model, q0, &mut Default::default(), &[]).expect("assembles");
    let mut sys = System::new(model, Constraints::new(model, locks), Backend::Tree);
    let part = sys.partition(&q);
    let eval = sys.evaluate(&q, &part).expect("evaluates");
    sys.kkt_blocks(&q, &part, &eval);
    let (m, n) = (sys.problem.cons.len(), q.len());
    let (entries, hess) = (&sys.work.jac.entries, &sys.work.hess);
    let fast = Shape::new(&part, m, n, entries, hess);
    let slow = Shape::build(&part, m, n, entries, hess, false);
    assert_eq!(fast.is_some(), slow.is_some(), "{name}: fits");
    let (Some(fast), Some(slow)) = (fast, slow) else {
        panic!("{name}: no tree structure");
    };
    // The same slot for every triplet, whether by runs or one by one.
    assert_eq!(fast.jac_slots(), slow.jac_slots(), "{name}: Jacobian slots");
    assert_eq!(fast.jac_slots().len(), entries.len(), "{name}");
    let lined: u32 = fast
        .jac_runs
        .iter()
        .filter(|r| r.step != super::jac_runs::EACH && r.slot != super::shape::SKIP)
        .map(|r| r.len)
        .sum();
    let (mut fast, mut slow) = (fast, slow);
    for s in [&mut fast, &mut slow] {
        s.jac_each = s.jac_slots();
        s.jac_runs = vec![super::jac_runs::JacRun {
            len: entries.len() as u32,
            slot: 0,
            mirror: 0,
            step: super::jac_runs::EACH,
        }];
    }
    assert_eq!(fast, slow, "{name}");
    // On a tree, the fast construction places almost every triplet by runs.
    if fast.border.size() == 0 && !name.contains("ladder") {
        assert!(
            lined as usize * 10 >= entries.len() * 9,
            "{name}: {lined} of {} triplets in runs",
            entries.len()
        );
    }
    (fast.border.size(), fast.at.len())
}

#[test]
fn fast_shape_equals_the_reference_construction() {
    let solo12 = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/robots/solo12/solo12_ground.urdf"
    );
    let solo12 = load_file(solo12, &ImportOptions::default())
        .expect("solo12 loads")
        .model;
    let cases: Vec<(&str, Model, Locks)> = vec![
        (
            "chain",
            from_text(&crate::generate::chain(40, false)),
            vec![],
        ),
        (
            "planar chain",
            from_text(&crate::generate::chain(15, true)),
            vec![],
        ),
        (
            "chain with locks",
            from_text(&crate::generate::chain(9, false)),
            vec![(JointId(2), 0, 0.2), (JointId(6), 0, -0.1)],
        ),
        ("solo12", solo12, vec![]),
        ("rope", from_text(&crate::generate::rope(20)), vec![]),
        (
            "four-bar",
            from_text(include_str!("../../../robots/four_bar_spatial.urdf")),
            vec![],
        ),
        ("ladder", from_text(&crate::generate::ladder(3)), vec![]),
        (
            "long ladder",
            from_text(&crate::generate::ladder(30)),
            vec![],
        ),
        (
            "longer ladder",
            from_text(&crate::generate::ladder(120)),
            vec![],
        ),
    ];
    for (name, model, locks) in cases {
        let (border, nodes) = compare(name, &model, &locks);
        let loops = matches!(name, "four-bar" | "ladder");
        assert_eq!(border > 0, loops, "{name}: border {border}");
        // The long ladder's loops merge bodies into super-nodes: fewer nodes than bodies.
        if matches!(name, "long ladder" | "longer ladder") {
            assert!(nodes < model.bodies.len(), "{name}: {nodes} nodes");
        }
    }
}
