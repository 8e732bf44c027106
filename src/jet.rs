//! Second-order jets over the 14 local coordinates of a body pair.
//!
//! Every constraint and potential in restpose depends on at most two bodies, `x = [r₀; p₀;
//! r₁; p₁] ∈ ℝ¹⁴`. Points `r_k + A(p_k) s` and vectors `A(p_k) a` are exact quadratics in `x`
//! (see [`crate::math`]), so their Jacobians are `[I, B(p_k, s)]` and their Hessians constant.
//! A [`Scalar`] carries a value `f`, its gradient `∇f` and (when asked) its Hessian `∇²f`;
//! products, `atan2` and smooth compositions follow the chain rule exactly:
//!
//! `∇²(a·b) = J_aᵀ J_b + J_bᵀ J_a + Σ_k b_k ∇²a_k + Σ_k a_k ∇²b_k`.
//!
//! This makes every analytic Jacobian and Hessian of the model exact (not finite differences);
//! each is checked against central differences in the tests of the modules using it.

pub(crate) mod closed;

use crate::math::{b_matrix, rotation};
use nalgebra::{Matrix3, SMatrix, SVector, Vector3, Vector4};

/// Number of local coordinates of a body pair.
pub(crate) const NL: usize = 14;
/// Gradient over a body pair.
pub(crate) type LVec = SVector<f64, NL>;
/// Hessian over a body pair.
pub(crate) type LMat = SMatrix<f64, NL, NL>;

/// Coordinates of the (up to) two bodies a term depends on; a ground side holds the identity.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Pair {
    pub(crate) r: [Vector3<f64>; 2],
    pub(crate) p: [Vector4<f64>; 2],
    /// Whether Hessians are wanted (they cost 14 × 14 per term).
    pub(crate) hess: bool,
}

/// A 3-vector `c + Σ_k (r_k terms) + Σ_k A(p_k) s_k` with its Jacobian.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Vec3Jet {
    pub(crate) v: Vector3<f64>,
    pub(crate) j: SMatrix<f64, 3, NL>,
    /// Body-frame vector rotated by `A(p_k)` in this jet, per side (for the Hessian).
    s: [Vector3<f64>; 2],
}

/// A Hessian over a body pair when asked for (`Pair::hess`), else `None`: a jet without one
/// is 15 numbers instead of 211, and Jacobian-only evaluations (every corrector step) neither
/// zero nor copy 14 × 14 blocks.
pub(crate) type Hess = Option<Box<LMat>>;

/// The Hessian `h`, zero if absent.
pub(crate) fn hess_or_zero(h: &Hess) -> LMat {
    h.as_deref().copied().unwrap_or_else(LMat::zeros)
}

/// A scalar with gradient and (when asked) Hessian over the local coordinates.
#[derive(Clone, Debug)]
pub(crate) struct Scalar {
    pub(crate) v: f64,
    pub(crate) g: LVec,
    pub(crate) h: Hess,
}

impl Pair {
    /// World position of the point `s` of side `k` (body frame).
    pub(crate) fn point(&self, k: usize, s: &Vector3<f64>) -> Vec3Jet {
        let mut j = SMatrix::<f64, 3, NL>::zeros();
        j.fixed_view_mut::<3, 3>(0, 7 * k)
            .copy_from(&Matrix3::identity());
        j.fixed_view_mut::<3, 4>(0, 7 * k + 3)
            .copy_from(&b_matrix(&self.p[k], s));
        let mut ss = [Vector3::zeros(); 2];
        ss[k] = *s;
        Vec3Jet {
            v: self.r[k] + rotation(&self.p[k]) * s,
            j,
            s: ss,
        }
    }

    /// World direction of the body-frame vector `a` of side `k`.
    pub(crate) fn vector(&self, k: usize, a: &Vector3<f64>) -> Vec3Jet {
        let mut j = SMatrix::<f64, 3, NL>::zeros();
        j.fixed_view_mut::<3, 4>(0, 7 * k + 3)
            .copy_from(&b_matrix(&self.p[k], a));
        let mut ss = [Vector3::zeros(); 2];
        ss[k] = *a;
        Vec3Jet {
            v: rotation(&self.p[k]) * a,
            j,
            s: ss,
        }
    }

    /// Dot product `a · b` with exact gradient and Hessian.
    pub(crate) fn dot(&self, a: &Vec3Jet, b: &Vec3Jet) -> Scalar {
        let v = a.v.dot(&b.v);
        let g = a.j.transpose() * b.v + b.j.transpose() * a.v;
        let h = self.hess.then(|| {
            let cross = a.j.transpose() * b.j;
            Box::new(cross + cross.transpose() + a.contract(&b.v) + b.contract(&a.v))
        });
        Scalar { v, g, h }
    }

