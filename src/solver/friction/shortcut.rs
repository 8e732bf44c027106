//! What the friction verdict (module `friction`) can decide without cone programs.
//!
//! **A lower bound.** Sticking contacts on one plane ground share the ground's frame
//! `(n̂, t̂₁, t̂₂)`: their rows are force components in it. Where the group's total
//! `F = Σ_i (n_i, t_{1,i}, t_{2,i})` does not depend on `z` (every self-equilibrated
//! combination sums to zero over the group: the group alone carries a fixed load, as the feet
//! of a rigid body on one ground do), every distribution needs
//!
//! ```text
//! max_i ‖t_i‖ / n_i  ≥  Σ_i ‖t_i‖ / Σ_i n_i  ≥  ‖F_t‖ / F_n  =: b,
//! ```
//!
//! so `required_mu ≥ b` (`tan α` on a slope of `α`; `b = 0` where no group qualifies).
//!
//! **Reaching it in closed form.** A distribution needing at most `b` makes both inequalities
//! equalities: every friction force of the group is `t_i = b n_i û` (`û = F_t / ‖F_t‖`, all
//! parallel to the total, each at exactly `b`); with `b = 0` every sticking contact's friction
//! force is zero. These are linear equalities in `z`, so the least-norm distribution
//!
//! ```text
//! min_z ½ ‖D λ(z)‖²   s.t.   those equalities
//! ```
//!
//! is a least-squares problem with linear equality constraints, solved here in closed form
//! (null-space method). Where it keeps every contact pushing, every stop within its limit and
//! every other sticking contact within `b`, the remaining constraints of the verdict are
//! inactive at it, so it is the verdict's answer: `required_mu = b`, and among the
//! distributions needing `b` the one of least norm (a box on a level floor: no friction and
//! no cone program; a crate or a robot with locked joints on a slope: every foot's force
//! parallel to gravity). Otherwise the cone programs decide.
//!
//! **No pushing distribution on a line.** Where the distributions form a line (one
//! self-equilibrated combination), whether one keeps every contact pushing is an intersection
//! of intervals.

use super::conic::Holder;
use super::support::Support;
use nalgebra::{DMatrix, DVector};

/// An orthonormal basis of the null space of `a` (columns) and a least-squares solution `x`
/// of `a x = b`, from the eigen-decomposition of `aᵀ a` (eigenvalues below `10⁻¹²` of the
/// largest count as zero: rounding leaves about `10⁻¹⁶` on the zero ones); `None` when `a x = b` has no solution (residual above `tol`).
fn solve_with_null(
    a: &DMatrix<f64>,
    b: &DVector<f64>,
    tol: f64,
) -> Option<(DVector<f64>, DMatrix<f64>)> {
    let n = a.ncols();
    let (values, vectors) = crate::solver::stability::eigen::symmetric_eigen(&(a.transpose() * a));
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

/// The least-norm distribution needing exactly `bound` (module docs; `group`: the first rows
/// of the contacts whose total gives the bound, unused when `bound` is 0), when it keeps every
/// contact pushing and every stop within its limit (`pushes`) and needs no more than `bound`
/// (`need`); `None` otherwise (the cone programs decide).
pub(crate) fn at_bound(
    support: &Support,
    (bound, group): (f64, &[usize]),
    scale: f64,
    pushes: impl Fn(&DVector<f64>) -> bool,
    need: impl Fn(&DVector<f64>) -> f64,
) -> Option<DVector<f64>> {
    let (base, null) = (&support.base, &support.null);
    let m = base.len();
    // Equality rows e·λ = 0 over the multipliers.
    let mut rows: Vec<Vec<(usize, f64)>> = Vec::new();
    if bound == 0.0 {
        for &(first, h) in &support.holders {
            if matches!(h, Holder::Stick { c: Some(_) }) {
                rows.push(vec![(first + 1, 1.0)]);
                rows.push(vec![(first + 2, 1.0)]);
            }
        }
    } else {
        let t: [f64; 2] = [1, 2].map(|j| group.iter().map(|f| base[f + j]).sum());
        let norm = t[0].hypot(t[1]);
        if norm <= 0.0 {
            return None;
        }
        for &first in group {
            for j in 0..2 {
                rows.push(vec![(first + 1 + j, 1.0), (first, -bound * t[j] / norm)]);
            }
        }
    }
    let e = DMatrix::from_fn(rows.len(), m, |r, c| {
        rows[r].iter().filter(|x| x.0 == c).map(|x| x.1).sum()
    });
    // e (base + N z) = 0: z = z_p + Z y.
    let en = &e * null;
    let (zp, zn) = solve_with_null(&en, &(-(&e * base)), 1e-12 * scale)?;
    // min_y ½ ‖D (base + N z_p + N Z y)‖².
    let d = DVector::from_column_slice(&support.weight);
    let lam = if zn.ncols() == 0 {
        base + null * &zp
    } else {
        let fixed = (base + null * &zp).component_mul(&d);
        let a = DMatrix::from_fn(m, zn.ncols(), |r, _| d[r]).component_mul(&(null * &zn));
        let (y, _) = solve_with_null(&a, &(-&fixed), f64::INFINITY)?;
        base + null * (&zp + &zn * y)
    };
    let off = (&e * &lam).amax();
    let within = need(&lam) <= bound + 1e-12 * bound.max(1.0);
    (off <= 1e-12 * scale && within && pushes(&lam)).then_some(lam)
}

/// The largest lower bound `‖F_t‖ / F_n` over the groups of sticking contacts on one plane
/// ground whose total force does not depend on the distribution (module docs), with the first
/// rows of that group; `None` when no group qualifies.
pub(crate) fn lower_bound(support: &Support) -> Option<(f64, Vec<usize>)> {
    let mut planes: Vec<usize> = support.plane.iter().flatten().copied().collect();
    planes.sort_unstable();
    planes.dedup();
    let null = &support.null;
    let mut best: Option<(f64, Vec<usize>)> = None;
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
        if firsts.is_empty() || moving > 1e-9 || total[0] <= 0.0 {
            continue;
        }
        let bound = total[1].hypot(total[2]) / total[0];
        if best.as_ref().is_none_or(|b| bound > b.0) {
            best = Some((bound, firsts));
        }
    }
    best
}

/// Whether no distribution keeps every contact pushing and every stop within its limit, decided
/// without a cone program when the distributions form a line (`N` one column): each row bounds
/// `z` to an interval, and their intersection is empty even with a slack of `10⁻⁹` of the force
/// scale (`false` in every other case: the cone programs decide).
pub(crate) fn nothing_pushes_on_a_line(support: &Support, scale: f64) -> bool {
    if support.null.ncols() != 1 {
        return false;
    }
    let tol = 1e-9 * scale;
    let (mut lo, mut hi, mut never) = (f64::NEG_INFINITY, f64::INFINITY, false);
    // a + k z ≥ 0 for each bound (a the row at z = 0 plus the slack; N's column has unit
    // norm, and entries below 10⁻¹² of it are rounding).
    let mut bound = |a: f64, k: f64| {
        if k > 1e-12 {
            lo = lo.max(-a / k);
        } else if k < -1e-12 {
            hi = hi.min(-a / k);
        } else {
            never |= a < 0.0;
        }
    };
    for &(first, h) in &support.holders {
        let (b, k) = (support.base[first], support.null[(first, 0)]);
        bound(b + tol, k);
        if let Holder::Stop { limit: Some(l) } = h {
            bound(l - b + tol, -k);
        }
    }
    never || lo > hi
}
