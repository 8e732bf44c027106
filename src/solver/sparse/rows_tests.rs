//! Tests of the rows kept between partitions ([`Rows::refill`]): refilled at another
//! configuration (where terms turn zero or nonzero), they equal the rows built afresh there to
//! the bit, and a partition with a kept workspace equals a fresh one, also when the workspace
//! comes from another system (the rope's contacts changing).

use super::Rows;
use crate::constraints::Constraints;
use crate::model::Model;
use crate::solver::sparse::fill_free::{partition, Workspace};
use crate::solver::system::{Backend, System};
use crate::urdf::{load_str, ImportOptions};
use nalgebra::DVector;

fn model(text: &str) -> Model {
    load_str(text, "m.urdf", &ImportOptions::default())
        .unwrap()
        .model
}

/// The triplets of `sys` at `q`.
fn triplets(sys: &mut System, q: &DVector<f64>) -> Vec<(usize, usize, f64)> {
    sys.triplets(q);
    sys.work.jac.entries.clone()
}

/// `q` moved off its start by a few hundredths on every coordinate.
fn moved(q: &DVector<f64>) -> DVector<f64> {
    DVector::from_fn(q.len(), |i, _| q[i] + 0.03 * ((i as f64) * 0.7).sin())
}

fn assert_same(kept: &Rows, fresh: &Rows, m: usize, name: &str) {
    let bits = |row: &[(usize, f64)]| row.iter().map(|e| (e.0, e.1.to_bits())).collect::<Vec<_>>();
    for r in 0..m {
        assert_eq!(bits(kept.row(r)), bits(fresh.row(r)), "{name}: row {r}");
        assert_eq!(kept.bodies(r), fresh.bodies(r), "{name}: row {r}");
        assert_eq!(
            kept.rmax[r].to_bits(),
            fresh.rmax[r].to_bits(),
            "{name}: row {r}"
        );
        assert_eq!(kept.own_of[r], fresh.own_of[r], "{name}: row {r}");
        let reach = |x: [f64; 2]| x.map(f64::to_bits);
        assert_eq!(
            reach(kept.reach[r]),
            reach(fresh.reach[r]),
            "{name}: row {r}"
        );
    }
    assert_eq!(kept.body_start, fresh.body_start, "{name}");
    assert_eq!(kept.body_rows, fresh.body_rows, "{name}");
}

fn assert_same_partition(
    model: &Model,
    sys: &System,
    entries: &[(usize, usize, f64)],
    work: &mut Workspace,
    name: &str,
) {
    let (m, n) = (sys.problem.cons.len(), 7 * model.bodies.len());
    let (rs, cs) = (&sys.problem.scaling.rows, &sys.problem.scaling.columns);
    let kept = partition(model, m, n, entries, rs, cs, work);
    let fresh = partition(model, m, n, entries, rs, cs, &mut Workspace::default());
    assert_eq!(kept.is_some(), fresh.is_some(), "{name}");
    if let (Some(a), Some(b)) = (kept, fresh) {
        assert_eq!(a.dependent, b.dependent, "{name}");
        assert_eq!(a.independent, b.independent, "{name}");
        assert_eq!(a.rows, b.rows, "{name}");
        assert_eq!(a.redundant, b.redundant, "{name}");
        assert_eq!(a.second_pass, b.second_pass, "{name}");
    }
}

/// A chain and a ladder at their start (identity orientations: many zero terms) and moved off
/// it, back and forth: the refilled rows and the partitions equal fresh ones.
#[test]
fn refilled_rows_equal_fresh_ones_as_zeros_change() {
    for (name, text) in [
        ("chain", crate::generate::chain(9, false)),
        ("ladder", crate::generate::ladder(5)),
    ] {
        let model = model(&text);
        let q0 = crate::solver::initial_state(&model).q;
        let q1 = moved(&q0);
        let mut sys = System::new(&model, Constraints::new(&model, &[]), Backend::Sparse);
        let (m, n) = (sys.problem.cons.len(), q0.len());
        let (rs, cs) = (
            sys.problem.scaling.rows.clone(),
            sys.problem.scaling.columns.clone(),
        );
        let (e0, e1) = (triplets(&mut sys, &q0), triplets(&mut sys, &q1));
        let zeros = |e: &[(usize, usize, f64)]| e.iter().filter(|t| t.2 == 0.0).count();
        assert_ne!(zeros(&e0), zeros(&e1), "{name}: the zeros change");
        let mut kept = Rows::new(m, n, &e0, &rs, &cs).unwrap();
        let mut work = Workspace::default();
        for (step, e) in [&e0, &e1, &e0, &e1].into_iter().enumerate() {
            let fresh = Rows::new(m, n, e, &rs, &cs).unwrap();
            assert!(kept.refill(m, n, e, &rs, &cs), "{name}: step {step}");
            assert_same(&kept, &fresh, m, &format!("{name} step {step}"));
            assert_same_partition(&model, &sys, e, &mut work, &format!("{name} step {step}"));
        }
    }
}

/// The rope with its contacts changing: a workspace kept from the rope with the touching
/// contacts active, then used on the rope without them and with them again at another
/// configuration, gives the partitions of fresh workspaces (the refill refuses the other
/// system's pattern and the rows are built afresh).
#[test]
fn a_workspace_from_another_active_set_gives_fresh_partitions() {
    use crate::constraints::unilateral::gap;
    use crate::solver::inequality::active_set::{activate, inequalities};
    let model = model(&crate::generate::rope(60));
    let q0 = crate::solver::initial_state(&model).q;
    let q = crate::solver::assemble_only(&model, q0, &mut Default::default(), &[]).unwrap();
    let options = crate::solver::Options::default();
    let active: Vec<_> = inequalities(&model, &options)
        .into_iter()
        .filter(|u| gap(&model, u, &q, &Default::default()).is_some_and(|g| g.abs() < 1e-9))
        .map(|u| activate(&model, &options, u, &q))
        .collect();
    assert!(!active.is_empty());
    let mut with = System::new(
        &model,
        Constraints::new(&model, &[]).with_active(&model, &active),
        Backend::Sparse,
    );
    let mut without = System::new(&model, Constraints::new(&model, &[]), Backend::Sparse);
    assert_ne!(with.problem.cons.len(), without.problem.cons.len());
    let q1 = moved(&q);
    let mut work = Workspace::default();
    let e = triplets(&mut with, &q);
    assert_same_partition(&model, &with, &e, &mut work, "with contacts");
    let e = triplets(&mut without, &q);
    assert_same_partition(&model, &without, &e, &mut work, "without contacts");
    let e = triplets(&mut with, &q1);
    assert_same_partition(&model, &with, &e, &mut work, "with contacts, moved");
    let e = triplets(&mut with, &q);
    assert_same_partition(&model, &with, &e, &mut work, "with contacts, back");
}