    /// `atan2(s, c)` with exact gradient and Hessian.
    pub(crate) fn atan2(&self, s: &Scalar, c: &Scalar) -> Scalar {
        let rho = s.v * s.v + c.v * c.v;
        let n = s.g * (c.v / rho) - c.g * (s.v / rho);
        let h = self.hess.then(|| {
            let a = s.g * c.g.transpose() - c.g * s.g.transpose() + hess_or_zero(&s.h) * c.v
                - hess_or_zero(&c.h) * s.v;
            let drho = s.g * (2.0 * s.v) + c.g * (2.0 * c.v);
            let m = a / rho - n * drho.transpose() / rho;
            Box::new((m + m.transpose()) * 0.5)
        });
        Scalar {
            v: s.v.atan2(c.v),
            g: n,
            h,
        }
    }
}

impl Vec3Jet {
    /// `a − b`.
    pub(crate) fn sub(&self, b: &Vec3Jet) -> Vec3Jet {
        Vec3Jet {
            v: self.v - b.v,
            j: self.j - b.j,
            s: [self.s[0] - b.s[0], self.s[1] - b.s[1]],
        }
    }

    /// `Σ_i w_i ∇² f_i`: the Hessian of `wᵀ f` for a constant `w`.
    pub(crate) fn contract(&self, w: &Vector3<f64>) -> LMat {
        let mut h = LMat::zeros();
        for k in 0..2 {
            if self.s[k] == Vector3::zeros() {
                continue;
            }
            for m in 0..4 {
                let bm = b_matrix(&Vector4::ith(m, 1.0), &self.s[k]);
                let row = bm.transpose() * w;
                for l in 0..4 {
                    h[(7 * k + 3 + m, 7 * k + 3 + l)] += row[l];
                }
            }
        }
        h
    }
}

impl Scalar {
    /// `f − c` for a constant `c`.
    pub(crate) fn minus(mut self, c: f64) -> Scalar {
        self.v -= c;
        self
    }

    /// `c f` for a constant `c`.
    pub(crate) fn scale(mut self, c: f64) -> Scalar {
        self.v *= c;
        self.g *= c;
        if let Some(h) = self.h.as_deref_mut() {
            *h *= c;
        }
        self
    }

    /// `a + b`.
    pub(crate) fn add(mut self, b: &Scalar) -> Scalar {
        self.v += b.v;
        self.g += b.g;
        match (self.h.as_deref_mut(), b.h.as_deref()) {
            (Some(a), Some(b)) => *a += b,
            (None, Some(b)) => self.h = Some(Box::new(*b)),
            (_, None) => {}
        }
        self
    }

    /// `U(f)` given `U(f)`, `U'(f)`, `U''(f)`.
    pub(crate) fn compose(&self, u: f64, du: f64, ddu: f64) -> Scalar {
        Scalar {
            v: u,
            g: self.g * du,
            h: self
                .h
                .as_deref()
                .map(|h| Box::new(self.g * self.g.transpose() * ddu + h * du)),
        }
    }
}

#[cfg(test)]
pub(crate) mod testing {
    //! The one shared finite-difference checker for local jets.
    use super::*;

    /// A reproducible non-unit pose pair (raw Euler parameters, as inside the corrector).
    pub(crate) fn sample_pair(seed: u64) -> Pair {
        let mut lcg = crate::lcg::Lcg::new(seed);
        lcg.next_u64();
        let mut next = || lcg.signed();
        let mut r = [Vector3::zeros(); 2];
        let mut p = [Vector4::zeros(); 2];
        for k in 0..2 {
            r[k] = Vector3::new(next(), next(), next());
            p[k] = Vector4::new(1.0 + 0.3 * next(), next(), next(), next()) * 0.8;
        }
        Pair { r, p, hess: true }
    }

    /// A joint of `kind` between bodies 0 and 1 with skewed, non-trivial frames on both sides:
    /// the one fixture of the joint-row tests.
    pub(crate) fn sample_joint(kind: crate::model::JointKind) -> crate::model::Joint {
        use nalgebra::{Isometry3, Translation3, UnitQuaternion};
        let f0 = Isometry3::from_parts(
            Translation3::new(0.1, 0.2, -0.3),
            UnitQuaternion::from_euler_angles(0.3, -0.2, 0.9),
        );
        let f1 = Isometry3::from_parts(
            Translation3::new(-0.2, 0.05, 0.4),
            UnitQuaternion::from_euler_angles(-0.5, 0.4, 0.1),
        );
        crate::model::Joint {
            name: "j".into(),
            kind,
            parent_link: "a".into(),
            child_link: "b".into(),
            bodies: [Some(crate::model::BodyId(0)), Some(crate::model::BodyId(1))],
            body_from_joint: [f0, f1],
            tree: false,
            merged: false,
            limits: None,
            effort_limit: None,
            source: None,
        }
    }

