//! The rows read straight from the triplets (module `tree`) against the general route of
//! module `fill_free` (`by_rows`: the rows expanded, kept copies followed): the same pivots, in
//! the same order, wherever the tree route answers; and it answers on chains, branched trees and
//! a tree of every joint kind a tree may hold, at the assembled initial guess (where about half
//! of the triplets are zero), off it, and with a lock on joint coordinates.

use super::{by_rows, tree, Pivots};
use crate::constraints::{Constraints, Triplets};
use crate::model::Model;
use crate::solver::sparse::partition::elimination_order;
use crate::solver::system::Problem;
use crate::urdf::{load_str, ImportOptions};

/// A link with a mass (`name`).
fn link(name: &str) -> String {
    format!(
        r#"<link name="{name}"><inertial><origin xyz="0.1 0.02 -0.3"/><mass value="1.5"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.2" iyz="0" izz="0.3"/></inertial></link>"#
    )
}

/// A tree of every joint kind a tree may hold: a base on a revolute joint, from it one branch
/// per kind (URDF and Drake joints), each with a revolute grandchild.
fn every_kind() -> String {
    let mut t = String::from(
        r#"<robot name="kinds" xmlns:drake="http://drake.mit.edu"><link name="world"/>"#,
    );
    t += &link("base");
    t += r#"<joint name="root" type="revolute"><parent link="world"/><child link="base"/><origin xyz="0 0 2" rpy="0.1 0 0"/><axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>"#;
    let kinds = [
        (
            "joint",
            "revolute",
            r#"<axis xyz="1 0 0"/><limit lower="-3" upper="3" effort="1" velocity="1"/>"#,
        ),
        ("joint", "continuous", r#"<axis xyz="0 0.6 0.8"/>"#),
        (
            "joint",
            "prismatic",
            r#"<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/>"#,
        ),
        ("joint", "fixed", ""),
        ("joint", "floating", ""),
        ("joint", "planar", r#"<axis xyz="0 1 0"/>"#),
        ("joint", "spherical", ""),
        ("drake:joint", "universal", ""),
        (
            "drake:joint",
            "screw",
            r#"<axis xyz="0 0 1"/><drake:screw_thread_pitch value="0.01"/>"#,
        ),
    ];
    for (k, (tag, kind, extra)) in kinds.iter().enumerate() {
        let (a, b) = (format!("a{k}"), format!("b{k}"));
        t += &link(&a);
        t += &link(&b);
        t += &format!(
            r#"<{tag} name="j{k}" type="{kind}"><parent link="base"/><child link="{a}"/><origin xyz="0.{k} 0.3 -0.2" rpy="0 0.{k} 0.2"/>{extra}</{tag}>"#
        );
        t += &format!(
            r#"<joint name="g{k}" type="revolute"><parent link="{a}"/><child link="{b}"/><origin xyz="0 0 -0.4"/><axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>"#
        );
    }
    t + "</robot>"
}

/// The scaled Jacobian's triplets of `model` with a lock on the first coordinate of every
/// `lock_every`-th joint (none where 0) at `q`, and its scales.
fn jacobian<'a>(
    model: &'a Model,
    lock_every: usize,
    q: &nalgebra::DVector<f64>,
) -> (Triplets, Problem<'a>) {
    let locks: Vec<_> = if lock_every == 0 {
        Vec::new()
    } else {
        (0..model.joints.len())
            .step_by(lock_every)
            .filter(|&j| !model.joints[j].kind.value_counts().is_empty())
            .map(|j| (crate::model::JointId(j), 0, 0.1))
            .collect()
    };
    let problem = Problem::new(model, Constraints::new(model, &locks));
    let mut phi = nalgebra::DVector::zeros(problem.cons.len());
    let mut jac = Triplets::default();
    problem.cons.evaluate(model, q, &mut phi, Some(&mut jac));
    (jac, problem)
}

/// Both routes' pivots for `model` at `q` (the tree route's `None` where it gives way).
fn both(
    model: &Model,
    lock_every: usize,
    q: &nalgebra::DVector<f64>,
) -> (Option<Pivots>, Option<Pivots>) {
    let (jac, problem) = jacobian(model, lock_every, q);
    let order = elimination_order(model);
    let s = &problem.scaling;
    let args = (
        jac.rows,
        jac.cols,
        &jac.entries[..],
        &s.rows[..],
        &s.columns[..],
    );
    (
        tree::eliminate(&order, args.0, args.1, args.2, args.3, args.4),
        by_rows(&order, args.0, args.1, args.2, args.3, args.4),
    )
}

#[test]
fn the_tree_route_pivots_as_the_general_route() {
    let plain = ImportOptions::default();
    // Each on a fixed base and on a floating one.
    let models = [
        ("chain 9", crate::generate::chain(9, false)),
        ("planar chain 120", crate::generate::chain(120, true)),
        ("chain 300", crate::generate::chain(300, false)),
        ("every kind", every_kind()),
        (
            "panda",
            include_str!("../../../../robots/panda_class.urdf").to_string(),
        ),
        (
            "ur5",
            include_str!("../../../../robots/ur5_class.urdf").to_string(),
        ),
        (
            "quadruped leg",
            include_str!("../../../../robots/quadruped_leg.urdf").to_string(),
        ),
        (
            "transmission",
            include_str!("../../../../robots/gazebo_transmission.urdf").to_string(),
        ),
    ];
    // Cases the tree route answered.
    let mut answered = 0;
    let floating = ImportOptions {
        floating_base: true,
        ..Default::default()
    };
    for ((name, text), base) in models.iter().flat_map(|m| [(m, &plain), (m, &floating)]) {
        let model = load_str(text, "m.urdf", base).unwrap().model;
        let q0 = crate::solver::initial_state(&model).q;
        let q = crate::solver::assemble_only(&model, q0, &mut Default::default(), &[])
            .expect("assembles");
        // Off the assembled point: every coordinate moved (no triplet zero by symmetry).
        let off = q.map_with_location(|i, _, x| x + 1e-2 * ((i % 7) as f64 - 3.0));
        for (at, q) in [("at rest", &q), ("off", &off)] {
            for lock_every in [0, 1, 3] {
                let (fast, general) = both(&model, lock_every, q);
                let general = general.expect("the general route answers");
                match fast {
                    Some(fast) => {
                        assert_eq!(fast, general, "{name} {at}, locks {lock_every}");
                        answered += 1;
                    }
                    // Panda with locks leaves a row active at a body (as its locked system
                    // in module `verify`'s rank tests): the tree route gives way there.
                    None => assert!(
                        *name == "panda" && lock_every > 0,
                        "{name} {at}, locks {lock_every}: the tree route gives way"
                    ),
                }
            }
        }
    }
    // All but Panda's 8 cases with locks (2 bases, 2 points, 2 lock sets).
    assert_eq!(answered, 2 * 8 * 2 * 3 - 8);
}

/// Where the general route keeps a row (a ladder's loop rows) or the triplets are out of
/// order, the tree route gives way; a column twice in a row is summed as the general route
/// sums it.
#[test]
fn the_tree_route_gives_way() {
    let model = load_str(
        &crate::generate::ladder(4),
        "m.urdf",
        &ImportOptions::default(),
    )
    .unwrap()
    .model;
    let q = crate::solver::initial_state(&model).q;
    let (fast, general) = both(&model, 0, &q);
    assert!(fast.is_none() && general.is_some());
    let model = load_str(
        &crate::generate::chain(3, false),
        "m.urdf",
        &ImportOptions::default(),
    )
    .unwrap()
    .model;
    let q = crate::solver::initial_state(&model).q;
    let (jac, problem) = jacobian(&model, 0, &q);
    let s = &problem.scaling;
    let order = elimination_order(&model);
    let both = |entries: &[crate::constraints::Triplet]| {
        let (m, n) = (jac.rows, jac.cols);
        (
            tree::eliminate(&order, m, n, entries, &s.rows, &s.columns),
            by_rows(&order, m, n, entries, &s.rows, &s.columns),
        )
    };
    // A column twice in a row: a sum, and a sum that cancels.
    let t = jac
        .entries
        .iter()
        .position(|e| e.2 != 0.0)
        .expect("a nonzero entry");
    let e = jac.entries[t];
    for v in [0.5, -e.2] {
        let mut entries = jac.entries.clone();
        entries.insert(t + 1, (e.0, e.1, v));
        let (fast, general) = both(&entries);
        assert_eq!(fast.expect("answers"), general.expect("answers"), "{v}");
    }
    // Rows out of order.
    let mut entries = jac.entries.clone();
    let last = entries.len() - 1;
    entries.swap(0, last);
    assert!(both(&entries).0.is_none());
}
