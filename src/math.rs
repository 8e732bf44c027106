//! Euler-parameter helpers: the rotation matrix `A(p)`, its derivative `B(p, a)`, and the
//! only conversions between nalgebra quaternions and Euler parameters.
//!
//! For `p = [e0, e1, e2, e3]`, `e = [e1, e2, e3]`, restpose uses the homogeneous quadratic form
//!
//! `A(p) = (e0² − eᵀe) I + 2 e eᵀ + 2 e0 ẽ`
//!
//! which equals the paper's `(2 e0² − 1) I + 2 (e eᵀ + e0 ẽ)` whenever `pᵀp = 1`. Off the unit
//! sphere (inside the Newton corrector, where normalization is only a constraint row) the
//! homogeneous form keeps `A(p) a` an exact quadratic in `p`, so that
//!
//! `B(p, a) = ∂(A(p) a)/∂p = 2 [ (e0 I + ẽ) a ,  e aᵀ − (e0 I + ẽ) ã ]`
//!
//! is linear in `p` and the Hessian of `(A(p) a)_k` is the constant matrix whose row `m` is
//! row `k` of `B(e_m, a)` (`e_m` the m-th unit 4-vector).
//!
//! Conventions: `e0 = q.w, e1 = q.i, e2 = q.j, e3 = q.k`.
//!
//! ## References
//! - P. E. Nikravesh, *Computer-Aided Analysis of Mechanical Systems*, Prentice Hall (1988), ch. 6.

use nalgebra::{Matrix3, Matrix3x4, Quaternion, UnitQuaternion, Vector3, Vector4};

/// Skew-symmetric matrix `ã` with `ã b = a × b`.
pub fn skew(a: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -a.z, a.y, a.z, 0.0, -a.x, -a.y, a.x, 0.0)
}

/// Rotation matrix `A(p)` of (not necessarily unit) Euler parameters, homogeneous form.
pub fn rotation(p: &Vector4<f64>) -> Matrix3<f64> {
    let e0 = p[0];
    let e = Vector3::new(p[1], p[2], p[3]);
    Matrix3::identity() * (e0 * e0 - e.dot(&e)) + 2.0 * e * e.transpose() + 2.0 * e0 * skew(&e)
}

/// `B(p, a) = ∂(A(p) a)/∂p`, a 3 × 4 matrix linear in `p`.
///
/// Entry by entry, with the sums in the order of nalgebra's products
/// `2 (e0 I + ẽ) a` and `2 (e aᵀ − (e0 I + ẽ) ã)` (the same values; no temporaries).
pub fn b_matrix(p: &Vector4<f64>, a: &Vector3<f64>) -> Matrix3x4<f64> {
    let (e0, e) = (p[0], [p[1], p[2], p[3]]);
    // m = e0 I + ẽ and ã, row-major.
    let m = [[e0, -e[2], e[1]], [e[2], e0, -e[0]], [-e[1], e[0], e0]];
    let s = [[0.0, -a.z, a.y], [a.z, 0.0, -a.x], [-a.y, a.x, 0.0]];
    let a = [a.x, a.y, a.z];
    let mut b = Matrix3x4::zeros();
    for i in 0..3 {
        let m2 = [2.0 * m[i][0], 2.0 * m[i][1], 2.0 * m[i][2]];
        b[(i, 0)] = m2[0] * a[0] + m2[1] * a[1] + m2[2] * a[2];
        for j in 0..3 {
            let ms = m[i][0] * s[0][j] + m[i][1] * s[1][j] + m[i][2] * s[2][j];
            b[(i, j + 1)] = 2.0 * (e[i] * a[j] - ms);
        }
    }
    b
}

/// The former `b_matrix` through nalgebra's products (the reference of the tests).
#[cfg(test)]
fn b_matrix_products(p: &Vector4<f64>, a: &Vector3<f64>) -> Matrix3x4<f64> {
    let e0 = p[0];
    let e = Vector3::new(p[1], p[2], p[3]);
    let m = Matrix3::identity() * e0 + skew(&e);
    let c0 = 2.0 * m * a;
    let rest = 2.0 * (e * a.transpose() - m * skew(a));
    let mut b = Matrix3x4::zeros();
    b.set_column(0, &c0);
    b.fixed_view_mut::<3, 3>(0, 1).copy_from(&rest);
    b
}

