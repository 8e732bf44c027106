//! Stops and contacts at a given pose on the sparse path: the forces of the touching
//! inequalities from the solver's sparse partition instead of the dense null-space basis of
//! module `unilateral` (same report, same checks).
//!
//! The touching rows `g_k` (module `unilateral`: `|g_k| ≤ ε`) are appended to the equality rows
//! as the solver appends its active inequalities (`Constraints::with_active`), scaled down in
//! the pivot choice so that the partition keeps every equality row it can. With
//! `Φ_q = [Φ_u Φ_v]` so partitioned, the multipliers of all kept rows solve
//!
//! `Φ_uᵀ μ = ∇_u V`   (paper eq. 37; one sparse LU),
//!
//! and the forces `λ_k` are those of the touching rows (0 on rows the partition drops). At a
//! balanced pose `∇V = Φ_qᵀ a + G λ` has a solution, and it is this one up to the
//! dependencies among the touching rows (a statically indeterminate support: a box flat on four
//! vertices). Each dropped touching row `r` gives one: `∇g_r = Σ_k c_k ∇Φ_k` over the kept rows,
//! `Φ_uᵀ c = (∇g_r)_u`, so `λ + t (e_r − Σ_k c_k e_k)` (on the touching rows) balances as well.
//! Over these directions `K` the forces are made minimum-norm as on the dense path, weighted by
//! the row norms `D = diag ‖S ∇g_k‖`: `λ ← λ − K (Kᵀ D² K)⁻¹ Kᵀ D² λ` (the dense path weights by
//! the norms of the projected columns `‖Nᵀ S ∇g_k‖`; the two agree where the touching rows move
//! nothing but the supported bodies, e.g. a free body on the ground). Above
//! [`MAX_DEPENDENT`] dependent rows the basic forces are kept.
//!
//! A normal row with `λ_k < −τ` would have to pull: it is named in the failures (when the pose
//! then fails), dropped, and the forces are solved again without it, at most [`ROUNDS`] times;
//! the forces of rows that still pull after that are set to 0. The generalized force the rows
//! carry, `G λ`, is then taken off `∇V` before the joint efforts are computed (module
//! `reduced`), so a pose the stops and contacts cannot hold fails there, as on the dense path.
//! The cost is `O(N)` per round on chains, trees and ladders, plus `O(d² m)` for `d` dependent
//! touching rows among `m`.

use super::unilateral::{describe, pulling, touching, Touching};
use super::{UnilateralCheck, Unilaterals};
use crate::constraints::unilateral::Active;
use crate::constraints::{BlockKind, Constraints};
use crate::error::{Error, Result};
use crate::model::{JointId, Model};
use crate::solver::system::{Backend, System};
use crate::state::State;
use nalgebra::{DMatrix, DVector};

/// Largest number of dependent touching rows whose forces are made minimum-norm.
const MAX_DEPENDENT: usize = 200;

/// Largest number of solves dropping the rows that pull.
const ROUNDS: usize = 20;

/// Scale of the touching rows in the pivot choice: an equality row is preferred to them.
const PREFERENCE: f64 = 1e-3;

/// What the stops and contacts do at a pose on the sparse path.
pub(super) struct SparseUnilateral {
    /// The report (as the dense path's).
    pub(super) check: UnilateralCheck,
    /// `G λ`, the generalized force the touching rows carry (unscaled coordinates).
    pub(super) carried: DVector<f64>,
    /// The inequalities that carry a force (`λ > τ`): the stability's tangent space.
    pub(super) strong: Vec<Active>,
    /// The touching inequalities that carry no force (the critical cone's).
    pub(super) weak: Vec<Active>,
    /// Whether any inequality touches.
    pub(super) touching: bool,
}

