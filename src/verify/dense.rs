//! The dense verification path (models up to 40 bodies' coordinates): an orthonormal basis
//! `N` of the null space of `D Φ_q S` from a full-pivoting partition and a QR factorization,
//! and the projected gradient `Nᵀ S ∇V`, as described in the parent module (the efforts and
//! forces are module `held`'s, on both paths).

use crate::constraints::Constraints;
use crate::error::{Error, Result};
use crate::forces::potential;
use crate::model::Model;
use crate::solver::system::Scaling;
use crate::state::State;
use nalgebra::{DMatrix, DVector};

/// Everything the checks share: `Φ`, the scaled gradient and the null-space basis.
pub(super) struct Projection {
    pub(super) phi: DVector<f64>,
    pub(super) grad_s: DVector<f64>,
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
        null,
        energy: e.total,
        cons,
    })
}
