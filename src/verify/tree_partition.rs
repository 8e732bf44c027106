//! The self-check's locked system partitioned as a tree, from its structure alone.
//!
//! With every joint coordinate of a tree locked, each body `b` owns seven rows: its joint's
//! rows (five for a revolute or prismatic joint), its normalization `pᵀp − 1 = 0` and its
//! joint's lock `θ(q) − θ = 0`. A row's **home** is the body it touches first in the
//! elimination order (leaves first, `sparse::partition::elimination_order`): the joint's and
//! the lock's child, the normalization's body. Where every body is home to exactly seven rows,
//!
//! `Φ_u = [A_ij]`,   `A_ij` = the rows of body `i` on the columns of body `j`,
//!
//! is block upper triangular in that order (a row reaches its home and, through a joint, the
//! parent, which comes later) with square `7 × 7` diagonal blocks: every coordinate is
//! dependent, no row is redundant, and `Φ_uᵀ μ = ∇_u V` is solved node by node by the tree
//! factors (module `solver::tree::phi_u`, one LU with partial pivoting per diagonal block).
//!
//! This is the partition the fill-free elimination (`solver::sparse::fill_free`) finds there
//! (the same rows and columns in each node, each body's block being nonsingular at an
//! assembled pose: the joint's rows fix the child's position and its rotation off the axis,
//! the normalization the parameters' length, the lock the angle about the axis), read off the
//! triplets in one pass instead of chosen by magnitude: the pivots' order inside a node differs,
//! so the multipliers agree with that partition's to rounding. Anything else (a floating
//! base, whose root owns one row; loops, mimics, stops or contacts, which give a body more than
//! seven rows; a row without entries; a joint of two or three coordinates) is left to the
//! general partition (`None`), as is a pose where a block is singular (the caller's evaluation
//! fails and it partitions again).

use crate::constraints::Triplet;
use crate::forces::Energy;
use crate::model::Model;
use crate::solver::partition::{next_id, Partition};
use crate::solver::system::{Eval, System};
use nalgebra::DVector;

/// The locked system's partition by bodies (module docs) for the `m` rows with Jacobian
/// triplets `entries` on the `n` coordinates of `model`, or `None` where some body is not home
/// to exactly seven rows.
pub(super) fn partition(
    model: &Model,
    m: usize,
    n: usize,
    entries: &[Triplet],
) -> Option<Partition> {
    // Seven rows a body: as many rows as coordinates (the ladder's loop rows, a floating
    // base's missing joint rows fail this before any work).
    // And one coordinate a joint: the lock of an angle about an axis or a length along it
    // never depends on the joint's rows, where two or three coordinates of a joint (universal,
    // cylindrical, planar) have configurations at which their locks do.
    let nb = model.bodies.len();
    if n != 7 * nb
        || m != n
        || model
            .joints
            .iter()
            .any(|j| j.tree && !j.merged && j.kind.scalar_coordinates() != 1)
    {
        return None;
    }
    let order = crate::solver::sparse::partition::elimination_order(model);
    let mut rank = vec![0u32; nb];
    for (k, &b) in order.iter().enumerate() {
        rank[b] = k as u32;
    }
    // Each row's home: the least rank among the bodies of its entries.
    let mut home = vec![u32::MAX; m];
    for &(r, c, _) in entries {
        let k = rank[c as usize / 7];
        let h = &mut home[r as usize];
        if k < *h {
            *h = k;
        }
    }
    // The rows by home, ascending within each body (a counting sort).
    let mut start = vec![0usize; nb + 1];
    for &h in &home {
        if h == u32::MAX {
            return None;
        }
        start[h as usize + 1] += 1;
    }
    for k in 0..nb {
        if start[k + 1] != 7 {
            return None;
        }
        start[k + 1] += start[k];
    }
    let mut rows = vec![0usize; m];
    for (r, &h) in home.iter().enumerate() {
        let at = &mut start[h as usize];
        rows[*at] = r;
        *at += 1;
    }
    let dependent = order.iter().flat_map(|&b| 7 * b..7 * b + 7).collect();
    Some(Partition {
        id: next_id(),
        dependent,
        independent: Vec::new(),
        rows,
        redundant: Vec::new(),
        second_pass: Vec::new(),
    })
}

