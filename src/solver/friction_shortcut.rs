//! What the friction verdict (module `friction`) can decide without cone programs, or with
//! one instead of several.
//!
//! **No friction needed.** The least-norm distribution without any friction force,
//!
//! ```text
//! min_z ½ ‖D λ(z)‖²   s.t.   t_i(z) = 0   (every sticking contact),
//! ```
//!
//! is a least-squares problem with linear equality constraints, solved here in closed form
//! (null-space method). Where it keeps every contact pushing and every stop within its limit,
//! the inequalities of the cone program `least(0)` are inactive at it, so it is that program's
//! answer: `required_mu = 0` (a box on a level floor, a robot standing symmetrically).
//!
//! **A lower bound.** Sticking contacts on one plane ground share the ground's frame
//! `(n̂, t̂₁, t̂₂)`: their rows are force components in it. Where the group's total
//! `F = Σ_i (n_i, t_{1,i}, t_{2,i})` does not depend on `z` (every self-equilibrated
//! combination sums to zero over the group: the group alone carries a fixed load, as the feet
//! of a rigid body on one ground do), every distribution needs
//!
//! ```text
//! max_i ‖t_i‖ / n_i  ≥  Σ_i ‖t_i‖ / Σ_i n_i  ≥  ‖F_t‖ / F_n,
//! ```
//!
//! so `required_mu ≥ ‖F_t‖ / F_n` (`tan α` on a slope of `α`). The iteration of module
//! `friction` starts from a distribution within that bound when the cone program
//! `level(bound)` finds one, and stops there: the bound is reached (a crate or a robot with
//! locked joints on a slope: one cone program instead of five to eight).

use super::conic::Holder;
use super::friction::Support;
use nalgebra::{DMatrix, DVector};

/// The rows `first + 1`, `first + 2` of every sticking contact (weights `Some`).
fn friction_rows(support: &Support) -> Vec<usize> {
    support
        .holders
        .iter()
        .filter(|(_, h)| matches!(h, Holder::Stick { c: Some(_) }))
        .flat_map(|&(first, _)| [first + 1, first + 2])
        .collect()
}

/// An orthonormal basis of the null space of `a` (columns) and a least-squares solution `x`
/// of `a x = b`, from the eigen-decomposition of `aᵀ a` (eigenvalues below `10⁻¹²` of the
/// largest count as zero: rounding leaves about `10⁻¹⁶` on the zero ones); `None` when `a x = b` has no solution (residual above `tol`).
fn solve_with_null(
    a: &DMatrix<f64>,
    b: &DVector<f64>,
    tol: f64,
) -> Option<(DVector<f64>, DMatrix<f64>)> {
    let n = a.ncols();
    let (values, vectors) = super::stability::eigen::symmetric_eigen(&(a.transpose() * a));
    let top = values.amax();
    if !top.is_finite() {
        return None;
    }
    let (mut x, mut null) = (DVector::zeros(n), Vec::new());
    let atb = a.transpose() * b;
    for i in 0..values.len() {
        let v = vectors.column(i);
        if top > 0.0 && values[i] > 1e-12 * top {
            x += v * (v.dot(&atb) / values[i]);
        } else {
            null.push(v.into_owned());
        }
    }
    if (a * &x - b).amax() > tol {
        return None;
    }
    let null = if null.is_empty() {
        DMatrix::zeros(n, 0)
    } else {
        DMatrix::from_columns(&null)
    };
    Some((x, null))
}

/// The least-norm distribution without friction force (module docs), when it keeps every
/// contact pushing and every stop within its limit (`pushes`); `None` otherwise (no such
/// distribution, or one the cone program must find).
pub(crate) fn without_friction(
    support: &Support,
    scale: f64,
    pushes: impl Fn(&DVector<f64>) -> bool,
) -> Option<DVector<f64>> {
    let rows = friction_rows(support);
    let (base, null) = (&support.base, &support.null);
    let k = null.ncols();
    // t(z) = T base + T N z = 0: z = z_p + Z y.
    let tn = DMatrix::from_fn(rows.len(), k, |r, c| null[(rows[r], c)]);
    let tb = DVector::from_fn(rows.len(), |r, _| -base[rows[r]]);
    let (zp, zn) = solve_with_null(&tn, &tb, 1e-12 * scale)?;
    // min_y ½ ‖D (base + N z_p + N Z y)‖².
    let d = DVector::from_column_slice(&support.weight);
    let fixed = (base + null * &zp).component_mul(&d);
    let lam = if zn.ncols() == 0 {
        base + null * &zp
    } else {
        let a = DMatrix::from_fn(base.len(), zn.ncols(), |r, _| d[r]).component_mul(&(null * &zn));
        let (y, _) = solve_with_null(&a, &(-&fixed), f64::INFINITY)?;
        base + null * (&zp + &zn * y)
    };
    let friction = rows.iter().map(|&r| lam[r].abs()).fold(0.0, f64::max);
    (friction <= 1e-12 * scale && pushes(&lam)).then_some(lam)
}

/// The largest lower bound `‖F_t‖ / F_n` over the groups of sticking contacts on one plane
/// ground whose total force does not depend on the distribution (module docs); `None` when no
/// group qualifies.
pub(crate) fn lower_bound(support: &Support) -> Option<f64> {
    let mut planes: Vec<usize> = support.plane.iter().flatten().copied().collect();
    planes.sort_unstable();
    planes.dedup();
    let null = &support.null;
    let mut best: Option<f64> = None;
    for p in planes {
        let firsts: Vec<usize> = support
            .holders
            .iter()
            .zip(&support.plane)
            .filter(|((_, h), q)| matches!(h, Holder::Stick { c: Some(_) }) && **q == Some(p))
            .map(|((first, _), _)| *first)
            .collect();
        let mut total = [0.0f64; 3];
        let mut moving = 0.0f64;
        for j in 0..3 {
            total[j] = firsts.iter().map(|f| support.base[f + j]).sum();
            for c in 0..null.ncols() {
                let s: f64 = firsts.iter().map(|f| null[(f + j, c)]).sum();
                moving = moving.max(s.abs());
            }
        }
        // The columns of N are orthonormal (entries at most 1): a sum below 10⁻⁹ is zero.
        if moving > 1e-9 || total[0] <= 0.0 {
            continue;
        }
        let bound = total[1].hypot(total[2]) / total[0];
        best = Some(best.map_or(bound, |b: f64| b.max(bound)));
    }
    best
}
