//! The forces that hold a given pose: joint efforts, stop and contact forces, joint and loop
//! reactions, on the dense and the sparse path alike.
//!
//! With `θ_k` the scalar coordinates of the tree joints, `g_i` the touching stops and contacts
//! (module `unilateral`) and `Φ` the model's equality rows (joints, loops, normalization,
//! mimics, locks), a pose is held when
//!
//! `∇V = Φ_qᵀ a + Σ_i λ_i ∇g_i + Σ_k τ_k ∇θ_k`,   `λ_i ≥ 0` on the normal rows.
//!
//! The efforts `τ` act only on the joint coordinates: every other coordinate (a floating base,
//! a spherical joint, the coordinates a closed loop determines) is balanced by the reactions
//! `a` and the forces `λ` alone; what they cannot balance is the `unassigned` force. The
//! unknowns are found as the multipliers of one system: the model's rows, a lock row
//! `θ_k(q) − θ_k = 0` on every joint coordinate and the touching rows, partitioned (dense or
//! sparse: the same partition the solver uses; `analyze`'s self-check on a locked tree: by
//! bodies, module `tree_partition`; on a tree closed by loops: in joint coordinates, module
//! `loop_efforts`) so that it keeps every model row it can (lock
//! and touching rows scaled down by [`PREFERENCE`] in the pivot choice). `Φ_uᵀ μ = ∇_u V` gives
//! the basic multipliers `μ_b`; the reduced gradient that remains is the unassigned force.
//!
//! Where rows are dependent (a closed loop makes its joints' lock rows dependent; four feet on
//! the ground under a rigid body), the multipliers are not unique: every solution is
//! `μ_b + K z`, one column of `K` per row `r` the partition drops,
//! `K_r = e_r − Σ_k c_k e_k` with `Φ_uᵀ c = (∇Φ_r)_u` (a self-equilibrated combination of rows).
//! The reported solution is the one with
//! 1. the least efforts `‖τ‖₂` on the coordinates no lock of the model holds (the pose is a
//!    rest pose when they vanish), then
//! 2. the least stop and contact forces `‖λ‖₂` (as `analyze` distributes them: module
//!    `solver::distribution`), the efforts of locked coordinates following.
//!
//! So the answer does not depend on the partition (dense and sparse agree), a balanced pose
//! gets the forces `analyze` found at it, and a pose held by locks (`verify --lock`) gets
//! `analyze --lock`'s holding efforts and contact forces.
//!
//! The two stages are found in two solves. First without the joints' lock rows: where that
//! balances the pose (reduced gradient within the effort tolerance) the least efforts are
//! zero, and the forces are the least-norm ones of that system (dependent touching rows only:
//! a rope lying on the ground has none, where locking its joints would make hundreds); the
//! efforts are then the multipliers of the locked system with those forces taken off `∇V`
//! (`Φ_uᵀ δμ = −(G λ)_u`), which also gives the residual. Otherwise the locked system with the
//! touching rows is solved in one (the pose fails; its efforts say by how much).
//!
//! A normal force below `−τ` (the effort tolerance) would pull: the row is dropped and the
//! forces are solved again, at most `rounds::ROUNDS` times (the rows that pull in the first solve
//! without locks are named in the failures). Above [`MAX_DEPENDENT`] dependent rows the basic
//! multipliers are kept (a ladder of many loops: at a balanced pose the basic efforts are
//! zero too, since the partition keeps the model's rows). The cost is one or two sparse
//! partitions per round, `O(N)` on chains, trees and ladders, plus `O(d² m)` for `d`
//! dependent rows among `m`.

pub(super) use super::model_rows::ModelRows;
use super::unilateral::Touching;
use crate::constraints::{BlockKind, Constraints, Triplets};
use crate::error::{Error, Result};
use crate::model::{JointId, Model};
use crate::solver::partition::Partition;
use crate::solver::system::{Backend, Eval, System};
use crate::state::State;
use nalgebra::{DMatrix, DVector};

