//! The force distribution of a statically indeterminate support.
//!
//! At a rest pose `V_qᵀ = Φ_qᵀ μ` over all rows, equalities and active stops and contacts. When
//! rows are redundant (a box flat on four vertices: four rows for three degrees of freedom) the
//! partition's multipliers `μ_b` are one solution (basic: zero on the redundant rows). Every
//! solution is `μ = μ_b + K z`, `K` a basis of the null space of `Φ_qᵀ` (the self-equilibrated
//! combinations of the rows). restpose reports the one whose stop and contact multipliers `λ`
//! (rows `u`) have the least norm:
//!
//! `z = −K_u⁺ μ_b,u`, `μ = μ_b + K z`,
//!
//! so the symmetric box gets `m g / 4` on each vertex, and the joint reactions follow the same
//! distribution (the equality rows' part of `K z`). If that distribution would make a contact
//! pull or a stop push the wrong way (below `−threshold`), the basic one is kept. `K` comes from
//! the eigenvectors of `D Φ_q Φ_qᵀ D` (`D` normalizing the rows) with eigenvalues below
//! `10⁻¹²` of the largest (rounding leaves about `10⁻¹⁶` on the zero ones); models above
//! `MAX_ROWS` rows keep the basic distribution.

use crate::constraints::{BlockKind, Constraints, Triplets};
use crate::model::Model;
use nalgebra::{DMatrix, DVector};

/// Largest number of rows redistributed (the eigen-decomposition is `O(m³)`).
const MAX_ROWS: usize = 600;

/// The rows of the stops and contacts in `cons`, and which of them are sign-constrained (the
/// first row of each: a normal force or a stop's effort).
fn unilateral_rows(cons: &Constraints) -> (Vec<usize>, Vec<bool>) {
    let (mut rows, mut signed) = (Vec::new(), Vec::new());
    for b in &cons.blocks {
        if let BlockKind::Unilateral(a) = &b.kind {
            for k in 0..a.row_count() {
                rows.push(b.first + k);
                signed.push(k == 0);
            }
        }
    }
    (rows, signed)
}

/// Replaces the full multiplier vector `mu` (basic: zero on redundant rows) by the one whose
/// stop and contact multipliers have the least norm (module docs), when that keeps their signs.
pub(crate) fn spread(
    model: &Model,
    cons: &Constraints,
    q: &DVector<f64>,
    mu: &mut DVector<f64>,
    threshold: f64,
) {
    let (rows, signed) = unilateral_rows(cons);
    let m = cons.len();
    if rows.is_empty() || m > MAX_ROWS {
        return;
    }
    let mut phi = DVector::zeros(m);
    let mut jac = Triplets::default();
    cons.evaluate(model, q, &mut phi, Some(&mut jac));
    let mut j = jac.to_dense();
    let mut d = vec![1.0; m];
    for (r, dr) in d.iter_mut().enumerate() {
        let n = j.row(r).norm();
        if n > 0.0 {
            *dr = 1.0 / n;
            j.row_mut(r).scale_mut(*dr);
        }
    }
    let (values, vectors) = crate::solver::eigen::symmetric_eigen(&(&j * j.transpose()));
    let top = values.amax();
    if !top.is_finite() {
        return;
    }
    let null: Vec<usize> = (0..m).filter(|&k| values[k] <= 1e-12 * top).collect();
    if null.is_empty() {
        return;
    }
    // K: columns D ŷ (module docs); K_u its stop and contact rows.
    let k = DMatrix::from_fn(m, null.len(), |r, c| d[r] * vectors[(r, null[c])]);
    let ku = DMatrix::from_fn(rows.len(), null.len(), |r, c| k[(rows[r], c)]);
    let lu = DVector::from_fn(rows.len(), |r, _| mu[rows[r]]);
    let Some(svd) = crate::solver::eigen::svd(ku, true, true) else {
        return;
    };
    let eps = 1e-12 * svd.singular_values.amax().max(1e-300);
    let Ok(z) = svd.solve(&(-lu), eps) else {
        return;
    };
    let spread = &*mu + &k * z;
    if rows
        .iter()
        .zip(&signed)
        .any(|(&r, &s)| s && spread[r] < -threshold)
    {
        return;
    }
    *mu = spread;
}