/// Checks the stops and contacts at `state` with the equality rows of `model` and its `locks`;
/// `eps` the constraint tolerance, `tau` the effort tolerance.
///
/// # Errors
/// [`Error::SingularPartition`] if a partition's `Φ_u` is singular at the pose,
/// [`Error::ForceTableOutOfRange`] if the energy cannot be evaluated there.
pub(super) fn check(
    model: &Model,
    state: &State,
    opts: &Unilaterals,
    locks: &[(JointId, usize, f64)],
    eps: f64,
    tau: f64,
) -> Result<SparseUnilateral> {
    let mut out = UnilateralCheck::default();
    let list = touching(model, state, opts, eps, &mut out);
    let n = state.q.len();
    let mut carried = DVector::zeros(n);
    if list.is_empty() {
        return Ok(SparseUnilateral {
            check: out,
            carried,
            strong: Vec::new(),
            weak: Vec::new(),
            touching: false,
        });
    }
    let mut on = vec![true; list.len()];
    let mut forces = Vec::new();
    let mut named = Vec::new();
    let mut chosen = None;
    for round in 0..ROUNDS {
        (forces, chosen) = multipliers(model, state, locks, &list, &on)?;
        let negative: Vec<usize> = (0..list.len())
            .filter(|&i| on[i] && forces[i][0] < -tau)
            .collect();
        if round == 0 {
            named = negative.iter().map(|&i| (i, forces[i][0])).collect();
        }
        if negative.is_empty() {
            break;
        }
        for i in negative {
            on[i] = false;
        }
    }
    let (mut strong, mut weak) = (Vec::new(), Vec::new());
    for (i, t) in list.iter().enumerate() {
        let lambda: Vec<f64> = if forces[i][0] < -tau {
            vec![0.0; t.rows.len()]
        } else {
            forces[i].clone()
        };
        for (k, &l) in lambda.iter().enumerate() {
            t.add_gradient(k, l, &mut carried);
        }
        if lambda[0] > tau {
            strong.push(t.active);
        } else {
            weak.push(t.active);
        }
        out.complementarity = out.complementarity.max((t.gap * lambda[0]).abs());
        describe(model, state, t, &lambda, tau, &mut out);
    }
    // The sparse path keeps its one distribution (no search among the indeterminate ones).
    let sticking: Vec<(f64, Option<f64>)> = list
        .iter()
        .filter(|t| {
            matches!(
                t.active.row,
                crate::constraints::unilateral::Unilateral::Contact { .. }
            )
        })
        .zip(&out.contacts)
        .filter(|(t, _)| t.active.anchor.is_some())
        .map(|(t, c)| (c.required_friction, t.mu))
        .collect();
    out.friction = crate::solver::friction::verdict(&sticking, chosen);
    crate::solver::friction::settle_states(&mut out.contacts, out.friction.as_ref());
    if let Some(v) = out.friction.as_ref().filter(|v| v.slipping) {
        out.failures.push(super::friction::slipping(v));
    }
    for (i, f) in named {
        out.failures.push(pulling(model, &list[i].active.row, f));
    }
    Ok(SparseUnilateral {
        check: out,
        carried,
        strong,
        weak,
        touching: true,
    })
}