/// Scale of the lock and touching rows in the pivot choice: a model row is preferred.
pub(super) const PREFERENCE: f64 = 1e-3;

/// Largest number of dependent rows whose multipliers are made least-norm.
pub(super) const MAX_DEPENDENT: usize = 200;

/// The forces that hold a pose.
pub(super) struct Held {
    /// Effort per joint coordinate of `coords` \[N m or N\].
    pub(super) efforts: Vec<f64>,
    /// Whether a lock of the model holds that coordinate (its effort is a lock's reaction,
    /// not an imbalance).
    pub(super) locked: Vec<bool>,
    /// `‖S r‖∞` of the generalized force `r` no row or effort balances \[J\].
    pub(super) unassigned: f64,
    /// Forces per touching inequality of the list (normal first, then tangential); zero on
    /// the ones dropped because they would pull.
    pub(super) forces: Vec<Vec<f64>>,
    /// The inequalities (index in the list) whose normal force would pull in the first
    /// round, with that force.
    pub(super) pulling: Vec<(usize, f64)>,
    /// `(required_mu, slipping)` of the friction distribution chosen (module
    /// `solver::friction`), where sticking contacts carry the load without efforts.
    pub(super) friction: crate::solver::friction::Chosen,
}

/// The forces holding `state`: efforts of the joint coordinates `coords` (joint, dof, value),
/// forces of the touching inequalities `list`; `backend` the linear algebra, `tau` the effort
/// tolerance (a normal force below `−tau` pulls).
///
/// # Errors
/// [`Error::SingularPartition`] if `Φ_u` is singular at the pose,
/// [`Error::ForceTableOutOfRange`] if the energy cannot be evaluated there.
pub(super) fn held(
    model: &Model,
    state: &State,
    list: &[Touching],
    coords: &[(JointId, usize, f64)],
    backend: Backend,
    tau: f64,
    free: Free,
    given: Option<ModelRows>,
) -> Result<Held> {
    let locks = crate::solver::lock_values(model);
    let mut all = locks.clone();
    let mut row_of = Vec::with_capacity(coords.len());
    let mut locked = Vec::with_capacity(coords.len());
    for &(joint, dof, value) in coords {
        match locks.iter().position(|l| l.0 == joint && l.1 == dof) {
            Some(k) => {
                row_of.push(k);
                locked.push(true);
            }
            None => {
                row_of.push(all.len());
                locked.push(false);
                all.push((joint, dof, value));
            }
        }
    }
    // First without locking the joints: where that balances the pose, no effort is needed
    // and these are the forces (the least-norm ones among those needing none).
    // Nothing touching: the caller may have these multipliers already ([`free_of`]).
    let free = match free {
        Free::Given(m) if list.is_empty() => (m, Vec::new(), Vec::new()),
        Free::Skip { joint_space } if list.is_empty() => {
            // The locked solve is what the two stages give without a touching row (both the
            // balanced and the unbalanced case solve it; the balanced one adds a zero).
            let in_loops = joint_space.then(|| {
                super::loop_efforts::multipliers(model, state, &all, locks.len(), given.as_ref())
            });
            let r = match in_loops.flatten() {
                Some(r) => r,
                None => solve_once(
                    model,
                    state,
                    &[],
                    &[],
                    &all,
                    locks.len(),
                    backend,
                    None,
                    given,
                    true,
                )?,
            };
            return Ok(Held {
                efforts: row_of.iter().map(|&k| r.locks[k]).collect(),
                locked,
                unassigned: r.unassigned,
                forces: Vec::new(),
                pulling: Vec::new(),
                friction: None,
            });
        }
        _ => super::rounds::with_rounds(list, tau, |on| {
            solve_once(
                model,
                state,
                list,
                on,
                &locks,
                locks.len(),
                backend,
                None,
                None,
                false,
            )
        })?,
    };
    let locked_solve = if free.0.unassigned <= tau {
        None
    } else {
        let (r, forces, _) = super::rounds::with_rounds(list, tau, |on| {
            solve_once(
                model,
                state,
                list,
                on,
                &all,
                locks.len(),
                backend,
                None,
                None,
                false,
            )
        })?;
        // Too many dependent rows to choose among (a rope on the ground with its joints
        // locked): the forces of the solve without locks, the efforts balancing the rest.
        r.resolved.then_some((r, forces))
    };
    let (r, forces) = match locked_solve {
        Some(solved) => solved,
        None => {
            let mut carried = DVector::zeros(state.q.len());
            for (t, f) in list.iter().zip(&free.1) {
                for (k, &l) in f.iter().enumerate() {
                    t.add_gradient(k, l, &mut carried);
                }
            }
            let efforts = solve_once(
                model,
                state,
                &[],
                &[],
                &all,
                locks.len(),
                backend,
                Some(&carried),
                given,
                false,
            )?;
            (efforts, free.1)
        }
    };
    Ok(Held {
        efforts: row_of.iter().map(|&k| r.locks[k]).collect(),
        locked,
        unassigned: r.unassigned,
        forces,
        pulling: free.2,
        friction: free.0.chosen,
    })
}

