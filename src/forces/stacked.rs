//! The energy terms whose Hessians every Newton iteration forms, evaluated with their local
//! Hessians on the stack instead of the boxed ones of [`crate::jet::Scalar`]: gravity and dead
//! loads `wᵀ (r + A(p) s)`, and joint springs and efforts on revolute angles
//! `θ = atan2(y₀ · x₁, x₀ · x₁)`.
//!
//! Values and gradients are those of the generic path to the last bit (the same operations in
//! the same order). The weighted point's Hessian is too; the angle's is the generic
//! `∇²θ = sym(m)`,
//!
//! `m = (∇S ∇Cᵀ − ∇C ∇Sᵀ + C ∇²S − S ∇²C) / ρ − ∇θ ∇ρᵀ / ρ`,   `ρ = S² + C²`,
//!
//! regrouped (see [`revolute_angle`]; equal to rounding), and a spring `U(θ)` adds
//! `U'' ∇θ ∇θᵀ + U' ∇²θ`; but `θ` depends on the Euler parameters only, so its Hessian is
//! formed over those 8 coordinates of the pair (not 14), and no term allocates.
//!
//! Where no Hessian is asked for (every evaluation of the line search and of the reduced
//! gradient), the same terms give their value and gradient alone: `θ` and
//! `∇θ = (C ∇S − S ∇C) / ρ` by the first half of [`revolute_angle`]
//! ([`revolute_angle_gradient`]), a weighted point by its side 0 alone
//! ([`weighted_point_gradient`]); both to the last bit the generic path's.

use crate::jet::closed::quadratic_form;
use crate::jet::{HessianSink, LVec, Pair};
use crate::kinematics::{revolute_first_order as first_order, RevoluteFirstOrder as FirstOrder};
use crate::math::b_matrix;
use crate::model::{BodyId, Joint};
use nalgebra::{DVector, Matrix3, SMatrix, Vector3, Vector4};

/// The Euler-parameter coordinates of a body pair (local indices).
const P: [usize; 8] = crate::jet::EULER;

/// `c ∇f` into `grad` and `c ∇²f` into `hess` (as [`crate::jet::scatter`]), for an `f` whose
/// Hessian is zero outside the Euler parameters (`hp` over [`P`]).
fn scatter(
    bodies: &[Option<BodyId>; 2],
    g: &LVec,
    hp: &SMatrix<f64, 8, 8>,
    c: f64,
    grad: &mut DVector<f64>,
    hess: &mut dyn HessianSink,
) {
    scatter_gradient(bodies, g, c, grad);
    hess.add_euler_block(bodies, hp, c);
}

/// `c ∇f` into `grad` (as [`crate::jet::scatter`] adds the gradient).
pub(crate) fn scatter_gradient(
    bodies: &[Option<BodyId>; 2],
    g: &LVec,
    c: f64,
    grad: &mut DVector<f64>,
) {
    // Each side's 7 entries as one slice (one bounds check, not one per entry).
    let grad = grad.as_mut_slice();
    for (k, body) in bodies.iter().enumerate() {
        if let Some(b) = body {
            let out = &mut grad[7 * b.0..7 * b.0 + 7];
            for (i, o) in out.iter_mut().enumerate() {
                *o += c * g[7 * k + i];
            }
        }
    }
}

/// `wᵀ (r₀ + A(p₀) s)` of side 0 (the one `body`) with its gradient into `grad` and Hessian
/// into `hess` (as the general `closed::weighted_point` and [`crate::jet::scatter`] with
/// `c = 1`: the value and gradient by [`weighted_point_gradient`], the Hessian `2 M(s, w)` on
/// `p₀ p₀` added to zeros as `linear_hessian_euler` adds it); returns the value. Nothing is
/// formed for the empty side 1.
pub(crate) fn weighted_point(
    body: BodyId,
    q: &DVector<f64>,
    a0: &Matrix3<f64>,
    s: &Vector3<f64>,
    w: &Vector3<f64>,
    grad: &mut DVector<f64>,
    hess: &mut dyn HessianSink,
) -> f64 {
    let v = weighted_point_gradient(body, q, a0, s, w, grad);
    let m = quadratic_form(s, w) * 2.0;
    let mut h = SMatrix::<f64, 8, 8>::zeros();
    for i in 0..4 {
        for j in 0..4 {
            h[(i, j)] += m[(i, j)];
        }
    }
    hess.add_euler_block(&[Some(body), None], &h, 1.0);
    v
}

