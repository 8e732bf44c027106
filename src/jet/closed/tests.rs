//! The closed forms against the generic jets (to rounding) and against central differences.

use super::*;
use crate::jet::testing::{check_scalar, sample_pair};
use crate::jet::{hess_or_zero, Vec3Jet};
use crate::math::rotation;

/// Values and gradients of the rows of `joint` into `out` (cleared first; no Hessians): those
/// of [`super::rows_each`].
pub(crate) fn rows(joint: &Joint, pair: &Pair, out: &mut Vec<Scalar>) {
    out.clear();
    super::rows_each(
        joint,
        pair,
        &OwnedRotations::of(joint, pair).view(),
        |_, v, g| out.push(Scalar { v, g: *g, h: None }),
    );
}

/// The weighted point `wᵀ (r_k + A(p_k) s)` of side `k` (gravity, dead loads), with the
/// Hessian when `pair.hess`: the general path, the reference of the tests of `forces::stacked`.
pub(crate) fn weighted_point(pair: &Pair, k: usize, s: &Vector3<f64>, w: &Vector3<f64>) -> Scalar {
    let rot = Rotations::of(pair);
    let p = Lin::point(pair, &rot.0[k], k, s);
    let mut g = LVec::zeros();
    linear_gradient(&p, w, &mut g);
    let h = pair.hess.then(|| {
        let mut h = Box::new(LMat::zeros());
        linear_hessian(&p, w, &mut h);
        h
    });
    Scalar {
        v: w.dot(&p.v),
        g,
        h,
    }
}

/// Relative agreement of two scalars' value, gradient and Hessian.
pub(crate) fn assert_same(a: &Scalar, b: &Scalar, what: &str) {
    let scale = 1.0 + a.v.abs() + a.g.amax() + hess_or_zero(&a.h).amax();
    assert!(
        (a.v - b.v).abs() <= 1e-12 * scale,
        "{what}: value {} vs {}",
        a.v,
        b.v
    );
    assert!((a.g - b.g).amax() <= 1e-12 * scale, "{what}: gradient");
    let d = (hess_or_zero(&a.h) - hess_or_zero(&b.h)).amax();
    assert!(d <= 1e-12 * scale, "{what}: hessian differs by {d}");
}

fn dot_scalar(pair: &Pair, a: &Lin, b: &Lin) -> Scalar {
    let mut g = LVec::zeros();
    dot_gradient(a, b, 1.0, &mut g);
    let mut h = Box::new(LMat::zeros());
    dot_hessian(a, b, 1.0, &mut h);
    Scalar {
        v: a.v.dot(&b.v),
        g,
        h: pair.hess.then_some(h),
    }
}

fn s0() -> Vector3<f64> {
    Vector3::new(0.3, -0.2, 0.5)
}
fn s1() -> Vector3<f64> {
    Vector3::new(-0.1, 0.4, 0.2)
}

/// The jets of `d = o₁ − o₀`, `a₀` and `a₁`, generic and closed-form.
fn vectors(q: &Pair) -> ([Vec3Jet; 3], [Lin; 3]) {
    let rot = Rotations::of(q);
    (
        [
            q.point(1, &s1()).sub(&q.point(0, &s0())),
            q.vector(0, &Vector3::new(0.6, 0.0, -0.8)),
            q.vector(1, &Vector3::y()),
        ],
        [
            {
                let mut d = Lin::point(q, &rot.0[1], 1, &s1());
                d.subtract(&Lin::point(q, &rot.0[0], 0, &s0()));
                d
            },
            Lin::vector(q, &rot.0[0], 0, &Vector3::new(0.6, 0.0, -0.8)),
            Lin::vector(q, &rot.0[1], 1, &Vector3::y()),
        ],
    )
}

#[test]
fn quadratic_form_is_the_curvature_of_a_rotated_vector() {
    let pair = sample_pair(1);
    let w = Vector3::new(0.7, -1.1, 0.4);
    let jet = pair.vector(0, &s0()).contract(&w);
    let m = quadratic_form(&s0(), &w) * 2.0;
    for i in 0..4 {
        for j in 0..4 {
            assert!((jet[(3 + i, 3 + j)] - m[(i, j)]).abs() < 1e-14);
        }
    }
    // wᵀ A(p) s = pᵀ M p off the unit sphere too.
    let p = pair.p[0];
    let lhs = w.dot(&(rotation(&p) * s0()));
    assert!((lhs - (p.transpose() * quadratic_form(&s0(), &w) * p)[0]).abs() < 1e-14);
}

#[test]
fn dot_products_equal_the_jets_and_finite_differences() {
    for seed in 0..6 {
        let pair = sample_pair(seed);
        for (i, j) in [(0, 0), (0, 1), (1, 0), (1, 2), (0, 2), (2, 2)] {
            let (jets, lins) = vectors(&pair);
            let what = format!("seed {seed} dot({i}, {j})");
            assert_same(
                &pair.dot(&jets[i], &jets[j]),
                &dot_scalar(&pair, &lins[i], &lins[j]),
                &what,
            );
            check_scalar(
                &pair,
                &|q| {
                    let (_, l) = vectors(q);
                    dot_scalar(q, &l[i], &l[j])
                },
                &what,
            );
        }
    }
}

#[test]
fn weighted_points_equal_the_jets_and_finite_differences() {
    let w = Vector3::new(0.0, -3.0, -9.81);
    for seed in 0..4 {
        let pair = sample_pair(seed);
        for k in 0..2 {
            let p = pair.point(k, &s1());
            let jet = Scalar {
                v: w.dot(&p.v),
                g: p.j.transpose() * w,
                h: Some(Box::new(p.contract(&w))),
            };
            let what = format!("seed {seed} side {k}");
            assert_same(&jet, &weighted_point(&pair, k, &s1(), &w), &what);
            check_scalar(&pair, &|q| weighted_point(q, k, &s1(), &w), &what);
        }
    }
}

/// A component row's gradient read off `t_k I` and `B_k` equals [`linear_gradient`] of the
/// unit vector bit for bit (a zero's sign included), on a point difference and on directions
/// of either side, at poses where some entries of `B_k` are exact zeros (the identity, a
/// quarter turn) and at general ones.
#[test]
fn component_gradient_is_linear_gradient_bit_for_bit() {
    let mut pairs: Vec<Pair> = (0..6).map(sample_pair).collect();
    let h = std::f64::consts::FRAC_1_SQRT_2;
    for p in [
        nalgebra::Vector4::new(1.0, 0.0, 0.0, 0.0),
        nalgebra::Vector4::new(h, 0.0, 0.0, -h),
    ] {
        let mut pair = sample_pair(9);
        pair.p = [p, nalgebra::Vector4::new(0.0, -1.0, 0.0, 0.0)];
        pairs.push(pair);
    }
    let mut zeros = 0;
    for (n, q) in pairs.iter().enumerate() {
        for a in vectors(q).1 {
            zeros +=
                a.b.iter()
                    .flat_map(|b| b.iter())
                    .filter(|x| **x == 0.0)
                    .count();
            for m in 0..3 {
                let mut general = LVec::zeros();
                linear_gradient(&a, &Vector3::ith(m, 1.0), &mut general);
                let mut read = LVec::zeros();
                component_gradient(&a, m, &mut read);
                for i in 0..crate::jet::NL {
                    assert_eq!(
                        general[i].to_bits(),
                        read[i].to_bits(),
                        "pair {n} m {m} [{i}]"
                    );
                }
            }
        }
    }
    assert!(zeros > 0);
}
