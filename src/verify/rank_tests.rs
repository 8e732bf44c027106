//! The sparse partition on dense copies against the general sparse elimination, on the systems
//! `verify` and `check` build. `System::partition` runs the elimination on dense copies of each
//! body's rows (`solver::sparse::fill_free`) wherever that route answers (trees, ladders), the
//! general sparse elimination (`sparse::partition`) otherwise, and must give the same
//! `Partition` either way (to the last index, so the factors and every number computed from
//! them are the same to the bit): `verify`'s locked system (the model's rows and a lock row per
//! joint coordinate) and `check`'s count of free columns take it from there. Checked on every
//! model of the test set, with and without a lock on every joint coordinate.

use crate::constraints::Constraints;
use crate::solver::system::{Backend, System};
use crate::urdf::{load_str, ImportOptions};

/// `(free columns of this module, of the sparse partition)` at the assembled initial guess.
fn both(text: &str, options: &ImportOptions) -> (Option<usize>, usize) {
    let model = load_str(text, "m.urdf", options).unwrap().model;
    let locks = crate::solver::lock_values(&model);
    let mut branches = Default::default();
    let q0 = crate::solver::initial_state(&model).q;
    let q = crate::solver::assemble_only(&model, q0, &mut branches, &locks).unwrap();
    let cons = Constraints::new(&model, &locks).on_branches(branches);
    let mut sys = System::new(&model, cons, Backend::Sparse);
    let mut phi = nalgebra::DVector::zeros(sys.problem.cons.len());
    let mut jac = crate::constraints::Triplets::default();
    sys.problem
        .cons
        .evaluate(&model, &q, &mut phi, Some(&mut jac));
    let s = &sys.problem.scaling;
    let fast = crate::solver::sparse::fill_free::free_columns(
        &model,
        jac.rows,
        jac.cols,
        &jac.entries,
        &s.rows,
        &s.columns,
    );
    (fast, general(&mut sys, &q).independent.len())
}

/// The general sparse elimination of the rows of `sys` at `q` (what `System::partition` gave
/// before the dense copies).
fn general(sys: &mut System, q: &nalgebra::DVector<f64>) -> crate::solver::partition::Partition {
    sys.triplets(q);
    let (jac, s) = (&sys.work.jac, &sys.problem.scaling);
    crate::solver::sparse::partition::partition(
        sys.problem.model,
        jac.rows,
        jac.cols,
        &jac.entries,
        &s.rows,
        &s.columns,
    )
}

/// Trees (on which the fill-free route answers) and closed loops of the test set.
fn models() -> (Vec<String>, Vec<String>) {
    let trees = vec![
        include_str!("../../robots/pendulum.urdf").to_string(),
        include_str!("../../robots/chain20.urdf").to_string(),
        include_str!("../../robots/panda_class.urdf").to_string(),
        include_str!("../../robots/ur5_class.urdf").to_string(),
        include_str!("../../robots/quadruped_leg.urdf").to_string(),
        include_str!("../../robots/gazebo_transmission.urdf").to_string(),
        include_str!("../../robots/solo12/solo12_ground.urdf").to_string(),
        crate::generate::chain(9, false),
        crate::generate::chain(120, false),
        crate::generate::chain(120, true),
        crate::generate::chain(2000, false),
        crate::generate::rope(12),
    ];
    let loops = vec![
        include_str!("../../robots/slider_crank.urdf").to_string(),
        include_str!("../../robots/four_bar_spatial.urdf").to_string(),
        include_str!("../../robots/stewart_platform.urdf").to_string(),
        include_str!("../../robots/drake_closed_chain.urdf").to_string(),
        include_str!("../../robots/tractor_trailer.urdf").to_string(),
        crate::generate::ladder(5),
        crate::generate::ladder(40),
    ];
    (trees, loops)
}

/// The import options of the test set: a fixed base, then a floating one.
fn bases() -> [ImportOptions; 2] {
    let floating = ImportOptions {
        floating_base: true,
        ..Default::default()
    };
    [ImportOptions::default(), floating]
}

/// Same count as the partition wherever the dense copies answer; they answer on every tree and
/// on the ladders.
#[test]
fn same_free_columns_as_the_sparse_partition() {
    let (trees, loops) = models();
    let [plain, floating] = bases();
    for (k, t) in trees.iter().enumerate() {
        for o in [&plain, &floating] {
            let (fast, partition) = both(t, o);
            assert_eq!(fast, Some(partition), "tree {k}");
        }
    }
    for (k, t) in loops.iter().enumerate() {
        let (fast, partition) = both(t, &plain);
        assert!(fast.is_none_or(|f| f == partition), "loop {k}");
        // The ladders' loops: each level's rows resolved within its three bodies.
        assert!(k < 5 || fast.is_some(), "loop {k}");
    }
}

