//! The force distribution of a statically indeterminate support.
//!
//! At a rest pose `V_qᵀ = Φ_qᵀ μ` over all rows, equalities and active stops and contacts. When
//! rows are redundant (a box flat on four vertices: four rows for three degrees of freedom) the
//! partition's multipliers `μ_b` are one solution (basic: zero on the redundant rows). Every
//! solution is `μ = μ_b + K z`, `K` a basis of the null space of `Φ_qᵀ` (the self-equilibrated
//! combinations of the rows). With `K_u` its stop and contact rows, the distributions of the
//! stop and contact multipliers are `λ = λ_b + K_u z`, which module `friction` searches for
//! the one needing the least friction (every contact pushing, every stop within its
//! effort), ties broken by the least norm: the symmetric box gets `m g / 4` on each vertex and
//! no friction, and the joint reactions follow the same distribution (the equality rows' part
//! of `K z`). Where no distribution keeps every contact pushing the basic one is kept (the
//! active-set iteration then releases the one pulling hardest). `K` comes from the
//! eigenvectors of `D Φ_q Φ_qᵀ D` (`D` normalizing the rows) with eigenvalues below `10⁻¹²`
//! of the largest (rounding leaves about `10⁻¹⁶` on the zero ones); models above `MAX_ROWS`
//! rows keep the basic distribution.

use crate::constraints::unilateral::{Active, Unilateral};
use crate::constraints::{BlockKind, Constraints, Triplets};
use crate::model::Model;
use crate::solver::friction;
use nalgebra::{DMatrix, DVector};

/// Largest number of rows redistributed (the eigen-decomposition is `O(m³)`).
const MAX_ROWS: usize = 600;

/// The rows of the stops and contacts in `cons`, and each stop and contact with the friction
/// coefficient of a sticking contact.
fn unilateral_rows(
    model: &Model,
    cons: &Constraints,
    options: &crate::solver::Options,
) -> (Vec<usize>, Vec<(Active, Option<f64>)>) {
    let (mut rows, mut items) = (Vec::new(), Vec::new());
    for b in &cons.blocks {
        if let BlockKind::Unilateral(a) = &b.kind {
            for k in 0..a.row_count() {
                rows.push(b.first + k);
            }
            let mu = match a.row {
                Unilateral::Contact { point, .. } if a.anchor.is_some() => {
                    model.contact_points[point].settings.mu.or(options.mu)
                }
                _ => None,
            };
            items.push((*a, mu));
        }
    }
    (rows, items)
}

/// Replaces the full multiplier vector `mu` (basic: zero on redundant rows) by the
/// distribution of module `friction` (the least friction, then the least norm, with every
/// contact pushing), when one exists; returns its `required_mu` (`None` without sticking
/// contacts) and whether it slips (`None` when the basic distribution is kept).
pub(crate) fn spread(
    model: &Model,
    cons: &Constraints,
    q: &DVector<f64>,
    mu: &mut DVector<f64>,
    options: &crate::solver::Options,
) -> Option<(Option<f64>, bool)> {
    let (rows, items) = unilateral_rows(model, cons, options);
    let m = cons.len();
    if rows.is_empty() || m > MAX_ROWS {
        return None;
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
        return None;
    }
    let null: Vec<usize> = (0..m).filter(|&k| values[k] <= 1e-12 * top).collect();
    if null.is_empty() {
        return None;
    }
    // K: columns D ŷ (module docs); K_u its stop and contact rows, replaced by an
    // orthonormal basis U of its range (K_u = U Σ Vᵀ, so K_u z = U y for z = V Σ⁻¹ y).
    let k = DMatrix::from_fn(m, null.len(), |r, c| d[r] * vectors[(r, null[c])]);
    let ku = DMatrix::from_fn(rows.len(), null.len(), |r, c| k[(rows[r], c)]);
    // An orthonormal basis of range(K_u) from the eigenvectors of K_uᵀ K_u = V Λ Vᵀ:
    // U = K_u V Λ^(-1/2), and K_u z = U y for z = V Λ^(-1/2) y. (nalgebra's SVD was seen to
    // lose accuracy on K_u with repeated singular values: 3e-2 recomposition error on the
    // level box.)
    let (eig_values, eig_vectors) = crate::solver::eigen::symmetric_eigen(&(ku.transpose() * &ku));
    let lmax = eig_values.amax();
    if !lmax.is_finite() {
        return None;
    }
    let keep: Vec<usize> = (0..eig_values.len())
        .filter(|&i| eig_values[i] > 1e-20 * lmax && lmax > 0.0)
        .collect();
    let map = DMatrix::from_fn(null.len(), keep.len(), |r, c| {
        eig_vectors[(r, keep[c])] / eig_values[keep[c]].sqrt()
    });
    let support = friction::holders_of(model, &items)
        .support(DVector::from_fn(rows.len(), |r, _| mu[rows[r]]), &ku * &map);
    let out = friction::distribute(
        &support,
        crate::solver::inequality::active_set::force_scale(model),
    )?;
    let y = support.null.transpose() * (&out.forces - &support.base);
    *mu += &k * (&map * y);
    // The stop and contact rows exactly as chosen (`K z` reproduces them to rounding; the
    // equality rows follow through it).
    for (r, &row) in rows.iter().enumerate() {
        mu[row] = out.forces[r];
    }
    Some((out.required_mu, out.slipping))
}
