//! The dense verification path (models up to 40 bodies' coordinates): an orthonormal basis
//! `N` of the null space of `D Φ_q S` from a full-pivoting partition and a QR factorization,
//! the projected gradient `Nᵀ S ∇V`, and the minimum-norm efforts `τ` of
//! `Nᵀ S B τ = Nᵀ S ∇V` (by SVD), as described in the parent module.

use super::unilateral::UnilateralCheck;
use super::{closures, Closure, Tolerances, Unilaterals};
use crate::constraints::unilateral::Active;
use crate::constraints::Constraints;
use crate::error::{Error, Result};
use crate::forces::potential;
use crate::jet::scatter;
use crate::model::Model;
use crate::solver::system::Scaling;
use crate::state::State;
use nalgebra::{DMatrix, DVector};

/// Everything the checks share: `Φ`, the scaled gradient and the null-space basis.
pub(super) struct Projection {
    pub(super) phi: DVector<f64>,
    pub(super) grad_s: DVector<f64>,
    pub(super) scale: Vec<f64>,
    pub(super) null: DMatrix<f64>,
    pub(super) energy: f64,
    pub(super) cons: Constraints,
}

pub(super) fn project(model: &Model, state: &State) -> Result<Projection> {
    let cons = Constraints::new(model, &crate::solver::lock_values(model))
        .on_branches(state.branches.clone());
    let mut phi = DVector::zeros(cons.len());
    let mut jac = crate::constraints::Triplets::default();
    cons.evaluate(model, &state.q, &mut phi, Some(&mut jac));
    let n = state.q.len();
    let Scaling {
        columns: scale,
        rows: row_scale,
    } = Scaling::new(model, &cons);
    let mut j = jac.to_dense();
    for c in 0..n {
        j.column_mut(c).scale_mut(scale[c]);
    }
    let mut g = DVector::zeros(n);
    let e = potential(model, &state.branches, &state.q, &mut g, None).ok_or_else(|| {
        crate::forces::undefined_term(model, &state.branches, &state.q).unwrap_or(
            Error::SingularPartition {
                at: "the given pose".into(),
                rows: 0,
            },
        )
    })?;
    for c in 0..n {
        g[c] *= scale[c];
    }
    // Null space of the dimensionless Jacobian D Φ_q S: Z = [−Φ_u⁻¹ Φ_v; I] for the rows and
    // columns that full pivoting finds independent, made orthonormal by a QR factorization.
    // The subspace does not depend on that choice.
    for r in 0..cons.len() {
        j.row_mut(r).scale_mut(row_scale[r]);
    }
    let part = crate::solver::partition::partition(&j, &vec![1.0; cons.len()], &vec![1.0; n]);
    let (r, dof) = (part.rows.len(), part.independent.len());
    let phi_u = DMatrix::from_fn(r, r, |a, b| j[(part.rows[a], part.dependent[b])]);
    let phi_v = DMatrix::from_fn(r, dof, |a, b| j[(part.rows[a], part.independent[b])]);
    let h = if r > 0 {
        phi_u
            .lu()
            .solve(&(-phi_v))
            .ok_or_else(|| Error::SingularPartition {
                at: "the given pose".into(),
                rows: r,
            })?
    } else {
        DMatrix::zeros(0, dof)
    };
    let mut z = DMatrix::zeros(n, dof);
    for b in 0..dof {
        z[(part.independent[b], b)] = 1.0;
        for (k, &c) in part.dependent.iter().enumerate() {
            z[(c, b)] = h[(k, b)];
        }
    }
    let null = if dof > 0 { z.qr().q() } else { z };
    Ok(Projection {
        phi,
        grad_s: g,
        scale,
        null,
        energy: e.total,
        cons,
    })
}

/// What the dense checks find at a pose.
pub(super) struct DenseChecks {
    /// `Φ` at the pose.
    pub(super) phi: DVector<f64>,
    /// Potential energy \[J\].
    pub(super) energy: f64,
    /// `‖Nᵀ S ∇V‖∞` before the stops and contacts carry their share \[J\].
    pub(super) projected_gradient: f64,
    /// `‖S ∇V‖∞`, the scale of the forces \[J\].
    pub(super) force_scale: f64,
    /// Closure errors per joint.
    pub(super) closure: Vec<Closure>,
    /// Minimum-norm efforts of the scalar tree coordinates.
    pub(super) efforts: DVector<f64>,
    /// What no coordinate's effort can take.
    pub(super) unassigned: f64,
    /// The stops and contacts at the pose (module `unilateral`).
    pub(super) unilateral: UnilateralCheck,
    /// The stops and contacts that carry a force (the stability's tangent space).
    pub(super) strong: Vec<Active>,
    /// The touching stops and contacts that carry no force.
    pub(super) weak: Vec<Active>,
}

/// The dense checks: closure, the share of the load the stops and contacts carry (module
/// `unilateral`), then the minimum-norm efforts `τ` of `Nᵀ S B τ = Nᵀ S (∇V − carried)`.
pub(super) fn dense_checks(
    model: &Model,
    state: &State,
    tol: &Tolerances,
    uni: &Unilaterals,
    coords: &[(crate::model::JointId, usize, crate::jet::Scalar)],
) -> Result<DenseChecks> {
    let mut p = project(model, state)?;
    let n = state.q.len();
    let closure = closures(model, &p.cons, &p.phi, tol.constraint);
    let projected_gradient = (p.null.transpose() * &p.grad_s).amax();
    let force_scale = p.grad_s.amax();
    // The stops and contacts take their share of the load first.
    let tau = tol.force + tol.relative * force_scale;
    let (unilateral, carried, strong, weak) =
        super::unilateral::check(model, state, uni, &p, tol.constraint, tau);
    p.grad_s -= carried;
    // The (scaled) gradients of the scalar coordinates.
    let b_cols: Vec<DVector<f64>> = coords
        .iter()
        .map(|(id, _, s)| {
            let mut g = DVector::zeros(n);
            scatter(&model.joint(*id).bodies, s, 1.0, &mut g, None);
            for c in 0..n {
                g[c] *= p.scale[c];
            }
            g
        })
        .collect();
    let rhs = p.null.transpose() * &p.grad_s;
    let (efforts, unassigned) = if b_cols.is_empty() || p.null.ncols() == 0 {
        (DVector::zeros(b_cols.len()), rhs.amax())
    } else {
        let b = DMatrix::from_columns(&b_cols);
        let m = p.null.transpose() * b;
        let tau = crate::solver::eigen::svd(m.clone(), true, true)
            .and_then(|svd| {
                let eps = 1e-10 * svd.singular_values.max();
                svd.solve(&rhs, eps).ok()
            })
            .unwrap_or_else(|| DVector::zeros(b_cols.len()));
        let rest = (&rhs - m * &tau).amax();
        (tau, rest)
    };
    Ok(DenseChecks {
        phi: p.phi,
        energy: p.energy,
        projected_gradient,
        force_scale,
        closure,
        efforts,
        unassigned,
        unilateral,
        strong,
        weak,
    })
}