/// The forces of the touching rows `list` (those with `on`; 0 on the others), per inequality
/// (`g` first, then the tangential rows), from one sparse partition with the equality rows,
/// and (`required_mu`, slipping) where module `solver::friction` chose among them.
fn multipliers(
    model: &Model,
    state: &State,
    locks: &[(JointId, usize, f64)],
    list: &[Touching],
    on: &[bool],
) -> Result<(Vec<Vec<f64>>, crate::solver::friction::Chosen)> {
    let kept: Vec<usize> = (0..list.len()).filter(|&i| on[i]).collect();
    let active: Vec<Active> = kept.iter().map(|&i| list[i].active).collect();
    let cons = Constraints::new(model, locks)
        .with_active(model, &active)
        .on_branches(state.branches.clone());
    // Row of each kept inequality's first row.
    let firsts: Vec<usize> = cons
        .blocks
        .iter()
        .filter(|b| matches!(b.kind, BlockKind::Unilateral(_)))
        .map(|b| b.first)
        .collect();
    let mut sys = System::with_backend(model, cons, Backend::Sparse);
    let first = firsts.first().copied().unwrap_or(sys.problem.cons.len());
    for r in first..sys.problem.cons.len() {
        sys.problem.scaling.rows[r] *= PREFERENCE;
    }
    let singular = |rows| Error::SingularPartition {
        at: "the given pose".into(),
        rows,
    };
    let part = sys.partition(&state.q);
    let eval = sys
        .evaluate(&state.q, &part)
        .ok_or_else(|| singular(part.rows.len()))?;
    // The touching rows: (inequality in `list`, row in it) by row index from `first`.
    let mut which = Vec::new();
    for (&i, &f) in kept.iter().zip(&firsts) {
        for k in 0..list[i].rows.len() {
            which.push((i, k));
            debug_assert_eq!(f + k, first + which.len() - 1);
        }
    }
    let m = which.len();
    let mut lambda = DVector::zeros(m);
    for (k, &r) in part.rows.iter().enumerate() {
        if r >= first {
            lambda[r - first] = eval.mu[k];
        }
    }
    let dependent: Vec<usize> = part
        .redundant
        .iter()
        .filter(|&&r| r >= first)
        .map(|&r| r - first)
        .collect();
    if !dependent.is_empty() && dependent.len() <= MAX_DEPENDENT {
        let n = state.q.len();
        let scale = &sys.problem.scaling.columns;
        let weight: Vec<f64> = which
            .iter()
            .map(|&(i, k)| {
                let mut g = DVector::zeros(n);
                list[i].add_gradient(k, 1.0, &mut g);
                g.iter()
                    .zip(scale)
                    .map(|(x, s)| (x * s).powi(2))
                    .sum::<f64>()
            })
            .collect();
        let mut dirs = DMatrix::zeros(m, dependent.len());
        for (d, &r) in dependent.iter().enumerate() {
            let (i, k) = which[r];
            let mut g = DVector::zeros(n);
            list[i].add_gradient(k, 1.0, &mut g);
            let g_u =
                DVector::from_iterator(part.dependent.len(), part.dependent.iter().map(|&c| g[c]));
            let c = eval
                .factors
                .solve_transpose(g_u)
                .ok_or_else(|| singular(part.rows.len()))?;
            dirs[(r, d)] = 1.0;
            for (k, &row) in part.rows.iter().enumerate() {
                if row >= first {
                    dirs[(row - first, d)] -= c[k];
                }
            }
        }
        // Module `solver::friction` picks among `λ + dirs t` (as the dense path and analyze);
        // the least-norm one below where no distribution keeps every contact pushing.
        let items: Vec<(Active, Option<f64>)> =
            kept.iter().map(|&i| (list[i].active, list[i].mu)).collect();
        if let Some(chosen) = super::friction::choose(model, &lambda, &dirs, &items) {
            let mut out: Vec<Vec<f64>> = list.iter().map(|t| vec![0.0; t.rows.len()]).collect();
            for (r, &(i, k)) in which.iter().enumerate() {
                out[i][k] = chosen.forces[r];
            }
            return Ok((out, Some((chosen.required_mu, chosen.slipping))));
        }
        let w = DMatrix::from_diagonal(&DVector::from_vec(weight));
        let kw = dirs.transpose() * &w;
        let normal = &kw * &dirs;
        let svd = normal.svd(true, true);
        let e = 1e-12 * svd.singular_values.max().max(1e-300);
        if let Ok(t) = svd.solve(&(&kw * &lambda), e) {
            lambda -= &dirs * t;
        }
    }
    let mut out: Vec<Vec<f64>> = list.iter().map(|t| vec![0.0; t.rows.len()]).collect();
    for (r, &(i, k)) in which.iter().enumerate() {
        out[i][k] = lambda[r];
    }
    Ok((out, None))
}
