//! The energy terms whose Hessians every Newton iteration forms, evaluated with their local
//! Hessians on the stack instead of the boxed ones of [`crate::jet::Scalar`]: gravity and dead
//! loads `wᵀ (r + A(p) s)`, and joint springs and efforts on revolute angles
//! `θ = atan2(y₀ · x₁, x₀ · x₁)`.
//!
//! The operations are those of the generic path entry by entry, in the same order (so the
//! results are the same to the last bit): `∇²θ = sym(m)`,
//!
//! `m = (∇S ∇Cᵀ − ∇C ∇Sᵀ + C ∇²S − S ∇²C) / ρ − ∇θ ∇ρᵀ / ρ`,   `ρ = S² + C²`,
//!
//! and a spring `U(θ)` adds `U'' ∇θ ∇θᵀ + U' ∇²θ`; but `θ` depends on the Euler parameters
//! only, so its Hessian is formed over those 8 coordinates of the pair (not 14), and no term
//! allocates.

use crate::jet::closed::{dot_gradient, dot_hessian_euler, linear_gradient, linear_hessian_euler};
use crate::jet::closed::{Lin, Rotations};
use crate::jet::{HessianSink, LVec, Pair};
use crate::model::{BodyId, Joint};
use nalgebra::{DVector, SMatrix, Vector3};

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
    hess.add_euler_block(bodies, hp, c);
}

/// `wᵀ (r_k + A(p_k) s)` of side `k` with its gradient into `grad` and Hessian into `hess`
/// (as [`crate::jet::closed::weighted_point`] and [`crate::jet::scatter`] with `c = 1`);
/// returns the value.
pub(crate) fn weighted_point(
    bodies: &[Option<BodyId>; 2],
    pair: &Pair,
    s: &Vector3<f64>,
    w: &Vector3<f64>,
    grad: &mut DVector<f64>,
    hess: &mut dyn HessianSink,
) -> f64 {
    let rot = Rotations::of(pair);
    let p = Lin::point(pair, &rot, 0, s);
    let mut g = LVec::zeros();
    linear_gradient(&p, w, &mut g);
    let mut h = SMatrix::<f64, 8, 8>::zeros();
    linear_hessian_euler(&p, w, &mut h);
    scatter(bodies, &g, &h, 1.0, grad, hess);
    w.dot(&p.v)
}

/// A revolute angle `θ` (not yet on its branch), its gradient and its Hessian over [`P`].
pub(crate) struct Angle {
    pub(crate) v: f64,
    pub(crate) g: LVec,
    pub(crate) h: SMatrix<f64, 8, 8>,
}

/// `θ` of the revolute `joint` at `pair` (as [`crate::jet::closed::revolute_angle`]): each
/// side's joint rotation formed once, the `8 × 8` sums over plain arrays.
pub(crate) fn revolute_angle(joint: &Joint, pair: &Pair) -> Angle {
    let rot = Rotations::of(pair);
    let r0 = joint.body_from_joint[0].rotation.to_rotation_matrix();
    let r1 = joint.body_from_joint[1].rotation.to_rotation_matrix();
    let axis = |k: usize, r: &nalgebra::Rotation3<f64>, i: usize| {
        Lin::vector(pair, &rot, k, &r.matrix().column(i).into_owned())
    };
    let (x0, y0, x1) = (axis(0, &r0, 0), axis(0, &r0, 1), axis(1, &r1, 0));
    // The Hessians of the two dot products over the Euler parameters only (directions: zero
    // elsewhere).
    let dot = |a: &Lin, b: &Lin, h: &mut SMatrix<f64, 8, 8>| {
        let mut g = LVec::zeros();
        dot_gradient(a, b, 1.0, &mut g);
        dot_hessian_euler(a, b, 1.0, h);
        (a.v.dot(&b.v), g)
    };
    let (mut hs, mut hc) = (SMatrix::<f64, 8, 8>::zeros(), SMatrix::<f64, 8, 8>::zeros());
    let (s, gs) = dot(&y0, &x1, &mut hs);
    let (c, gc) = dot(&x0, &x1, &mut hc);
    // `Pair::atan2`, over the Euler parameters.
    let rho = s * s + c * c;
    let n = gs * (c / rho) - gc * (s / rho);
    let drho = gs * (2.0 * s) + gc * (2.0 * c);
    let (mut ps, mut pc, mut pn, mut pd) = ([0.0f64; 8], [0.0f64; 8], [0.0f64; 8], [0.0f64; 8]);
    for (a, &i) in P.iter().enumerate() {
        (ps[a], pc[a], pn[a], pd[a]) = (gs[i], gc[i], n[i], drho[i]);
    }
    let (hs, hc) = (hs.as_slice(), hc.as_slice());
    // `m[a, b]` at `8 b + a` (column-major, as `SMatrix`).
    let mut m = [0.0f64; 64];
    for b in 0..8 {
        for a in 0..8 {
            let x = ps[a] * pc[b] - pc[a] * ps[b] + hs[8 * b + a] * c - hc[8 * b + a] * s;
            m[8 * b + a] = x / rho - pn[a] * pd[b] / rho;
        }
    }
    let mut h = SMatrix::<f64, 8, 8>::zeros();
    let hm = h.as_mut_slice();
    for b in 0..8 {
        for a in 0..8 {
            hm[8 * b + a] = (m[8 * b + a] + m[8 * a + b]) * 0.5;
        }
    }
    Angle {
        v: s.atan2(c),
        g: n,
        h,
    }
}