/// The structural count of `check` (`n − m` on trees of joints with independent rows) is the
/// partition's wherever it answers; it answers on the chains, the rope and the floating
/// bases, not on closed loops or with a lock, and `check` reports it.
#[test]
fn structural_count_is_the_partition_count() {
    let (trees, loops) = models();
    let [plain, floating] = bases();
    let structural = |t: &str, o: &ImportOptions| {
        let model = load_str(t, "m.urdf", o).unwrap().model;
        let cons = Constraints::new(&model, &crate::solver::lock_values(&model));
        let n = crate::solver::initial_state(&model).q.len();
        let dof = super::initial_guess::tree_dof(&model, &cons, n);
        (dof, super::check(&model).dof)
    };
    let mut answered = 0;
    for (k, t) in trees.iter().enumerate() {
        for o in [&plain, &floating] {
            let (dof, checked) = structural(t, o);
            let (_, partition) = both(t, o);
            assert!(dof.is_none_or(|d| d == partition), "tree {k}");
            assert_eq!(checked, Some(partition), "tree {k}");
            answered += usize::from(dof.is_some());
        }
    }
    assert!(answered >= 16, "{answered}");
    for k in [1, 7, 8, 9, 10, 11] {
        assert!(structural(&trees[k], &plain).0.is_some(), "tree {k}");
    }
    for (k, t) in loops.iter().enumerate() {
        assert_eq!(structural(t, &plain).0, None, "loop {k}");
    }
    let locked = ImportOptions {
        locks: vec![("joint3".to_string(), 0, None)],
        ..Default::default()
    };
    assert_eq!(structural(&trees[8], &locked).0, None);
}

/// Lock rows (on the joint's own body) and a redundant lock: the same count as the
/// partition, the redundant row found as there.
#[test]
fn locks_and_a_redundant_lock() {
    let chain = crate::generate::chain(60, false);
    let lock = |joint: &str| (joint.to_string(), 0, None);
    let one = ImportOptions {
        locks: vec![lock("joint0"), lock("joint30")],
        ..Default::default()
    };
    let (fast, partition) = both(&chain, &one);
    assert_eq!(fast, Some(partition));
    assert_eq!(partition, 58);
    let twice = ImportOptions {
        locks: vec![lock("joint7"), lock("joint7")],
        ..Default::default()
    };
    let (fast, partition) = both(&chain, &twice);
    assert_eq!(partition, 59);
    assert_eq!(fast, Some(partition));
}

/// The partition of `System::partition` against the general sparse
/// elimination's at the
/// assembled initial guess of `text` and at a pose off it (each coordinate moved): all but
/// the id equal. `locked`: with a lock on every joint coordinate scaled down as module `held`
/// does (its locked system). Returns whether the fill-free route answered.
fn same_partition(text: &str, options: &ImportOptions, locked: bool) -> bool {
    let model = load_str(text, "m.urdf", options).unwrap().model;
    let locks = crate::solver::lock_values(&model);
    let mut branches = Default::default();
    let q0 = crate::solver::initial_state(&model).q;
    let q = crate::solver::assemble_only(&model, q0, &mut branches, &locks).unwrap();
    let state = crate::state::State { q, branches };
    let mut all = locks.clone();
    if locked {
        let coords = super::run::tree_coordinates(&model, &state);
        all.extend(
            coords
                .into_iter()
                .filter(|c| !locks.iter().any(|l| l.0 == c.0 && l.1 == c.1)),
        );
    }
    let off = state
        .q
        .map_with_location(|i, _, x| x + 1e-3 * ((i % 5) as f64 - 2.0));
    let mut answered = true;
    for q in [&state.q, &off] {
        let cons = Constraints::new(&model, &all).on_branches(state.branches.clone());
        let lock_rows: Vec<usize> = cons
            .blocks
            .iter()
            .filter(|b| matches!(b.kind, crate::constraints::BlockKind::Lock { .. }))
            .map(|b| b.first)
            .collect();
        let mut sys = System::new(&model, cons, Backend::Sparse);
        for &r in &lock_rows[locks.len()..] {
            sys.problem.scaling.rows[r] *= super::held::PREFERENCE;
        }
        let fast = sys.partition(q);
        let full = general(&mut sys, q);
        let jac = &sys.work.jac;
        let s = &sys.problem.scaling;
        answered &= crate::solver::sparse::fill_free::free_columns(
            &model,
            jac.rows,
            jac.cols,
            &jac.entries,
            &s.rows,
            &s.columns,
        )
        .is_some();
        assert_ne!(fast.id, full.id);
        assert_eq!(fast.dependent, full.dependent);
        assert_eq!(fast.independent, full.independent);
        assert_eq!(fast.rows, full.rows);
        assert_eq!(fast.redundant, full.redundant);
        assert_eq!(fast.second_pass, full.second_pass);
    }
    answered
}