/// `wᵀ (r₀ + A(p₀) s)` of side 0 (the one `body`) with its gradient added into `grad`, without
/// the Hessian: the general `closed::weighted_point` and [`crate::jet::scatter`] with `c = 1`
/// to the last bit (the same operations on side 0; nothing formed for the empty side 1),
/// with `a0 = A(p₀)` and `r₀`, `p₀` read from `q` (as [`crate::jet::pair_of`] reads them);
/// returns the value.
pub(crate) fn weighted_point_gradient(
    body: BodyId,
    q: &DVector<f64>,
    a0: &Matrix3<f64>,
    s: &Vector3<f64>,
    w: &Vector3<f64>,
    grad: &mut DVector<f64>,
) -> f64 {
    let x = &q.as_slice()[7 * body.0..7 * body.0 + 7];
    let v = a0 * s + Vector3::new(x[0], x[1], x[2]);
    let gp = b_matrix(&Vector4::new(x[3], x[4], x[5], x[6]), s).tr_mul(w);
    let out = &mut grad.as_mut_slice()[7 * body.0..7 * body.0 + 7];
    // `linear_gradient` into zeros (`t = 1` on the position), then `scatter`'s `1 · g`.
    for i in 0..3 {
        out[i] += 1.0 * (0.0 + 1.0 * w[i]);
    }
    for i in 0..4 {
        out[3 + i] += 1.0 * (0.0 + gp[i]);
    }
    w.dot(&v)
}

/// A revolute angle `θ` (not yet on its branch), its gradient and its Hessian over [`P`].
pub(crate) struct Angle {
    pub(crate) v: f64,
    pub(crate) g: LVec,
    pub(crate) h: SMatrix<f64, 8, 8>,
}

/// `θ` of the revolute `joint` at `pair` (as [`crate::jet::closed::revolute_angle`]; the
/// value and gradient to the last bit, the Hessian regrouped), over plain arrays. With
/// `S = y₀ · x₁`, `C = x₀ · x₁`, `ρ = S² + C²` frozen, the body-0 direction
/// `w = A(p₀) (C ŷ₀ − S x̂₀) / ρ` has `∇²(w · x₁) = (C ∇²S − S ∇²C) / ρ` (`w` is linear in
/// `ŷ₀`, `x̂₀`), and the antisymmetric `∇S ∇Cᵀ − ∇C ∇Sᵀ` drops out of `sym(m)`, so
///
/// `∇²θ = ∇²(w · x₁) − ∇θ ∇ρᵀ / 2ρ − ∇ρ ∇θᵀ / 2ρ`,   `∇ρ / 2ρ = (S ∇S + C ∇C) / ρ`,
///
/// with `∇²(w · x₁)` as [`crate::jet::closed::dot_hessian_euler`] forms it: `B_wᵀ B_x₁` on
/// the `p₀ p₁` block (and its transpose), `2 M(ŵ, x₁)` on `p₀ p₀`, `2 M(x̂₁, w)` on `p₁ p₁`.
/// One dot-product Hessian instead of two, no division per entry.
pub(crate) fn revolute_angle(joint: &Joint, pair: &Pair, a: [&Matrix3<f64>; 2]) -> Angle {
    let FirstOrder {
        v,
        g: n,
        x0,
        y0,
        x1,
        bx0,
        by0,
        bx1,
        b0x,
        b0y,
        b1x,
        gs,
        gc,
        s,
        c,
        rho,
    } = first_order(pair, a, &crate::jet::closed::frame_rotations(joint));
    let (cr, sr) = (c / rho, s / rho);
    let (wb, w, bw) = (by0 * cr - bx0 * sr, y0 * cr - x0 * sr, b0y * cr - b0x * sr);
    let mut h = SMatrix::<f64, 8, 8>::zeros();
    h.fixed_view_mut::<4, 4>(0, 0)
        .copy_from(&(quadratic_form(&wb, &x1) * 2.0));
    h.fixed_view_mut::<4, 4>(4, 4)
        .copy_from(&(quadratic_form(&bx1, &w) * 2.0));
    let pp = bw.tr_mul(&b1x);
    h.fixed_view_mut::<4, 4>(0, 4).copy_from(&pp);
    h.fixed_view_mut::<4, 4>(4, 0).copy_from(&pp.transpose());
    let (mut pn, mut pd) = ([0.0f64; 8], [0.0f64; 8]);
    for (a, &i) in P.iter().enumerate() {
        (pn[a], pd[a]) = (n[i], (gs[i] * s + gc[i] * c) / rho);
    }
    // On and below the diagonal, mirrored: the blocks above are symmetric to the last bit,
    // and each entry and its mirror subtract the same products summed in swapped order (the
    // same numbers as forming both).
    let hm = h.as_mut_slice();
    for b in 0..8 {
        for a in b..8 {
            let x = hm[8 * b + a] - (pn[a] * pd[b] + pd[a] * pn[b]);
            hm[8 * b + a] = x;
            hm[8 * a + b] = x;
        }
    }
    Angle { v, g: n, h }
}