/// The quaternion product `a ⊗ b` of Euler parameters: `A(a ⊗ b) = A(a) A(b)` (the rotation `b`
/// followed by `a`), of norm `|a| |b|`.
pub fn compose(a: &Vector4<f64>, b: &Vector4<f64>) -> Vector4<f64> {
    let (a0, av) = (a[0], Vector3::new(a[1], a[2], a[3]));
    let (b0, bv) = (b[0], Vector3::new(b[1], b[2], b[3]));
    let v = a0 * bv + b0 * av + av.cross(&bv);
    Vector4::new(a0 * b0 - av.dot(&bv), v.x, v.y, v.z)
}

/// Euler parameters `[e0, e1, e2, e3]` of a unit quaternion.
pub fn euler_parameters(q: &UnitQuaternion<f64>) -> Vector4<f64> {
    Vector4::new(q.w, q.i, q.j, q.k)
}

/// Unit quaternion of Euler parameters (normalized; the identity if `p` is zero).
pub fn unit_quaternion(p: &Vector4<f64>) -> UnitQuaternion<f64> {
    let q = Quaternion::new(p[0], p[1], p[2], p[3]);
    if q.norm() > 0.0 {
        UnitQuaternion::from_quaternion(q)
    } else {
        UnitQuaternion::identity()
    }
}

/// Rotation taking the z axis onto the unit vector `axis` by the shortest arc (a half turn
/// about x when `axis = −z`).
pub fn align_z(axis: &Vector3<f64>) -> UnitQuaternion<f64> {
    UnitQuaternion::rotation_between(&Vector3::z(), axis).unwrap_or_else(|| {
        UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI)
    })
}

/// The rotation vector `ψ = θ û` of a rotation matrix `R` (`R = exp(ψ̃)`), accurate for small
/// angles: `θ = atan2(|w|, (tr R − 1)/2)`, `w` the axial vector of `(R − Rᵀ)/2` (`= sin θ û`).
/// nalgebra's `Rotation3::scaled_axis` takes `θ = acos((tr R − 1)/2)`, which loses half the
/// digits near 0: a matrix off orthonormal by `ε` (Euler parameters normalized to the
/// constraint tolerance) reads as a turn of `√(2ε)` (`ε = 1e-13`: 4.7e-7 rad where the body
/// turned 1e-9). Past a quarter turn (`tr R < 1`) the axis is read by nalgebra's.
pub fn rotation_vector(r: &Matrix3<f64>) -> Vector3<f64> {
    let w = 0.5
        * Vector3::new(
            r[(2, 1)] - r[(1, 2)],
            r[(0, 2)] - r[(2, 0)],
            r[(1, 0)] - r[(0, 1)],
        );
    let c = 0.5 * (r.trace() - 1.0);
    let s = w.norm();
    if c < 0.0 {
        return nalgebra::Rotation3::from_matrix_unchecked(*r).scaled_axis();
    }
    if s == 0.0 {
        return Vector3::zeros();
    }
    w * (s.atan2(c) / s)
}