/// The same partition as the general sparse elimination's on every model of the test set,
/// with and without the locked system's rows; the dense copies answer on every tree (and on
/// the locked systems of all but one) and on the ladders.
#[test]
fn same_partition_as_the_sparse_partition() {
    let (trees, loops) = models();
    let [plain, floating] = bases();
    for (k, t) in trees.iter().enumerate() {
        for o in [&plain, &floating] {
            assert!(same_partition(t, o, false), "tree {k}");
            // Panda's locked system keeps a row active at a body: the solver's partition
            // answers there (equal all the same).
            let answered = same_partition(t, o, true);
            assert!(answered || k == 2, "tree {k}, locked");
        }
    }
    for (k, t) in loops.iter().enumerate() {
        for locked in [false, true] {
            let answered = same_partition(t, &plain, locked);
            assert!(k < 5 || answered, "loop {k}, locked {locked}");
        }
    }
}

/// The rows expanded in one pass (`solver::sparse::rows`) against a plain reference on triplets
/// with duplicates, zeros, a sum that cancels, rows on one body, on two and empty: the same
/// entries (as sets; their order is not read), maxima, bodies, rows touching each body, and
/// reach; out-of-order or out-of-range triplets give `None`.
#[test]
fn rows_expanded_as_the_partition_builds_them() {
    use crate::solver::sparse::rows::Rows;
    let (m, n) = (6, 21);
    let t = vec![
        (0, 3, 2.0),
        (0, 1, 0.0),
        (0, 3, -0.5),
        (0, 5, 1.0),
        (1, 2, 1.0),
        (1, 9, -4.0),
        (1, 2, -1.0),
        (1, 3, 0.25),
        (2, 15, 3.0),
        (2, 0, 0.0),
        (2, 8, 0.5),
        (2, 16, -7.0),
        (4, 0, 0.0),
        (4, 14, 0.0),
        (4, 14, 2.0),
        (5, 20, 1e-300),
        (5, 1, 1.0),
    ];
    let row_scale = [1.0, 2.0, 0.5, 1.0, 3.0, 1.0];
    let scale: Vec<f64> = (0..n).map(|c| 1.0 + 0.125 * c as f64).collect();
    let rows = Rows::new(m, n, &t, &row_scale, &scale).unwrap();
    for r in 0..m {
        // Reference: sums in triplet order, zeros dropped.
        let mut sums: Vec<(usize, f64)> = Vec::new();
        for &(_, c, v) in t.iter().filter(|e| e.0 as usize == r) {
            let c = c as usize;
            let a = v * row_scale[r] * scale[c];
            match sums.iter_mut().find(|e| e.0 == c) {
                Some(e) => e.1 += a,
                None => sums.push((c, a)),
            }
        }
        sums.retain(|e| e.1 != 0.0);
        let mut got = rows.row(r).to_vec();
        got.sort_by_key(|e| e.0);
        sums.sort_by_key(|e| e.0);
        assert_eq!(got, sums, "row {r}");
        let max = sums.iter().fold(0.0f64, |a, e| a.max(e.1.abs()));
        assert_eq!(rows.rmax[r], max, "row {r}");
        let mut bodies: Vec<usize> = sums.iter().map(|e| e.0 / 7).collect();
        bodies.dedup();
        let one = bodies.len() == 1;
        assert_eq!(rows.own_of[r], if one { bodies[0] } else { usize::MAX });
        if one {
            for kind in 0..2 {
                let reach = sums
                    .iter()
                    .filter(|e| usize::from(e.0 % 7 >= 3) == kind)
                    .fold(0.0f64, |a, e| a.max(e.1.abs()));
                assert_eq!(rows.reach[r][kind], reach, "row {r}");
            }
        }
    }
    // Row 1's column 2 cancels (its column 3 keeps it on body 0); row 2's zero on body 0
    // does not touch it, and its two runs on body 2 count once; row 4's only nonzero entry
    // is on body 2.
    let mut touching = Vec::new();
    for (b, want) in [(0, vec![0, 1, 5]), (1, vec![1, 2]), (2, vec![2, 4, 5])] {
        rows.touching(b, &mut touching);
        assert_eq!(touching, want, "body {b}");
    }
    let mut swapped = t.clone();
    swapped.swap(3, 4);
    assert!(Rows::new(m, n, &swapped, &row_scale, &scale).is_none());
    let mut outside = t.clone();
    outside[2].1 = n as u32;
    assert!(Rows::new(m, n, &outside, &row_scale, &scale).is_none());
    assert!(Rows::new(m - 1, n, &t, &row_scale, &scale).is_none());
}
