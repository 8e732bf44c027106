//! The revolute angle `θ = atan2(S, C)`, `S = y₀ · x₁`, `C = x₀ · x₁` (the child's `x` axis
//! in the parent's joint frame, about `z₀`; as [`crate::kinematics::angle`], in (−π, π]), and
//! its gradient in closed form: with `ρ = S² + C²` frozen,
//!
//! `∇θ = (C ∇S − S ∇C) / ρ = ∇(w · x₁)`,   `w = A(p₀) ŵ`,   `ŵ = (C ŷ₀ − S x̂₀) / ρ`,
//!
//! zero over the positions, `B(p₀, ŵ)ᵀ x₁` over `p₀` and `B(p₁, x̂₁)ᵀ w` over `p₁`
//! ([`crate::math::b_transpose_mul`]; `x̂₀, ŷ₀, x̂₁` the frame axes in their bodies). The
//! joint springs' and efforts' terms (`forces`) and the lock rows of a revolute angle
//! (`constraints`) read it; the vectors and factors it is formed from are kept for the
//! Hessian of the forces' terms.

use crate::jet::{LVec, Pair};
use crate::math::b_transpose_mul;
use nalgebra::{Matrix3, Vector3};

/// `θ`, `∇θ` and the vectors and factors they are formed from, which the Hessian reuses.
pub(crate) struct RevoluteFirstOrder {
    pub(crate) v: f64,
    pub(crate) g: LVec,
    pub(crate) x0: Vector3<f64>,
    pub(crate) y0: Vector3<f64>,
    pub(crate) x1: Vector3<f64>,
    pub(crate) bx0: Vector3<f64>,
    pub(crate) by0: Vector3<f64>,
    pub(crate) bx1: Vector3<f64>,
    /// `w = A(p₀) ŵ` and `ŵ = (C ŷ₀ − S x̂₀) / ρ`.
    pub(crate) w: Vector3<f64>,
    pub(crate) wb: Vector3<f64>,
    /// `C / ρ`, `S / ρ`.
    pub(crate) cr: f64,
    pub(crate) sr: f64,
}

/// `θ = atan2(S, C)` and `∇θ = (C ∇S − S ∇C) / ρ = ∇(w · x₁)` with `ρ` frozen: over `p₀`
/// `B(p₀, ŵ)ᵀ x₁`, over `p₁` `B(p₁, x̂₁)ᵀ w` ([`b_transpose_mul`]), zero on the positions.
#[inline(always)]
pub(crate) fn revolute_first_order(
    pair: &Pair,
    a: [&Matrix3<f64>; 2],
    r: &[Matrix3<f64>; 2],
) -> RevoluteFirstOrder {
    let (p0, p1) = (&pair.p[0], &pair.p[1]);
    let (a0, a1) = (a[0], a[1]);
    let [r0, r1] = r;
    let (bx0, by0) = (r0.column(0).into_owned(), r0.column(1).into_owned());
    let bx1 = r1.column(0).into_owned();
    let (x0, y0, x1) = (a0 * bx0, a0 * by0, a1 * bx1);
    let (s, c) = (y0.dot(&x1), x0.dot(&x1));
    let rho = s * s + c * c;
    let (cr, sr) = (c / rho, s / rho);
    let (wb, w) = (by0 * cr - bx0 * sr, y0 * cr - x0 * sr);
    let (g0, g1) = (b_transpose_mul(p0, &wb, &x1), b_transpose_mul(p1, &bx1, &w));
    let mut g = LVec::zeros();
    for i in 0..4 {
        g[3 + i] = g0[i];
        g[10 + i] = g1[i];
    }
    RevoluteFirstOrder {
        v: s.atan2(c),
        g,
        x0,
        y0,
        x1,
        bx0,
        by0,
        bx1,
        w,
        wb,
        cr,
        sr,
    }
}