/// Wraps an angle into (−π, π].
pub fn wrap_angle(a: f64) -> f64 {
    let two_pi = 2.0 * std::f64::consts::PI;
    // `a % 2π` is `a` itself, exactly, for `|a| < 2π` (the usual case: an angle read near its
    // branch), without the call to `fmod`.
    let mut w = if a.abs() < two_pi { a } else { a % two_pi };
    if w <= -std::f64::consts::PI {
        w += two_pi;
    } else if w > std::f64::consts::PI {
        w -= two_pi;
    }
    w
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn b_matrix_entrywise_equals_the_products_exactly() {
        let mut lcg = crate::lcg::Lcg::new(7);
        let mut rnd = || lcg.unit() * 4.0 - 2.0;
        for _ in 0..20_000 {
            let p = Vector4::new(rnd(), rnd(), rnd(), rnd());
            let a = Vector3::new(rnd(), rnd(), rnd());
            let (x, y) = (b_matrix(&p, &a), b_matrix_products(&p, &a));
            for k in 0..12 {
                assert!(x[k] == y[k], "{p} {a}: {} != {}", x[k], y[k]);
            }
        }
    }

    fn arb_p() -> impl Strategy<Value = Vector4<f64>> {
        (-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64)
            .prop_map(|(a, b, c, d)| Vector4::new(a, b, c, d))
    }

    /// The rotation vector equals nalgebra's where that is accurate (any axis, 0.1 to 3 rad),
    /// and stays within rounding (1e-15 rad) for a turn of 1e-9 rad of Euler parameters 1e-12 off
    /// the unit sphere, where `acos` of the trace reads a turn of 2.4e-6 rad (or NaN).
    #[test]
    fn rotation_vector_is_accurate_near_the_identity() {
        for (k, angle) in [0.1, 0.25, 1.0, 1.5, 2.0, 3.0].iter().enumerate() {
            let axis = Vector3::new(0.3, -0.5 + 0.1 * k as f64, 0.8).normalize();
            let r = UnitQuaternion::from_scaled_axis(axis * *angle).to_rotation_matrix();
            let psi = rotation_vector(r.matrix());
            assert!((psi - axis * *angle).norm() < 1e-12, "{angle}: {psi}");
        }
        let axis = Vector3::new(0.0, 1.0, 0.0);
        let start = euler_parameters(&UnitQuaternion::from_scaled_axis(Vector3::new(
            0.3, 0.2, 0.1,
        )));
        let turned = compose(
            &euler_parameters(&UnitQuaternion::from_scaled_axis(axis * 1e-9)),
            &start,
        );
        for scale in [1.0 + 1e-12, 1.0 - 1e-12] {
            let r = rotation(&(turned * scale)) * rotation(&start).transpose();
            let psi = rotation_vector(&r);
            assert!((psi - axis * 1e-9).norm() < 1e-15, "{scale}: {psi}");
            let acos = nalgebra::Rotation3::from_matrix_unchecked(r).scaled_axis();
            // 2.4e-6 rad off, or NaN where the trace exceeds 3.
            let off = (acos - axis * 1e-9).norm();
            assert!(off.is_nan() || off > 1e-8, "{scale}: {acos}");
        }
    }

    proptest! {
        #[test]
        fn rotation_matches_nalgebra_on_unit_sphere(p in arb_p()) {
            prop_assume!(p.norm() > 0.1);
            let p = p.normalize();
            let a = rotation(&p);
            let r = unit_quaternion(&p).to_rotation_matrix();
            prop_assert!((a - r.matrix()).norm() < 1e-12);
        }

        #[test]
        fn b_is_exact_derivative(p in arb_p(), a in (-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64)) {
            let a = Vector3::new(a.0, a.1, a.2);
            let b = b_matrix(&p, &a);
            let h = 1e-6;
            for m in 0..4 {
                let mut pp = p;
                pp[m] += h;
                let mut pm = p;
                pm[m] -= h;
                let fd = (rotation(&pp) * a - rotation(&pm) * a) / (2.0 * h);
                prop_assert!((fd - b.column(m)).norm() < 1e-8);
            }
        }

        #[test]
        fn compose_is_the_product_of_rotations(a in arb_p(), b in arb_p()) {
            prop_assume!(a.norm() > 0.1 && b.norm() > 0.1);
            let (a, b) = (a.normalize(), b.normalize());
            let ab = compose(&a, &b);
            prop_assert!((rotation(&ab) - rotation(&a) * rotation(&b)).norm() < 1e-12);
            let q = unit_quaternion(&a) * unit_quaternion(&b);
            prop_assert!((euler_parameters(&q) - ab).norm() < 1e-12);
        }

        #[test]
        fn q_and_minus_q_same_rotation(p in arb_p()) {
            prop_assert!((rotation(&p) - rotation(&(-p))).norm() < 1e-14);
        }
    }

    #[test]
    fn align_z_maps_z_to_axis() {
        for axis in [
            Vector3::x(),
            Vector3::y(),
            Vector3::z(),
            -Vector3::z(),
            Vector3::new(1.0, 2.0, -3.0).normalize(),
        ] {
            let r = align_z(&axis);
            assert!((r * Vector3::z() - axis).norm() < 1e-12);
        }
    }

    #[test]
    fn wrap_angle_without_fmod_is_bit_for_bit() {
        let two_pi = 2.0 * std::f64::consts::PI;
        let mut lcg = crate::lcg::Lcg::new(3);
        for i in 0..20000 {
            let u = lcg.signed();
            let a = u * 4.0 * two_pi * if i % 2 == 0 { 1.0 } else { 1e-3 };
            for x in [
                a,
                two_pi,
                -two_pi,
                std::f64::consts::PI,
                -std::f64::consts::PI,
                0.0,
                -0.0,
            ] {
                let mut w = x % two_pi;
                if w <= -std::f64::consts::PI {
                    w += two_pi;
                } else if w > std::f64::consts::PI {
                    w -= two_pi;
                }
                assert_eq!(wrap_angle(x).to_bits(), w.to_bits(), "{x}");
            }
        }
        assert!(wrap_angle(f64::NAN).is_nan());
    }

    #[test]
    fn wrap_angle_range() {
        assert!((wrap_angle(3.0 * std::f64::consts::PI) - std::f64::consts::PI).abs() < 1e-12);
        assert!((wrap_angle(-0.5) + 0.5).abs() < 1e-15);
        assert!((wrap_angle(7.0) - (7.0 - 2.0 * std::f64::consts::PI)).abs() < 1e-12);
    }
}
