//! The `O(N)` verification path for large models: the same questions as the dense path of
//! [`super::verify`], answered with the solver's sparse partition and factors instead of a
//! dense null-space basis (which costs `O(n³)`: 440 s at 1,000 links).
//!
//! With `Φ_q = [Φ_u Φ_v]` partitioned by the sparse body-by-body elimination, `S` the coordinate
//! scaling and `Z = [−Φ_u⁻¹ Φ_v; I] S`:
//! - projected gradient: the solver's reduced gradient `Zᵀ ∇V = S (V_v − Φ_vᵀ μ)`,
//!   `Φ_uᵀ μ = V_u` (paper eq. 37). It vanishes on exactly the poses where the orthonormal
//!   projection `Nᵀ S ∇V` of the dense path vanishes; its size differs by the conditioning of `Z`.
//! - efforts: every scalar coordinate `θ_k` of a tree joint gets a lock row `θ_k(q) − θ_k = 0`,
//!   which leaves no degree of freedom a scalar coordinate can carry, and the efforts are the
//!   multipliers of those rows in `∇V = Φ_qᵀ λ + Σ_k τ_k ∇θ_k`, i.e. `Φ_uᵀ μ = V_u` with one
//!   sparse LU. For a tree this is `τ_k = ∂V/∂θ_k`, exactly the dense path's answer. In a closed
//!   loop the lock rows are redundant with the loop's closure rows. The added lock rows are
//!   scaled down (by `LOCK_PREFERENCE`) for the pivot choice, so that the partition keeps every
//!   row of the model and drops lock rows only (checked: otherwise an error): then a balanced
//!   pose needs no effort, and off balance the effort of a loop is carried by the joints whose
//!   lock rows the partition keeps (a basic split instead of the dense path's minimum-norm
//!   split; dropped lock rows carry 0). Whether the pose is balanced does not depend on the
//!   split.
//! - unassigned: the reduced gradient that remains with all scalar coordinates locked
//!   (spherical and floating joints).

use crate::constraints::{BlockKind, Constraints};
use crate::error::{Error, Result};
use crate::forces::potential;
use crate::model::{JointId, Model};
use crate::solver::partition::Partition;
use crate::solver::system::{coordinate_scale, Backend, Eval, System};
use crate::state::State;
use nalgebra::DVector;

/// Scale of the added lock rows in the pivot choice: small enough that a model row with an
/// entry in the same body's columns is preferred, far above the rank tolerance (`1e-9`).
const LOCK_PREFERENCE: f64 = 1e-3;

/// The quantities of one sparse partition at a configuration.
pub(super) struct Reduced<'a> {
    /// `Φ(q)` over all rows.
    pub(super) phi: DVector<f64>,
    /// Potential energy \[J\].
    pub(super) energy: f64,
    /// `‖Zᵀ ∇V‖∞` \[J\] (0 without degrees of freedom).
    pub(super) reduced_gradient: f64,
    /// `‖S ∇V‖∞` \[J\]: the largest generalized force, the scale of the relative tolerance.
    pub(super) force_scale: f64,
    /// Number of independent coordinates.
    pub(super) dof: usize,
    /// Multiplier per row (0 on redundant rows).
    pub(super) multipliers: Vec<f64>,
    /// Redundant rows, ascending.
    pub(super) redundant: Vec<usize>,
    /// The system (rows included), its partition and evaluation at the configuration: what
    /// the stability verdict needs too.
    pub(super) sys: System<'a>,
    pub(super) part: Partition,
    pub(super) eval: Eval,
}

