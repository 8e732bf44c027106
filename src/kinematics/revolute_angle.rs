//! The revolute angle `θ = atan2(S, C)`, `S = y₀ · x₁`, `C = x₀ · x₁` (the child's `x` axis
//! in the parent's joint frame, about `z₀`; as [`crate::kinematics::angle`], in (−π, π]), and
//! its gradient in closed form, `Pair::atan2`'s
//!
//! `∇θ = (C ∇S − S ∇C) / ρ`,   `ρ = S² + C²`,
//!
//! with `∇S = [B(p₀, ŷ₀)ᵀ x₁, B(p₁, x̂₁)ᵀ y₀]`, `∇C = [B(p₀, x̂₀)ᵀ x₁, B(p₁, x̂₁)ᵀ x₀]` over the
//! Euler parameters and zero over the positions (`x̂₀, ŷ₀, x̂₁` the frame axes in their
//! bodies). The joint springs' and efforts' terms (`forces`, whose Hessians reuse the vectors
//! and factors kept here) and the lock rows of a revolute angle (`constraints`) read it.

use crate::jet::{LVec, Pair};
use crate::math::b_matrix;
use nalgebra::{Matrix3, Matrix3x4, Vector3, Vector4};

/// `θ`, `∇θ` (`Pair::atan2`'s) and the vectors and factors they are formed from, which the
/// Hessian reuses.
pub(crate) struct RevoluteFirstOrder {
    pub(crate) v: f64,
    pub(crate) g: LVec,
    pub(crate) x0: Vector3<f64>,
    pub(crate) y0: Vector3<f64>,
    pub(crate) x1: Vector3<f64>,
    pub(crate) bx0: Vector3<f64>,
    pub(crate) by0: Vector3<f64>,
    pub(crate) bx1: Vector3<f64>,
    pub(crate) b0x: Matrix3x4<f64>,
    pub(crate) b0y: Matrix3x4<f64>,
    pub(crate) b1x: Matrix3x4<f64>,
    pub(crate) gs: LVec,
    pub(crate) gc: LVec,
    pub(crate) s: f64,
    pub(crate) c: f64,
    pub(crate) rho: f64,
}

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
    let (b0x, b0y, b1x) = (b_matrix(p0, &bx0), b_matrix(p0, &by0), b_matrix(p1, &bx1));
    // `∇S`, `∇C` (as `dot_gradient`: zero on the positions).
    let side = |g0: Vector4<f64>, g1: Vector4<f64>| {
        let mut g = LVec::zeros();
        for i in 0..4 {
            g[3 + i] += g0[i];
            g[10 + i] += g1[i];
        }
        g
    };
    let gs = side(b0y.tr_mul(&x1), b1x.tr_mul(&y0));
    let gc = side(b0x.tr_mul(&x1), b1x.tr_mul(&x0));
    let (s, c) = (y0.dot(&x1), x0.dot(&x1));
    // `Pair::atan2`'s gradient.
    let rho = s * s + c * c;
    let n = gs * (c / rho) - gc * (s / rho);
    RevoluteFirstOrder {
        v: s.atan2(c),
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
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::jet::closed::{frame_rotations, Rotations};
    use crate::jet::testing::{sample_joint, sample_pair, shifted};
    use crate::model::JointKind;

    /// `θ` and `∇θ` equal the generic jets' coordinate ([`crate::kinematics::coordinate`]) to
    /// rounding and `∇θ` matches central differences, on random pairs off the unit sphere.
    #[test]
    fn revolute_angle_equals_the_jets_and_central_differences() {
        let joint = sample_joint(JointKind::Revolute);
        let r = frame_rotations(&joint);
        let first = |pair: &Pair| {
            let rot = Rotations::of(pair);
            revolute_first_order(pair, [&rot.0[0], &rot.0[1]], &r)
        };
        for seed in 0..8 {
            let mut pair = sample_pair(seed);
            pair.hess = false;
            let f = first(&pair);
            let jet = crate::kinematics::coordinate(&joint, &pair, 0, f64::NAN).unwrap();
            assert!(
                (f.v - jet.v).abs() <= 4e-15,
                "seed {seed}: {} {}",
                f.v,
                jet.v
            );
            let scale = jet.g.amax();
            assert!((f.g - jet.g).amax() <= 1e-14 * scale, "seed {seed}");
            let h = 1e-6;
            for i in 0..crate::jet::NL {
                let at = |step: f64| first(&shifted(&pair, i, step)).v;
                let fd = (at(h) - at(-h)) / (2.0 * h);
                assert!(
                    (fd - f.g[i]).abs() < 1e-7 * (1.0 + scale),
                    "seed {seed} {i}: {fd}"
                );
            }
        }
    }
}