/// The first solve of [`held`] (the model's rows and the touching ones, no joint locked).
pub(super) enum Free {
    /// Nothing touches and these are its multipliers ([`free_of`]).
    Given(Multipliers),
    /// To be solved.
    Solve,
    /// Not needed where nothing touches: the efforts, forces and unassigned force are the
    /// locked solve's (as they are after the first solve; solved where something touches);
    /// with `joint_space`, on a tree closed by loops, in joint coordinates (module
    /// `loop_efforts`) where that applies.
    Skip { joint_space: bool },
}

/// One solve's multipliers: per lock of `all`, per inequality of `list`, and the unassigned
/// force.
pub(super) struct Multipliers {
    pub(super) locks: Vec<f64>,
    pub(super) forces: Vec<Vec<f64>>,
    pub(super) unassigned: f64,
    /// Whether the multipliers were made unique (at most [`MAX_DEPENDENT`] dependent rows).
    pub(super) resolved: bool,
    /// `(required_mu, slipping)` where sticking contacts carry the load and no effort is
    /// chosen: the distribution of module `solver::friction` (the one `analyze` reports).
    pub(super) chosen: crate::solver::friction::Chosen,
}

/// The multipliers of the first solve of [`held`] where nothing touches (the model's rows
/// and locks alone), from the system of those rows already partitioned and evaluated at the
/// pose (`verify`'s balance check, module `reduced`, builds the same system `solve_once`
/// would: the same rows, scaling and partition). No row's multiplier is chosen there (no
/// joint lock, no touching row), so they are the basic ones.
pub(super) fn free_of(sys: &System, part: &Partition, eval: &Eval) -> Multipliers {
    let mut mu = DVector::zeros(sys.problem.cons.len());
    for (k, &r) in part.rows.iter().enumerate() {
        mu[r] = eval.mu[k];
    }
    Multipliers {
        locks: sys
            .problem
            .cons
            .blocks
            .iter()
            .filter(|b| matches!(b.kind, BlockKind::Lock { .. }))
            .map(|b| mu[b.first])
            .collect(),
        forces: Vec::new(),
        unassigned: eval.grad_v.amax(),
        resolved: part.redundant.len() <= MAX_DEPENDENT,
        chosen: None,
    }
}