/// Partitions and evaluates the rows of `model` plus `locks` at `q` on the sparse path; the
/// locks from index `preferred` on are the added ones, kept only where no model row can be.
pub(super) fn reduced<'a>(
    model: &'a Model,
    state: &State,
    locks: &[(JointId, usize, f64)],
    preferred: usize,
) -> Result<Reduced<'a>> {
    let q = &state.q;
    let mut g = DVector::zeros(q.len());
    potential(model, &state.branches, q, &mut g, None).ok_or_else(|| {
        crate::forces::undefined_term(model, &state.branches, q).unwrap_or(
            Error::SingularPartition {
                at: "the given pose".into(),
                rows: 0,
            },
        )
    })?;
    let scale = coordinate_scale(model);
    let force_scale = g
        .iter()
        .zip(&scale)
        .fold(0.0f64, |a, (x, s)| a.max((x * s).abs()));
    let mut sys = System::new(
        model,
        Constraints::new(model, locks).on_branches(state.branches.clone()),
        Backend::Sparse,
    );
    let added = sys.problem.cons.len() - model.mimics.len() - (locks.len() - preferred);
    for r in added..sys.problem.cons.len() - model.mimics.len() {
        sys.problem.scaling.rows[r] *= LOCK_PREFERENCE;
    }
    let part = sys.partition(q);
    let eval = sys
        .evaluate(q, &part)
        .ok_or_else(|| Error::SingularPartition {
            at: "the given pose".into(),
            rows: part.rows.len(),
        })?;
    let mut multipliers = vec![0.0; sys.problem.cons.len()];
    for (k, &r) in part.rows.iter().enumerate() {
        multipliers[r] = eval.mu[k];
    }
    Ok(Reduced {
        phi: sys.phi().clone(),
        energy: eval.energy.total,
        reduced_gradient: eval.grad_v.iter().fold(0.0f64, |a, x| a.max(x.abs())),
        force_scale,
        dof: part.independent.len(),
        multipliers,
        redundant: part.redundant.clone(),
        sys,
        part,
        eval,
    })
}

/// The efforts of the tree joints' scalar coordinates `coords` (joint, dof, current value) and
/// the unassigned generalized force, with the model's own `locks` (whose coordinates need no
/// effort: their lock rows hold them). `base` is the number of redundant rows without the
/// added locks. `carried` is the generalized force the touching stops and contacts take
/// (`G λ`, unscaled; module `unilateral_sparse`): the efforts balance `∇V − G λ`.
pub(super) fn efforts(
    model: &Model,
    state: &State,
    locks: &[(JointId, usize, f64)],
    coords: &[(JointId, usize, f64)],
    base: usize,
    carried: Option<&DVector<f64>>,
) -> Result<(Vec<f64>, f64)> {
    let mut all = locks.to_vec();
    let mut row_of = Vec::with_capacity(coords.len());
    for &(joint, dof, value) in coords {
        if locks.iter().any(|l| l.0 == joint && l.1 == dof) {
            row_of.push(None);
        } else {
            row_of.push(Some(all.len()));
            all.push((joint, dof, value));
        }
    }
    let mut r = reduced(model, state, &all, locks.len())?;
    if let Some(c) = carried {
        take_off(&mut r, c)?;
    }
    let cons = &r.sys.problem.cons;
    let first_added = cons.len() - model.mimics.len() - (all.len() - locks.len());
    let dropped = r.redundant.iter().filter(|&&i| i < first_added).count();
    if dropped > base {
        return Err(Error::InseparableEfforts {
            dependent: dropped,
            without: base,
        });
    }
    let first_lock = cons
        .blocks
        .iter()
        .find(|b| matches!(b.kind, BlockKind::Lock { .. }))
        .map_or(0, |b| b.first);
    let tau = row_of
        .iter()
        .map(|k| k.map_or(0.0, |k| r.multipliers[first_lock + k]))
        .collect();
    Ok((tau, r.reduced_gradient))
}

/// Takes the generalized force `c` off the gradient of `r`: the multipliers and reduced
/// gradient are linear in `∇V`, so `Φ_uᵀ δμ = −c_u` and `δ(∂V/∂v) = S (−c_v − Φ_vᵀ δμ)` are
/// added to them (one more solve with the same factors).
fn take_off(r: &mut Reduced<'_>, c: &DVector<f64>) -> Result<()> {
    let (part, eval) = (&r.part, &mut r.eval);
    let c_u = DVector::from_iterator(part.dependent.len(), part.dependent.iter().map(|&i| -c[i]));
    let d_mu = eval
        .factors
        .solve_transpose(c_u)
        .ok_or_else(|| Error::SingularPartition {
            at: "the given pose".into(),
            rows: part.rows.len(),
        })?;
    let dof = part.independent.len();
    let d_v = eval.factors.phi_v_tr_mul(&d_mu, dof);
    let scale = &r.sys.problem.scaling.columns;
    for (b, &i) in part.independent.iter().enumerate() {
        eval.grad_v[b] += (-c[i] - d_v[b]) * scale[i];
    }
    for (k, &row) in part.rows.iter().enumerate() {
        eval.mu[k] += d_mu[k];
        r.multipliers[row] = eval.mu[k];
    }
    r.reduced_gradient = eval.grad_v.iter().fold(0.0f64, |a, x| a.max(x.abs()));
    Ok(())
}