/// The partition of `sys` at `q` and its evaluation with `known` `V`, `∇V` (module
/// `model_rows`): with `by_bodies`, by bodies where that applies (as many rows as
/// coordinates first) and its blocks factor; otherwise (and then) the general partition.
///
/// # Errors
/// The general partition's rank where its `Φ_u` is singular.
pub(super) fn evaluated(
    sys: &mut System,
    q: &DVector<f64>,
    known: Option<(Energy, DVector<f64>)>,
    by_bodies: bool,
) -> Result<(Partition, Eval), usize> {
    let (m, n) = (sys.problem.cons.len(), q.len());
    if by_bodies && m == n {
        // Installed rows are the triplets at `q` already.
        if known.is_none() {
            sys.triplets(q);
        }
        let model = sys.problem.model;
        if let Some(part) = partition(model, m, n, &sys.work.jac.entries) {
            if let Some(eval) = sys.evaluate_knowing(q, &part, known.clone()) {
                return Ok((part, eval));
            }
        }
    }
    let part = sys.partition(q);
    match sys.evaluate_knowing(q, &part, known) {
        Some(eval) => Ok((part, eval)),
        None => Err(part.rows.len()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::constraints::Constraints;
    use crate::solver::system::Backend;
    use crate::verify::test_support::model;

    /// The locked system of `model` at `state` (every joint coordinate locked, as module
    /// `held` builds it), its triplets evaluated.
    fn locked<'a>(model: &'a Model, state: &crate::state::State) -> System<'a> {
        let mut all = crate::solver::lock_values(model);
        all.extend(super::super::run::tree_coordinates(model, state));
        let cons = Constraints::new(model, &all).on_branches(state.branches.clone());
        let mut sys = System::new(model, cons, Backend::Tree);
        sys.triplets(&state.q);
        sys
    }

    /// `model` with every one-coordinate tree joint turned off its initial value.
    fn bent(model: &Model) -> crate::state::State {
        let values: crate::state::JointValues = model
            .joints
            .iter()
            .enumerate()
            .filter(|(_, j)| j.tree && !j.merged && j.kind.scalar_coordinates() == 1)
            .map(|(i, j)| (j.name.clone(), vec![0.06 * ((i * 37 % 11) as f64 - 5.0)]))
            .collect();
        super::super::pose_state(model, &values).unwrap().0
    }

    /// On chains and a branched tree, bent: the partition by bodies has the general
    /// partition's rows and columns node by node (the same sets, every coordinate dependent,
    /// nothing redundant), and its multipliers and reduced gradient are the general
    /// partition's to rounding.
    #[test]
    fn the_tree_partition_has_the_general_partitions_nodes_and_multipliers() {
        let branched = r#"<robot name="y">
  <link name="world"/><link name="a"><inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="b"><inertial><origin xyz="0.2 0 0"/><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="c"><inertial><origin xyz="0 0.3 0"/><mass value="2"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="ja" type="revolute"><parent link="world"/><child link="a"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="jb" type="continuous"><parent link="a"/><child link="b"/><origin xyz="0.5 0 0"/><axis xyz="0 1 0"/></joint>
  <joint name="jc" type="prismatic"><parent link="a"/><child link="c"/><origin xyz="0 0 -0.4"/><axis xyz="1 0 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>"#;
        for text in [
            crate::generate::chain(12, false),
            crate::generate::chain(60, false),
            branched.to_string(),
        ] {
            let model = model(&text, false);
            let state = bent(&model);
            let mut sys = locked(&model, &state);
            let (m, n) = (sys.problem.cons.len(), state.q.len());
            let ours = partition(&model, m, n, &sys.work.jac.entries).expect("a tree");
            let general = sys.partition(&state.q);
            assert!(general.redundant.is_empty() && general.independent.is_empty());
            assert_eq!(ours.rows.len(), general.rows.len());
            for k in (0..n).step_by(7) {
                let set = |v: &[usize]| {
                    let mut s = v[k..k + 7].to_vec();
                    s.sort_unstable();
                    s
                };
                assert_eq!(
                    set(&ours.rows),
                    set(&general.rows),
                    "{} node {k}",
                    model.name
                );
                assert_eq!(
                    set(&ours.dependent),
                    set(&general.dependent),
                    "{} node {k}",
                    model.name
                );
            }
            let g = sys.evaluate(&state.q, &general).unwrap();
            let o = sys.evaluate(&state.q, &ours).unwrap();
            let mu = |e: &crate::solver::system::Eval, p: &Partition| {
                let mut mu = DVector::zeros(m);
                for (k, &r) in p.rows.iter().enumerate() {
                    mu[r] = e.mu[k];
                }
                mu
            };
            let (mg, mo) = (mu(&g, &general), mu(&o, &ours));
            let scale = mg.amax();
            assert!(scale > 1.0, "{}: {scale}", model.name);
            assert!(
                (&mg - &mo).amax() <= 1e-12 * scale,
                "{}: {:e} of {scale:e}",
                model.name,
                (&mg - &mo).amax()
            );
        }
    }

    /// Left to the general partition: a floating base (its root owns its normalization
    /// alone), a ladder (a loop's rows), a chain with a mimic joint.
    #[test]
    fn other_structures_are_left_to_the_general_partition() {
        let cases = [
            (crate::generate::chain(12, false), true),
            (crate::generate::ladder(3), false),
            (
                include_str!("../../robots/panda_class.urdf").to_string(),
                false,
            ),
        ];
        for (text, floating) in cases {
            let model = model(&text, floating);
            let state = crate::state::State::initial(&model);
            let sys = locked(&model, &state);
            let (m, n) = (sys.problem.cons.len(), state.q.len());
            assert!(
                partition(&model, m, n, &sys.work.jac.entries).is_none(),
                "{}",
                model.name
            );
        }
    }
}