/// The multipliers of the model's rows, the locks `all` (the first `model_locks` the model's
/// own) and the inequalities of `list` with `on`, made unique as the module docs say; with
/// `by_bodies` and the tree factors, partitioned by bodies where that applies (module
/// `tree_partition`: `analyze`'s self-check, the multipliers to rounding).
fn solve_once(
    model: &Model,
    state: &State,
    list: &[Touching],
    on: &[bool],
    all: &[(JointId, usize, f64)],
    model_locks: usize,
    backend: Backend,
    carried: Option<&DVector<f64>>,
    given: Option<ModelRows>,
    by_bodies: bool,
) -> Result<Multipliers> {
    let kept: Vec<usize> = (0..list.len()).filter(|&i| on[i]).collect();
    let active: Vec<_> = kept.iter().map(|&i| list[i].active).collect();
    let cons = Constraints::new(model, all)
        .with_active(model, &active)
        .on_branches(state.branches.clone());
    // Rows: the lock rows in the order of `all`, the touching rows by inequality.
    let lock_rows: Vec<usize> = cons
        .blocks
        .iter()
        .filter(|b| matches!(b.kind, BlockKind::Lock { .. }))
        .map(|b| b.first)
        .collect();
    let touch_firsts: Vec<usize> = cons
        .blocks
        .iter()
        .filter(|b| matches!(b.kind, BlockKind::Unilateral(_)))
        .map(|b| b.first)
        .collect();
    let m = cons.len();
    let mut sys = System::new(model, cons, backend);
    for &r in &lock_rows[model_locks..] {
        sys.problem.scaling.rows[r] *= PREFERENCE;
    }
    for (&f, &i) in touch_firsts.iter().zip(&kept) {
        for k in 0..list[i].rows.len() {
            sys.problem.scaling.rows[f + k] *= PREFERENCE;
        }
    }
    let singular = |rows| Error::SingularPartition {
        at: "the given pose".into(),
        rows,
    };
    // The model's rows from the balance check where they are this system's first ones, and
    // with them the guard's `V` and `∇V` (the same pose and branches).
    let known = given.and_then(|rows| rows.install(&mut sys, &state.q));
    let by_bodies = by_bodies && backend == Backend::Tree;
    let (part, mut eval) =
        super::tree_partition::evaluated(&mut sys, &state.q, known, by_bodies).map_err(singular)?;
    if let Some(c) = carried {
        // The multipliers and the reduced gradient are linear in ∇V: with `c` taken off it,
        // `Φ_uᵀ δμ = −c_u` and `δ(∂V/∂v) = S (−c_v − Φ_vᵀ δμ)` (one more solve).
        let c_u =
            DVector::from_iterator(part.dependent.len(), part.dependent.iter().map(|&i| -c[i]));
        let d_mu = eval
            .factors
            .solve_transpose(c_u)
            .ok_or_else(|| singular(part.rows.len()))?;
        let d_v = eval.factors.phi_v_tr_mul(&d_mu, part.independent.len());
        let scale = &sys.problem.scaling.columns;
        for (b, &i) in part.independent.iter().enumerate() {
            eval.grad_v[b] += (-c[i] - d_v[b]) * scale[i];
        }
        eval.mu += d_mu;
    }
    let mut mu = DVector::zeros(m);
    for (k, &r) in part.rows.iter().enumerate() {
        mu[r] = eval.mu[k];
    }
    let unassigned = eval.grad_v.amax();
    // The rows whose multipliers are chosen: the efforts of free coordinates (stage 1), the
    // touching rows (stage 2).
    let free: Vec<usize> = lock_rows[model_locks..].to_vec();
    let mut touch = Vec::new();
    for (&f, &i) in touch_firsts.iter().zip(&kept) {
        touch.extend(f..f + list[i].rows.len());
    }
    let dependent = &part.redundant;
    let resolved = dependent.len() <= MAX_DEPENDENT;
    // The touching rows' self-equilibrated directions and their effect on every row.
    let mut directions: Option<(DMatrix<f64>, DMatrix<f64>)> = None;
    if !dependent.is_empty()
        && dependent.len() <= MAX_DEPENDENT
        && !(free.is_empty() && touch.is_empty())
    {
        // ∇Φ_r of the dropped rows, from the triplets.
        let mut phi = DVector::zeros(m);
        let mut jac = Triplets::default();
        sys.problem
            .cons
            .evaluate(model, &state.q, &mut phi, Some(&mut jac));
        let index: std::collections::HashMap<usize, usize> =
            dependent.iter().enumerate().map(|(d, &r)| (r, d)).collect();
        let mut grads = vec![DVector::zeros(state.q.len()); dependent.len()];
        for &(r, c, v) in &jac.entries {
            if let Some(&d) = index.get(&(r as usize)) {
                grads[d][c as usize] += v;
            }
        }
        // K restricted to the rows of the two stages.
        let (mut k_free, mut k_touch) = (
            DMatrix::zeros(free.len(), dependent.len()),
            DMatrix::zeros(touch.len(), dependent.len()),
        );
        let free_at: std::collections::HashMap<usize, usize> =
            free.iter().enumerate().map(|(k, &r)| (r, k)).collect();
        let touch_at: std::collections::HashMap<usize, usize> =
            touch.iter().enumerate().map(|(k, &r)| (r, k)).collect();
        let mut put = |row: usize, d: usize, x: f64| {
            if let Some(&k) = free_at.get(&row) {
                k_free[(k, d)] += x;
            }
            if let Some(&k) = touch_at.get(&row) {
                k_touch[(k, d)] += x;
            }
        };
        let mut k_all = DMatrix::zeros(m, dependent.len());
        for (d, &r) in dependent.iter().enumerate() {
            let g_u = DVector::from_iterator(
                part.dependent.len(),
                part.dependent.iter().map(|&c| grads[d][c]),
            );
            let c = eval
                .factors
                .solve_transpose(g_u)
                .ok_or_else(|| singular(part.rows.len()))?;
            put(r, d, 1.0);
            k_all[(r, d)] = 1.0;
            for (k, &row) in part.rows.iter().enumerate() {
                put(row, d, -c[k]);
                k_all[(row, d)] = -c[k];
            }
        }
        let at = |rows: &[usize]| DVector::from_iterator(rows.len(), rows.iter().map(|&r| mu[r]));
        let z = super::lexicographic::lexicographic(&k_free, &at(&free), &k_touch, &at(&touch));
        mu += &k_all * z;
        directions = Some((k_touch, k_all));
    }
    // Sticking contacts without efforts to choose: among the balancing forces, the
    // distribution needing the least friction, then the least norm (module
    // `solver::friction`, as `analyze`), and the friction verdict with it.
    let sticks = kept.iter().any(|&i| {
        list[i].active.anchor.is_some()
            && matches!(
                list[i].active.row,
                crate::constraints::unilateral::Unilateral::Contact { .. }
            )
    });
    let mut chosen = None;
    if free.is_empty() && sticks {
        let base = DVector::from_iterator(touch.len(), touch.iter().map(|&r| mu[r]));
        let dirs = directions
            .as_ref()
            .map_or_else(|| DMatrix::zeros(touch.len(), 0), |d| d.0.clone());
        let items: Vec<_> = kept.iter().map(|&i| (list[i].active, list[i].mu)).collect();
        if let Some(d) = super::friction::choose(model, &base, &dirs, &items) {
            if let Some((k_touch, k_all)) = &directions {
                let step = &d.forces - &base;
                if let Some(svd) = crate::solver::svd::svd(k_touch.clone(), true, true) {
                    let eps = 1e-12 * svd.singular_values.amax().max(1e-300);
                    if let Ok(z) = svd.solve(&step, eps) {
                        mu += k_all * z;
                    }
                }
                // The touching rows exactly as chosen (`K z` reproduces them to rounding).
                for (k, &r) in touch.iter().enumerate() {
                    mu[r] = d.forces[k];
                }
            }
            chosen = Some((d.required_mu, d.slipping));
        }
    }
    let mut forces: Vec<Vec<f64>> = list.iter().map(|t| vec![0.0; t.rows.len()]).collect();
    for (&f, &i) in touch_firsts.iter().zip(&kept) {
        for (k, x) in forces[i].iter_mut().enumerate() {
            *x = mu[f + k];
        }
    }
    Ok(Multipliers {
        locks: lock_rows.iter().map(|&r| mu[r]).collect(),
        forces,
        unassigned,
        resolved,
        chosen,
    })
}