    /// Every joint kind of the table ([`crate::joint::KINDS`]), its parameter (if any) not zero.
    pub(crate) fn every_kind() -> Vec<crate::model::JointKind> {
        use crate::model::JointKind;
        crate::joint::KINDS
            .iter()
            .map(|k| match *k {
                JointKind::Screw { .. } => JointKind::Screw { pitch: 0.01 },
                JointKind::Distance { .. } => JointKind::Distance { length: 0.7 },
                k => k,
            })
            .collect()
    }

    /// `pair` with its local coordinate `i` (`r₀, p₀, r₁, p₁`, 7 a side) moved by `h`.
    pub(crate) fn shifted(pair: &Pair, i: usize, h: f64) -> Pair {
        let mut out = *pair;
        let (k, c) = (i / 7, i % 7);
        if c < 3 {
            out.r[k][c] += h;
        } else {
            out.p[k][c - 3] += h;
        }
        out
    }

    /// Checks the gradient and Hessian of `f` against central differences at `pair`.
    pub(crate) fn check_scalar(pair: &Pair, f: &dyn Fn(&Pair) -> Scalar, what: &str) {
        let h = 1e-6;
        let s = f(pair);
        for i in 0..NL {
            let fp = f(&shifted(pair, i, h));
            let fm = f(&shifted(pair, i, -h));
            let fd = (fp.v - fm.v) / (2.0 * h);
            let scale = 1.0 + s.g[i].abs();
            assert!(
                (fd - s.g[i]).abs() < 1e-6 * scale,
                "{what}: gradient[{i}] analytic {} vs central difference {fd}",
                s.g[i]
            );
            let fdh = (fp.g - fm.g) / (2.0 * h);
            let sh = hess_or_zero(&s.h);
            for j in 0..NL {
                let scale = 1.0 + sh[(j, i)].abs();
                assert!(
                    (fdh[j] - sh[(j, i)]).abs() < 1e-5 * scale,
                    "{what}: hessian[{j},{i}] analytic {} vs central difference {}",
                    sh[(j, i)],
                    fdh[j]
                );
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::testing::*;
    use super::*;

    #[test]
    fn dot_of_points_and_vectors() {
        let s0 = Vector3::new(0.3, -0.2, 0.5);
        let s1 = Vector3::new(-0.1, 0.4, 0.2);
        for seed in 0..5 {
            let pair = sample_pair(seed);
            check_scalar(
                &pair,
                &|q| {
                    let d = q.point(1, &s1).sub(&q.point(0, &s0));
                    q.dot(&d, &q.vector(0, &Vector3::new(0.0, 1.0, 0.0)))
                },
                "d·y0",
            );
            check_scalar(
                &pair,
                &|q| q.dot(&q.vector(0, &Vector3::z()), &q.vector(1, &Vector3::x())),
                "z0·x1",
            );
        }
    }

    #[test]
    fn atan2_and_compose() {
        for seed in 0..5 {
            let pair = sample_pair(seed);
            check_scalar(
                &pair,
                &|q| {
                    let s = q.dot(&q.vector(0, &Vector3::y()), &q.vector(1, &Vector3::x()));
                    let c = q.dot(&q.vector(0, &Vector3::x()), &q.vector(1, &Vector3::x()));
                    q.atan2(&s, &c)
                },
                "atan2",
            );
            check_scalar(
                &pair,
                &|q| {
                    let d = q.point(1, &Vector3::x()).sub(&q.point(0, &Vector3::y()));
                    let l2 = q.dot(&d, &d);
                    let l = l2.v.sqrt();
                    l2.compose(l, 0.5 / l, -0.25 / (l * l * l))
                },
                "length",
            );
        }
    }
}

/// Builds the [`Pair`] of two bodies from the state vector `q` (ground sides hold the
/// identity pose).
pub(crate) fn pair_of(
    bodies: &[Option<crate::model::BodyId>; 2],
    q: &nalgebra::DVector<f64>,
    hess: bool,
) -> Pair {
    let mut r = [Vector3::zeros(); 2];
    let mut p = [Vector4::new(1.0, 0.0, 0.0, 0.0); 2];
    for k in 0..2 {
        if let Some(b) = bodies[k] {
            // One bounds check for the body's 7 coordinates (not two per entry).
            let x = &q.as_slice()[7 * b.0..7 * b.0 + 7];
            r[k] = Vector3::new(x[0], x[1], x[2]);
            p[k] = Vector4::new(x[3], x[4], x[5], x[6]);
        }
    }
    Pair { r, p, hess }
}

/// `A(p)` of every body at `q` (7 coordinates a body), formed once for all the terms that
/// read a body's: the same numbers as [`rotation`] of the `p` that [`pair_of`] reads.
pub(crate) fn body_rotations(q: &nalgebra::DVector<f64>) -> Vec<Matrix3<f64>> {
    q.as_slice()
        .chunks_exact(7)
        .map(|x| rotation(&Vector4::new(x[3], x[4], x[5], x[6])))
        .collect()
}

/// `A(p)` of a ground side: of the identity `p` that [`pair_of`] gives it.
pub(crate) fn ground_rotation() -> Matrix3<f64> {
    rotation(&Vector4::new(1.0, 0.0, 0.0, 0.0))
}

/// Global coordinate index of local coordinate `i` (`None` on a ground side).
pub(crate) fn global_index(bodies: &[Option<crate::model::BodyId>; 2], i: usize) -> Option<usize> {
    bodies[i / 7].map(|b| 7 * b.0 + i % 7)
}

/// Where second derivatives over body pairs are accumulated: a dense matrix (small models) or
/// the block-sparse Hessian of the large-scale path.
pub(crate) trait HessianSink {
    /// Adds `c h` for the local Hessian `h` over the coordinates of `bodies`.
    fn add_block(&mut self, bodies: &[Option<crate::model::BodyId>; 2], h: &LMat, c: f64);
    /// Adds `v` at the global position `(i, j)`.
    fn add_entry(&mut self, i: usize, j: usize, v: f64);
    /// Adds `c h` for a local Hessian `h` that is zero outside the Euler parameters of the
    /// pair, given by its [`EULER`] rows and columns `hp` (a revolute angle, a weighted point:
    /// `A(p)` is quadratic in `p` and the rest linear). By default the full local Hessian.
    fn add_euler_block(
        &mut self,
        bodies: &[Option<crate::model::BodyId>; 2],
        hp: &SMatrix<f64, 8, 8>,
        c: f64,
    ) {
        self.add_block(bodies, &euler_to_local(hp), c);
    }
    /// Adds `c h` for a local Hessian `h` symmetric to the last bit (`h[(i, j)]` and
    /// `h[(j, i)]` the same number, as the augmentation's sums: a sink may read either, see
    /// [`add_symmetric_part`]). By default [`HessianSink::add_block`].
    fn add_symmetric_block(
        &mut self,
        bodies: &[Option<crate::model::BodyId>; 2],
        h: &LMat,
        c: f64,
    ) {
        self.add_block(bodies, h, c);
    }
}

/// `blk[7 i + j] += c h[(7 sa + i, 7 sb + j)]` for the sides `(sa, sb)` of a local Hessian `h`
/// symmetric to the last bit, read as `h[(7 sb + j, 7 sa + i)]`: along `h`'s columns (as it
/// is stored), so that both runs are contiguous. The same numbers as the row-wise read.
pub(crate) fn add_symmetric_part(blk: &mut [f64; 49], h: &LMat, sa: usize, sb: usize, c: f64) {
    let h = h.as_slice();
    for (i, row) in blk.chunks_exact_mut(7).enumerate() {
        let at = NL * (7 * sa + i) + 7 * sb;
        for (x, &v) in row.iter_mut().zip(&h[at..at + 7]) {
            *x += c * v;
        }
    }
}

/// The Euler-parameter coordinates of a body pair (local indices).
pub(crate) const EULER: [usize; 8] = [3, 4, 5, 6, 10, 11, 12, 13];

/// The local Hessian whose [`EULER`] rows and columns are `hp` (zero elsewhere).
pub(crate) fn euler_to_local(hp: &SMatrix<f64, 8, 8>) -> LMat {
    let mut h = LMat::zeros();
    for (a, &i) in EULER.iter().enumerate() {
        for (b, &j) in EULER.iter().enumerate() {
            h[(i, j)] = hp[(a, b)];
        }
    }
    h
}

impl HessianSink for nalgebra::DMatrix<f64> {
    fn add_block(&mut self, bodies: &[Option<crate::model::BodyId>; 2], h: &LMat, c: f64) {
        for i in 0..NL {
            let Some(gi) = global_index(bodies, i) else {
                continue;
            };
            for j in 0..NL {
                if let Some(gj) = global_index(bodies, j) {
                    self[(gi, gj)] += c * h[(i, j)];
                }
            }
        }
    }

    fn add_entry(&mut self, i: usize, j: usize, v: f64) {
        self[(i, j)] += v;
    }
}

/// Adds `c ∇f` to the global vector `g` and `c ∇²f` to the Hessian sink `h` (if given).
pub(crate) fn scatter<'h>(
    bodies: &[Option<crate::model::BodyId>; 2],
    f: &Scalar,
    c: f64,
    g: &mut nalgebra::DVector<f64>,
    h: Option<&mut (dyn HessianSink + 'h)>,
) {
    for i in 0..NL {
        if let Some(gi) = global_index(bodies, i) {
            g[gi] += c * f.g[i];
        }
    }
    if let Some(h) = h {
        h.add_block(bodies, &hess_or_zero(&f.h), c);
    }
}