/// `θ` of the revolute `joint` at `pair` and its gradient alone (no Hessian): the value and
/// gradient of [`revolute_angle`], the same operations.
pub(crate) fn revolute_angle_gradient(
    joint: &Joint,
    pair: &Pair,
    a: [&Matrix3<f64>; 2],
) -> (f64, LVec) {
    let f = first_order(pair, a, &crate::jet::closed::frame_rotations(joint));
    (f.v, f.g)
}

/// `c U(θ)` for `U` given by `(u, du, ddu)` at `θ` (`Scalar::compose`; `None`: `U = θ`):
/// its gradient into `grad` and Hessian `U'' ∇θ ∇θᵀ + U' ∇²θ` into `hess`, formed on and
/// below the diagonal and mirrored: [`revolute_angle`]'s `∇²θ` is symmetric to the last bit
/// (each entry and its mirror are the same products summed in swapped order), and so is
/// `∇θ ∇θᵀ`, so each mirrored entry is the number its own formula gives.
pub(crate) fn scatter_angle(
    bodies: &[Option<BodyId>; 2],
    theta: &Angle,
    law: Option<(f64, f64)>,
    c: f64,
    grad: &mut DVector<f64>,
    hess: &mut dyn HessianSink,
) {
    let Some((du, ddu)) = law else {
        scatter(bodies, &theta.g, &theta.h, c, grad, hess);
        return;
    };
    let mut pg = [0.0f64; 8];
    for (a, &i) in P.iter().enumerate() {
        pg[a] = theta.g[i];
    }
    let mut h = SMatrix::<f64, 8, 8>::zeros();
    let (hm, th) = (h.as_mut_slice(), theta.h.as_slice());
    for b in 0..8 {
        for a in b..8 {
            let v = pg[a] * pg[b] * ddu + th[8 * b + a] * du;
            hm[8 * b + a] = v;
            hm[8 * a + b] = v;
        }
    }
    scatter(bodies, &(theta.g * du), &h, c, grad, hess);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::jet::hess_or_zero;
    use crate::jet::testing::{sample_joint, sample_pair};
    use nalgebra::DMatrix;

    /// The coordinates of bodies `0..=body` with side 0 of `pair` as body `body`'s.
    fn coordinates(body: usize, pair: &Pair) -> DVector<f64> {
        let mut q = DVector::zeros(7 * body + 7);
        q.rows_mut(7 * body, 3).copy_from(&pair.r[0]);
        q.rows_mut(7 * body + 3, 4).copy_from(&pair.p[0]);
        q
    }

    /// The gradient and Hessian over two bodies that `f` adds to zeros.
    fn hessian_of(
        f: impl Fn(&mut DVector<f64>, &mut DMatrix<f64>),
    ) -> (DVector<f64>, DMatrix<f64>) {
        let mut g = DVector::zeros(14);
        let mut h = DMatrix::zeros(14, 14);
        f(&mut g, &mut h);
        (g, h)
    }

    /// The stacked terms equal the boxed generic path: bit for bit the angle's value and
    /// gradient and all of a weighted point, the angle's regrouped Hessian (spring `U(θ)`,
    /// effort `−τ θ`) to rounding (`1e-13` of its largest entry).
    #[test]
    fn stacked_terms_equal_the_boxed_path() {
        let j = sample_joint(crate::model::JointKind::Revolute);
        let bodies = j.bodies;
        for seed in 0..6 {
            let mut pair = sample_pair(seed);
            pair.hess = true;
            let (du, ddu) = (0.7 + seed as f64, -1.3 * seed as f64);
            // Spring: boxed.
            let theta = crate::jet::closed::revolute_angle(&j, &pair);
            let boxed = theta.compose(0.0, du, ddu);
            let (g0, h0) = hessian_of(|g, h| {
                crate::jet::scatter(&bodies, &boxed, 1.0, g, Some(h as &mut dyn HessianSink));
            });
            let rot = crate::jet::closed::Rotations::of(&pair);
            let a = [&rot.0[0], &rot.0[1]];
            let stacked = revolute_angle(&j, &pair, a);
            assert_eq!(stacked.v, theta.v);
            // `∇²θ` symmetric to the last bit, and the spring's Hessian entry by entry
            // `U'' ∂θ_a ∂θ_b + U' ∂²θ_ab` (the mirrored half too).
            let (mut g1, mut h1) = (DVector::zeros(14), DMatrix::zeros(14, 14));
            scatter_angle(&bodies, &stacked, Some((du, ddu)), 1.0, &mut g1, &mut h1);
            for (x, &i) in P.iter().enumerate() {
                for (y, &k) in P.iter().enumerate() {
                    let th = stacked.h[(x, y)];
                    assert_eq!(th.to_bits(), stacked.h[(y, x)].to_bits(), "seed {seed}");
                    let entry = stacked.g[i] * stacked.g[k] * ddu + th * du;
                    // The sink adds `1 · entry` to zero (bodies 0 and 1: global = local).
                    assert_eq!(h1[(i, k)].to_bits(), (0.0 + 1.0 * entry).to_bits());
                }
            }
            let (g1, h1) = hessian_of(|g, h| {
                scatter_angle(&bodies, &stacked, Some((du, ddu)), 1.0, g, h);
            });
            assert_eq!(stacked.g, theta.g, "seed {seed}");
            assert_eq!(g0, g1, "seed {seed}");
            assert!((&h0 - &h1).amax() <= 1e-13 * h0.amax(), "seed {seed}");
            assert!(h1.amax() > 0.0);
            // Effort: `−τ θ`.
            let tau = -2.5;
            let (g0, h0) = hessian_of(|g, h| {
                crate::jet::scatter(&bodies, &theta, tau, g, Some(h as &mut dyn HessianSink));
            });
            let (g1, h1) = hessian_of(|g, h| {
                scatter_angle(&bodies, &stacked, None, tau, g, h);
            });
            assert_eq!(g0, g1, "seed {seed}");
            assert!((&h0 - &h1).amax() <= 1e-13 * h0.amax(), "seed {seed}");
            // Weighted point.
            let one = [Some(BodyId(1)), None];
            let (s, w) = (Vector3::new(0.3, -0.1, 0.25), Vector3::new(1.0, -2.0, 9.81));
            let boxed = crate::jet::closed::tests::weighted_point(&pair, 0, &s, &w);
            assert!(hess_or_zero(&boxed.h).amax() > 0.0);
            let (g0, h0) = hessian_of(|g, h| {
                crate::jet::scatter(&one, &boxed, 1.0, g, Some(h as &mut dyn HessianSink));
            });
            let mut v = 0.0;
            let (g1, h1) = {
                let mut g = DVector::zeros(14);
                let mut h = DMatrix::zeros(14, 14);
                v += weighted_point(
                    BodyId(1),
                    &coordinates(1, &pair),
                    a[0],
                    &s,
                    &w,
                    &mut g,
                    &mut h,
                );
                (g, h)
            };
            assert_eq!(v, boxed.v);
            assert_eq!((g0, h0), (g1, h1), "seed {seed}");
        }
    }

    /// Without the Hessian: the angle's value and gradient and the weighted point's value and
    /// gradient, added into a vector, are the boxed generic path's to the last bit (compared
    /// as bits, so that a zero's sign counts).
    #[test]
    fn gradient_only_terms_equal_the_boxed_path_bit_for_bit() {
        let bits = |g: &DVector<f64>| g.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        let j = sample_joint(crate::model::JointKind::Revolute);
        for seed in 0..6 {
            let pair = sample_pair(seed);
            let du = 0.7 - seed as f64;
            let theta = crate::jet::closed::revolute_angle(&j, &pair);
            let rot = crate::jet::closed::Rotations::of(&pair);
            let a = [&rot.0[0], &rot.0[1]];
            let (v, g) = revolute_angle_gradient(&j, &pair, a);
            assert_eq!(v.to_bits(), theta.v.to_bits(), "seed {seed}");
            // A spring `U(θ)` (`Scalar::compose`, scattered with `c = 1`) and an effort.
            for (c, du) in [(1.0, du), (-2.5, 1.0)] {
                let boxed = theta.clone().scale(du);
                let mut g0 = DVector::zeros(21);
                crate::jet::scatter(&j.bodies, &boxed, c, &mut g0, None);
                let mut g1 = DVector::zeros(21);
                scatter_gradient(&j.bodies, &(g * du), c, &mut g1);
                assert_eq!(bits(&g0), bits(&g1), "seed {seed}");
                assert!(g1.amax() > 0.0);
            }
            let (s, w) = (Vector3::new(0.3, -0.1, 0.25), Vector3::new(1.0, -2.0, 9.81));
            let body = [Some(BodyId(2)), None];
            let boxed = crate::jet::closed::tests::weighted_point(&pair, 0, &s, &w);
            let mut g0 = DVector::zeros(21);
            crate::jet::scatter(&body, &boxed, 1.0, &mut g0, None);
            let mut g1 = DVector::zeros(21);
            let q = coordinates(2, &pair);
            let v = weighted_point_gradient(BodyId(2), &q, a[0], &s, &w, &mut g1);
            assert_eq!(v.to_bits(), boxed.v.to_bits(), "seed {seed}");
            assert_eq!(bits(&g0), bits(&g1), "seed {seed}");
        }
    }

    /// A revolute spring `U(θ) = k (θ − θ₀)² / 2` and the angle `θ` itself as the stacked
    /// terms add them (gradient into the vector, Hessian through the Euler-parameter sink)
    /// match central differences.
    #[test]
    fn stacked_spring_matches_central_differences() {
        let j = sample_joint(crate::model::JointKind::Revolute);
        let bodies = j.bodies;
        let (k, theta0) = (3.5, 0.4);
        let spring = |q: &Pair| {
            let mut pair = *q;
            pair.hess = true;
            let rot = crate::jet::closed::Rotations::of(&pair);
            let theta = revolute_angle(&j, &pair, [&rot.0[0], &rot.0[1]]);
            let delta = theta.v - theta0;
            let (g, h) = hessian_of(|g, h| {
                scatter_angle(&bodies, &theta, Some((k * delta, k)), 1.0, g, h);
            });
            crate::jet::Scalar {
                v: 0.5 * k * delta * delta,
                g: crate::jet::LVec::from_column_slice(g.as_slice()),
                h: Some(Box::new(crate::jet::LMat::from_column_slice(h.as_slice()))),
            }
        };
        // The angle itself (an effort's `U = θ`): the regrouped `∇²θ` alone.
        let angle = |q: &Pair| {
            let mut pair = *q;
            pair.hess = true;
            let rot = crate::jet::closed::Rotations::of(&pair);
            let theta = revolute_angle(&j, &pair, [&rot.0[0], &rot.0[1]]);
            let (g, h) = hessian_of(|g, h| scatter_angle(&bodies, &theta, None, 1.0, g, h));
            crate::jet::Scalar {
                v: theta.v,
                g: crate::jet::LVec::from_column_slice(g.as_slice()),
                h: Some(Box::new(crate::jet::LMat::from_column_slice(h.as_slice()))),
            }
        };
        for seed in 0..6 {
            let pair = sample_pair(seed);
            assert!(hess_or_zero(&spring(&pair).h).amax() > 0.0);
            crate::jet::testing::check_scalar(&pair, &spring, &format!("seed {seed}"));
            assert!(hess_or_zero(&angle(&pair).h).amax() > 0.0);
            crate::jet::testing::check_scalar(&pair, &angle, &format!("angle, seed {seed}"));
        }
    }
}
