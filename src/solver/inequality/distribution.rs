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
//! active-set iteration then releases the one pulling hardest).
//!
//! `K` comes from the partition already made, without a dense decomposition of `Φ_q`: each
//! redundant row `r` is a combination `Φ_r = cᵀ Φ_R` of the partition's independent rows `R`,
//! with `Φ_uᵀ c = Φ_r,uᵀ` (one solve with the factors of `Φ_u`), so `e_r − E_R c` is a
//! self-equilibrated combination, and these columns span the null space of `Φ_qᵀ`. They are
//! made orthonormal in the row-normalized metric (`ŷ = D⁻¹ K`, `D` dividing each row by its
//! norm): the basis the least-norm choice of `z` is taken in. (`K` was the eigenvectors of
//! `D Φ_q Φ_qᵀ D` with zero eigenvalue: the same space and the same orthonormality, at
//! `O(m³)`: 87 % of Romeo's run, whose finger stops rest on their mimicked joint's stop.)
//! Where only stops touch and none carries a force (basic multipliers below `10⁻¹²` of the
//! force scale), the basic distribution is kept as it is: zero is the least-norm one.
//! Models above `MAX_ROWS` rows keep the basic distribution.

use crate::constraints::unilateral::{Active, Unilateral};
use crate::constraints::{BlockKind, Constraints, Triplets};
use crate::model::Model;
use crate::solver::friction;
use crate::solver::partition::Partition;
use crate::solver::system::Factors;
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
    part: &Partition,
    factors: &Factors,
    mu: &mut DVector<f64>,
    options: &crate::solver::Options,
) -> Option<(Option<f64>, bool)> {
    let (rows, items) = unilateral_rows(model, cons, options);
    let m = cons.len();
    if rows.is_empty() || m > MAX_ROWS || part.redundant.is_empty() {
        return None;
    }
    // Stops that touch without a force (a finger held at its stop by its spring): the basic
    // distribution, zero, is the least-norm one, and there is no friction to choose.
    let tiny = 1e-12 * crate::solver::inequality::active_set::force_scale(model);
    let stops_only = items
        .iter()
        .all(|(a, _)| matches!(a.row, Unilateral::Limit { .. }));
    if stops_only && rows.iter().all(|&r| mu[r].abs() <= tiny) {
        return Some((None, false));
    }
    let k = null_space(model, cons, q, part, factors)?;
    // K_u: the stop and contact rows of K, replaced by an orthonormal basis U of its range
    // (K_u = U Σ Vᵀ, so K_u z = U y for z = V Σ⁻¹ y).
    let ku = DMatrix::from_fn(rows.len(), k.ncols(), |r, c| k[(rows[r], c)]);
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
    let map = DMatrix::from_fn(k.ncols(), keep.len(), |r, c| {
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

/// A basis `K = D ŷ` of the null space of `Φ_qᵀ` at `q` (`m × #redundant`), `ŷ` orthonormal
/// (module docs): from the redundant rows of `part` through the factors of `Φ_u` at `q`.
/// `None` if a solve fails or a value is not finite.
fn null_space(
    model: &Model,
    cons: &Constraints,
    q: &DVector<f64>,
    part: &Partition,
    factors: &Factors,
) -> Option<DMatrix<f64>> {
    let m = cons.len();
    let mut phi = DVector::zeros(m);
    let mut jac = Triplets::default();
    cons.evaluate(model, q, &mut phi, Some(&mut jac));
    let mut dependent = vec![usize::MAX; q.len()];
    for (k, &c) in part.dependent.iter().enumerate() {
        dependent[c] = k;
    }
    let mut redundant = vec![usize::MAX; m];
    for (k, &r) in part.redundant.iter().enumerate() {
        redundant[r] = k;
    }
    // Row norms (for `D`) and the redundant rows' entries on the dependent coordinates.
    let mut norm2 = vec![0.0; m];
    let mut rhs = DMatrix::zeros(part.rows.len(), part.redundant.len());
    let mut dense_row = vec![0.0; q.len()];
    let mut by_row: Vec<Vec<(usize, f64)>> = vec![Vec::new(); m];
    for &(i, c, v) in &jac.entries {
        by_row[i as usize].push((c as usize, v));
    }
    for (i, entries) in by_row.iter().enumerate() {
        // Duplicates summed, as in the dense Jacobian.
        for &(c, v) in entries {
            dense_row[c] += v;
        }
        for &(c, _) in entries {
            let v = std::mem::take(&mut dense_row[c]);
            norm2[i] += v * v;
            if redundant[i] != usize::MAX && dependent[c] != usize::MAX {
                rhs[(dependent[c], redundant[i])] += v;
            }
        }
    }
    // ŷ = D⁻¹ K: row i scaled by its norm (rows of zero norm by 1).
    let norm = |i: usize| if norm2[i] > 0.0 { norm2[i].sqrt() } else { 1.0 };
    let mut y = DMatrix::zeros(m, part.redundant.len());
    for (j, &r) in part.redundant.iter().enumerate() {
        let c = factors.solve_transpose(rhs.column(j).into_owned())?;
        y[(r, j)] = norm(r);
        for (k, &row) in part.rows.iter().enumerate() {
            y[(row, j)] = -c[k] * norm(row);
        }
    }
    // Orthonormal columns by modified Gram–Schmidt, twice.
    for j in 0..y.ncols() {
        for _ in 0..2 {
            for i in 0..j {
                let c = y.column(i).dot(&y.column(j));
                // Column `i` read in place (no copy per step; the same operations).
                let (prev, mut col) = y.columns_range_pair_mut(i, j);
                col.axpy(-c, &prev, 1.0);
            }
        }
        let n = y.column(j).norm();
        if !(n.is_finite() && n > 0.0) {
            return None;
        }
        y.column_mut(j).scale_mut(1.0 / n);
    }
    // K = D ŷ.
    for i in 0..m {
        let d = 1.0 / norm(i);
        y.row_mut(i).scale_mut(d);
    }
    Some(y)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::system::{Backend, System};
    use crate::urdf::{load_str, ImportOptions};

    /// The null space of `Φ_qᵀ` from the partition's redundant rows (a 4-loop ladder: three
    /// redundant rows per loop) is the one the eigenvectors of `D Φ_q Φ_qᵀ D` with zero
    /// eigenvalue span, with `D⁻¹ K` orthonormal, on both linear-algebra paths.
    #[test]
    fn null_space_from_the_partition_is_the_eigenvectors_null_space() {
        let text = crate::generate::ladder(4);
        let model = load_str(&text, "l.urdf", &ImportOptions::default())
            .unwrap()
            .model;
        let q = crate::solver::initial_state(&model).q;
        for backend in [Backend::Dense, Backend::Sparse] {
            let cons = Constraints::new(&model, &[]);
            let mut sys = System::new(&model, cons.clone(), backend);
            let part = sys.partition(&q);
            assert!(!part.redundant.is_empty());
            let eval = sys.evaluate(&q, &part).unwrap();
            let k = null_space(&model, &cons, &q, &part, &eval.factors).unwrap();
            assert_eq!(k.ncols(), part.redundant.len());
            let mut phi = DVector::zeros(cons.len());
            let mut jac = Triplets::default();
            cons.evaluate(&model, &q, &mut phi, Some(&mut jac));
            let j = jac.to_dense();
            let d: Vec<f64> = (0..j.nrows())
                .map(|r| {
                    let n = j.row(r).norm();
                    if n > 0.0 {
                        1.0 / n
                    } else {
                        1.0
                    }
                })
                .collect();
            // Self-equilibrated: Φ_qᵀ K = 0 (relative to the row norms).
            let residual = (j.transpose() * &k).amax();
            assert!(residual < 1e-12, "{backend:?}: ‖Φ_qᵀ K‖ = {residual:e}");
            // ŷ = D⁻¹ K orthonormal.
            let y = DMatrix::from_fn(k.nrows(), k.ncols(), |r, c| k[(r, c)] / d[r]);
            let gram = y.transpose() * &y - DMatrix::identity(k.ncols(), k.ncols());
            assert!(
                gram.amax() < 1e-12,
                "{backend:?}: ŷᵀŷ − I = {:e}",
                gram.amax()
            );
            // The same space as the eigenvectors with zero eigenvalue: equal projectors.
            let mut jd = j.clone();
            for r in 0..jd.nrows() {
                jd.row_mut(r).scale_mut(d[r]);
            }
            let (values, vectors) = crate::solver::eigen::symmetric_eigen(&(&jd * jd.transpose()));
            let top = values.amax();
            let null: Vec<usize> = (0..values.len())
                .filter(|&i| values[i] <= 1e-12 * top)
                .collect();
            assert_eq!(null.len(), k.ncols());
            let e = DMatrix::from_fn(values.len(), null.len(), |r, c| vectors[(r, null[c])]);
            let gap = (&y * y.transpose() - &e * e.transpose()).amax();
            assert!(gap < 1e-9, "{backend:?}: projectors differ by {gap:e}");
        }
    }
}
