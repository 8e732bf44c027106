//! The `O(N)` verification path for large models: the same questions as the dense path of
//! [`super::verify`], answered with the solver's sparse partition and factors instead of a
//! dense null-space basis (which costs `O(n³)`: 440 s at 1,000 links).
//!
//! With `Φ_q = [Φ_u Φ_v]` partitioned by the sparse body-by-body elimination, `S` the coordinate
//! scaling and `Z = [−Φ_u⁻¹ Φ_v; I] S`:
//! - projected gradient: the solver's reduced gradient `Zᵀ ∇V = S (V_v − Φ_vᵀ μ)`,
//!   `Φ_uᵀ μ = V_u` (paper eq. 37). It vanishes on exactly the poses where the orthonormal
//!   projection `Nᵀ S ∇V` of the dense path vanishes; its size differs by the conditioning of `Z`.
//! - the efforts and forces that hold the pose: module `held` (on both paths).
//!
//! The partition and evaluation are kept for the stability verdict. Where neither the
//! projected gradient nor the verdict is asked (`analyze`'s self-check, which judges the pose
//! by its residual and the forces of module `held`), the rows and the energy are evaluated
//! without a partition, on the dense path too (with the forces' backend: the dense path's
//! null-space basis of module `dense` is not formed). The energy and its gradient are evaluated once, by the finiteness
//! guard: the evaluation of the partition and the forces' locked system take them
//! (`System::evaluate_knowing`).

use crate::constraints::Constraints;
use crate::error::{Error, Result};
use crate::forces::Energy;
use crate::model::{JointId, Model};
use crate::solver::partition::Partition;
use crate::solver::system::{coordinate_scale, Backend, Eval, System};
use crate::state::State;
use nalgebra::DVector;

/// The quantities of one sparse partition at a configuration.
pub(super) struct Reduced<'a> {
    /// `Φ(q)` over all rows.
    pub(super) phi: DVector<f64>,
    /// Potential energy \[J\].
    pub(super) energy: f64,
    /// `‖Zᵀ ∇V‖∞` \[J\] (0 without degrees of freedom; NaN where not partitioned).
    pub(super) reduced_gradient: f64,
    /// `‖S ∇V‖∞` \[J\]: the largest generalized force, the scale of the relative tolerance.
    pub(super) force_scale: f64,
    /// Number of independent coordinates.
    pub(super) dof: usize,
    /// The system (rows included), its partition and evaluation at the configuration (where
    /// partitioned): what the stability verdict needs too.
    pub(super) sys: System<'a>,
    pub(super) solved: Option<(Partition, Eval)>,
    /// `V(q)` and `∇V(q)`, evaluated once by the finiteness guard: the evaluation of this
    /// system's partition and the forces' locked system (module `model_rows`) take them.
    pub(super) potential: (Energy, DVector<f64>),
}

/// Partitions and evaluates the rows of `model` plus its `locks` at `q` on the sparse path
/// (the sparse partition, factored by `backend`: the sparse or the tree factors), after the finiteness guard on those rows (`solver::finite`; they are evaluated once for
/// both). Without `partition`, the rows and the energy only (no partition, factors or
/// reduced gradient: `solved` is `None`, `reduced_gradient` NaN, `dof` 0).
///
/// # Errors
/// The guard's [`Error::NonFiniteConstraint`] or [`Error::NonFiniteEnergy`]; an undefined
/// energy term; [`Error::SingularPartition`] if `Φ_u` is singular.
pub(super) fn reduced<'a>(
    model: &'a Model,
    state: &State,
    locks: &[(JointId, usize, f64)],
    backend: Backend,
    partition: bool,
) -> Result<Reduced<'a>> {
    let q = &state.q;
    let mut sys = System::new(
        model,
        Constraints::new(model, locks).on_branches(state.branches.clone()),
        backend,
    );
    // Room in the triplets for a lock row on every joint coordinate: they become the first
    // rows of the forces' locked system (module `model_rows`), which then grows them in
    // place (capacity never written costs no page; `Constraints::evaluate` reserves only an
    // empty list).
    let coordinates: usize = model
        .joints
        .iter()
        .filter(|j| j.tree && !j.merged)
        .map(|j| j.kind.scalar_coordinates())
        .sum();
    sys.work
        .jac
        .entries
        .reserve_exact(crate::jet::NL * (sys.problem.cons.len() + coordinates));
    // The guard's gradient is `∇V` (one evaluation for both).
    let guarded = crate::solver::finite::guard_system_energy(&mut sys, state, "the given pose")?;
    let (guard_energy, g) = guarded.ok_or_else(|| {
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
    if !partition {
        return Ok(Reduced {
            phi: sys.phi().clone(),
            energy: guard_energy.total,
            reduced_gradient: f64::NAN,
            force_scale,
            dof: 0,
            sys,
            solved: None,
            potential: (guard_energy, g),
        });
    }
    let part = sys.partition(q);
    let eval = sys
        .evaluate_knowing(q, &part, Some((guard_energy, g.clone())))
        .ok_or_else(|| Error::SingularPartition {
            at: "the given pose".into(),
            rows: part.rows.len(),
        })?;
    Ok(Reduced {
        phi: sys.phi().clone(),
        energy: eval.energy.total,
        reduced_gradient: eval.grad_v.iter().fold(0.0f64, |a, x| a.max(x.abs())),
        force_scale,
        dof: part.independent.len(),
        sys,
        solved: Some((part, eval)),
        potential: (guard_energy, g),
    })
}