/// `c U(θ)` for `U` given by `(u, du, ddu)` at `θ` (`Scalar::compose`; `None`: `U = θ`):
/// its gradient into `grad` and Hessian into `hess`.
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
        for a in 0..8 {
            hm[8 * b + a] = pg[a] * pg[b] * ddu + th[8 * b + a] * du;
        }
    }
    scatter(bodies, &(theta.g * du), &h, c, grad, hess);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::jet::hess_or_zero;
    use crate::jet::testing::sample_pair;
    use nalgebra::{DMatrix, Isometry3, Translation3, UnitQuaternion};

    fn joint() -> Joint {
        Joint {
            name: "j".into(),
            kind: crate::model::JointKind::Revolute,
            parent_link: "a".into(),
            child_link: "b".into(),
            bodies: [Some(BodyId(0)), Some(BodyId(1))],
            body_from_joint: [
                Isometry3::from_parts(
                    Translation3::new(0.1, 0.2, -0.3),
                    UnitQuaternion::from_euler_angles(0.3, -0.2, 0.9),
                ),
                Isometry3::from_parts(
                    Translation3::new(-0.2, 0.05, 0.4),
                    UnitQuaternion::from_euler_angles(-0.5, 0.4, 0.1),
                ),
            ],
            tree: false,
            merged: false,
            limits: None,
            effort_limit: None,
            source: None,
        }
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

    /// The stacked terms equal the boxed generic path bit for bit: gradient and Hessian of a
    /// revolute spring `U(θ)`, of an effort `−τ θ` and of a weighted point.
    #[test]
    fn stacked_terms_equal_the_boxed_path_bit_for_bit() {
        let j = joint();
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
            let stacked = revolute_angle(&j, &pair);
            assert_eq!(stacked.v, theta.v);
            let (g1, h1) = hessian_of(|g, h| {
                scatter_angle(&bodies, &stacked, Some((du, ddu)), 1.0, g, h);
            });
            assert_eq!(g0, g1, "seed {seed}");
            assert_eq!(h0, h1, "seed {seed}");
            assert!(h1.amax() > 0.0);
            // Effort: `−τ θ`.
            let tau = -2.5;
            let (g0, h0) = hessian_of(|g, h| {
                crate::jet::scatter(&bodies, &theta, tau, g, Some(h as &mut dyn HessianSink));
            });
            let (g1, h1) = hessian_of(|g, h| {
                scatter_angle(&bodies, &stacked, None, tau, g, h);
            });
            assert_eq!((g0, h0), (g1, h1), "seed {seed}");
            // Weighted point.
            let one = [Some(BodyId(1)), None];
            let (s, w) = (Vector3::new(0.3, -0.1, 0.25), Vector3::new(1.0, -2.0, 9.81));
            let boxed = crate::jet::closed::weighted_point(&pair, 0, &s, &w);
            assert!(hess_or_zero(&boxed.h).amax() > 0.0);
            let (g0, h0) = hessian_of(|g, h| {
                crate::jet::scatter(&one, &boxed, 1.0, g, Some(h as &mut dyn HessianSink));
            });
            let mut v = 0.0;
            let (g1, h1) = {
                let mut g = DVector::zeros(14);
                let mut h = DMatrix::zeros(14, 14);
                v += weighted_point(&one, &pair, &s, &w, &mut g, &mut h);
                (g, h)
            };
            assert_eq!(v, boxed.v);
            assert_eq!((g0, h0), (g1, h1), "seed {seed}");
        }
    }

    /// A revolute spring `U(θ) = k (θ − θ₀)² / 2` as the stacked terms add it (gradient into
    /// the vector, Hessian through the Euler-parameter sink) matches central differences.
    #[test]
    fn stacked_spring_matches_central_differences() {
        let j = joint();
        let bodies = j.bodies;
        let (k, theta0) = (3.5, 0.4);
        let spring = |q: &Pair| {
            let mut pair = *q;
            pair.hess = true;
            let theta = revolute_angle(&j, &pair);
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
        for seed in 0..6 {
            let pair = sample_pair(seed);
            assert!(hess_or_zero(&spring(&pair).h).amax() > 0.0);
            crate::jet::testing::check_scalar(&pair, &spring, &format!("seed {seed}"));
        }
    }
}
