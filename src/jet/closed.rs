//! Closed-form first and second derivatives of the constraint primitives, without generic
//! 14-coordinate jets.
//!
//! Every joint row but a screw's thread is a component of `d` or a dot product `aᵀb` of two
//! 3-vectors of the form `u = Σ_k t_k r_k + A(p_k) s_k` (a point: `t_k = 1`; a direction:
//! `t_k = 0`; `d = o₁ − o₀`: `t = (−1, 1)`, `s = (−s₀, s₁)`). Their derivatives are
//!
//! - `∂u/∂r_k = t_k I`, `∂u/∂p_k = B_k = B(p_k, s_k)` ([`crate::math::b_matrix`]);
//! - `∇(aᵀb)`: `t^a_k b + t^b_k a` over `r_k`, `B^a_kᵀ b + B^b_kᵀ a` over `p_k`;
//! - `∇²(aᵀb) = J_aᵀ J_b + J_bᵀ J_a + C(a, b) + C(b, a)` with `J_k = [t_k I, B_k]` and the
//!   curvature of `A(p)`: `wᵀ A(p) s = pᵀ M(s, w) p` is a quadratic form (homogeneous
//!   `A(p)`), so `C(a, w)` is `2 M(s^a_k, w)` on the `p_k p_k` block, with
//!
//!   `M(s, w) = [ wᵀs      (s × w)ᵀ          ]`
//!   `          [ s × w    w sᵀ + s wᵀ − wᵀs I ]`.
//!
//! Rows are weighted before their Hessians are formed (`Σ_r w_r ∇²Φ_r` in one 14 × 14 local
//! matrix, only the blocks a primitive touches), and the three components of `d` weighted by
//! `w` are `∇²(wᵀd) = C(d, w)`. The generic jets of [`crate::jet`] stay the reference: the
//! tests check every row here against them and against central differences.

use super::{LMat, LVec, Pair, Scalar};
use crate::joint::{Row, V};
use crate::math::b_matrix;
use crate::model::Joint;
use nalgebra::{Matrix3, Matrix3x4, Matrix4, SMatrix, Vector3};
pub(crate) mod euler;
mod rotations;
#[cfg(test)]
pub(crate) use rotations::OwnedRotations;
pub(crate) use rotations::{frame_rotations, JointRotations, Rotations};

/// `Σ_k t_k r_k + A(p_k) s_k` with `B_k = B(p_k, s_k)`; `on[k]` whether side `k` enters.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Lin {
    pub(crate) v: Vector3<f64>,
    t: [f64; 2],
    s: [Vector3<f64>; 2],
    b: [Matrix3x4<f64>; 2],
    on: [bool; 2],
}

/// `M(s, w)` of the module docs: `wᵀ A(p) s = pᵀ M p`.
pub(crate) fn quadratic_form(s: &Vector3<f64>, w: &Vector3<f64>) -> Matrix4<f64> {
    let ws = w.dot(s);
    let c = s.cross(w);
    let mut m = Matrix4::zeros();
    m[(0, 0)] = ws;
    for i in 0..3 {
        m[(0, i + 1)] = c[i];
        m[(i + 1, 0)] = c[i];
        for j in 0..3 {
            m[(i + 1, j + 1)] = w[i] * s[j] + s[i] * w[j];
        }
        m[(i + 1, i + 1)] -= ws;
    }
    m
}

impl Lin {
    /// The constant zero vector.
    const ZERO: Lin = Lin {
        v: Vector3::new(0.0, 0.0, 0.0),
        t: [0.0; 2],
        s: [Vector3::new(0.0, 0.0, 0.0); 2],
        b: [Matrix3x4::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0); 2],
        on: [false; 2],
    };

    /// The world point of the body-frame point `s` of side `k`.
    pub(crate) fn point(pair: &Pair, a_k: &Matrix3<f64>, k: usize, s: &Vector3<f64>) -> Lin {
        let mut l = Lin::ZERO;
        l.set_point(pair, a_k, k, s);
        l
    }

    /// [`Lin::point`] written over `self` (no copy of the whole vector).
    fn set_point(&mut self, pair: &Pair, a_k: &Matrix3<f64>, k: usize, s: &Vector3<f64>) {
        self.set_vector(pair, a_k, k, s);
        self.v += pair.r[k];
        self.t[k] = 1.0;
    }

    /// The world direction of the body-frame vector `a` of side `k`.
    pub(crate) fn vector(pair: &Pair, a_k: &Matrix3<f64>, k: usize, a: &Vector3<f64>) -> Lin {
        let mut l = Lin::ZERO;
        l.set_vector(pair, a_k, k, a);
        l
    }

    /// [`Lin::vector`] written over `self` (no copy of the whole vector).
    fn set_vector(&mut self, pair: &Pair, a_k: &Matrix3<f64>, k: usize, a: &Vector3<f64>) {
        self.v = a_k * a;
        self.t = [0.0; 2];
        self.s = [Vector3::zeros(); 2];
        self.b = [Matrix3x4::zeros(); 2];
        self.on = [false; 2];
        self.s[k] = *a;
        self.b[k] = b_matrix(&pair.p[k], a);
        self.on[k] = true;
    }

    /// `self −= o` for two points of different sides (`d = o₁ − o₀`).
    fn subtract(&mut self, o: &Lin) {
        self.v -= o.v;
        for k in 0..2 {
            if o.on[k] {
                self.t[k] -= o.t[k];
                self.s[k] -= o.s[k];
                self.b[k] -= o.b[k];
                self.on[k] = true;
            }
        }
    }
}

/// `∇(aᵀb)` added into `g` with weight `c`.
pub(crate) fn dot_gradient(a: &Lin, b: &Lin, c: f64, g: &mut LVec) {
    for k in 0..2 {
        let o = 7 * k;
        if a.on[k] {
            if a.t[k] != 0.0 {
                for i in 0..3 {
                    g[o + i] += c * a.t[k] * b.v[i];
                }
            }
            let gp = a.b[k].tr_mul(&b.v);
            for i in 0..4 {
                g[o + 3 + i] += c * gp[i];
            }
        }
        if b.on[k] {
            if b.t[k] != 0.0 {
                for i in 0..3 {
                    g[o + i] += c * b.t[k] * a.v[i];
                }
            }
            let gp = b.b[k].tr_mul(&a.v);
            for i in 0..4 {
                g[o + 3 + i] += c * gp[i];
            }
        }
    }
}

/// `∇(wᵀa)` for a constant `w` added into `g`.
#[cfg(test)]
pub(crate) fn linear_gradient(a: &Lin, w: &Vector3<f64>, g: &mut LVec) {
    for k in 0..2 {
        if a.on[k] {
            let o = 7 * k;
            for i in 0..3 {
                g[o + i] += a.t[k] * w[i];
            }
            let gp = a.b[k].tr_mul(w);
            for i in 0..4 {
                g[o + 3 + i] += gp[i];
            }
        }
    }
}

/// `∇a_m = ∇(e_mᵀ a)` added into `g`: [`linear_gradient`] for the unit vector `e_m`, which
/// reads row `m` of `t_k I` and of `B_k`. Its products with the zero components of `e_m`
/// are zeros, which leave a finite sum unchanged but for the sign of a zero result, and each
/// sum enters `g` by an addition (to the zero `g` starts from, in [`rows_each`]), which
/// clears that sign: the same numbers to the last bit.
#[cfg(test)]
fn component_gradient(a: &Lin, m: usize, g: &mut LVec) {
    for k in 0..2 {
        if a.on[k] {
            let o = 7 * k;
            g[o + m] += a.t[k];
            for i in 0..4 {
                g[o + 3 + i] += a.b[k][(m, i)];
            }
        }
    }
}

/// `∇²(wᵀa) = C(a, w)` for a constant `w` added into `h`.
pub(crate) fn linear_hessian(a: &Lin, w: &Vector3<f64>, h: &mut LMat) {
    for k in 0..2 {
        if a.on[k] {
            let m = quadratic_form(&a.s[k], w) * 2.0;
            let o = 7 * k + 3;
            for i in 0..4 {
                for j in 0..4 {
                    h[(o + i, o + j)] += m[(i, j)];
                }
            }
        }
    }
}

/// [`linear_hessian`] into the Euler-parameter rows and columns of the pair
/// ([`crate::jet::EULER`]): the same entries, the same arithmetic.
pub(crate) fn linear_hessian_euler(a: &Lin, w: &Vector3<f64>, hp: &mut SMatrix<f64, 8, 8>) {
    for k in 0..2 {
        if a.on[k] {
            let m = quadratic_form(&a.s[k], w) * 2.0;
            let o = 4 * k;
            for i in 0..4 {
                for j in 0..4 {
                    hp[(o + i, o + j)] += m[(i, j)];
                }
            }
        }
    }
}

/// `c ∇²(aᵀb)` added into `h`.
pub(crate) fn dot_hessian(a: &Lin, b: &Lin, c: f64, h: &mut LMat) {
    for k in 0..2 {
        if !a.on[k] {
            continue;
        }
        for l in 0..2 {
            if !b.on[l] {
                continue;
            }
            // c J^a_kᵀ J^b_l at (k, l) and its transpose at (l, k).
            let (ok, ol) = (7 * k, 7 * l);
            let tt = c * a.t[k] * b.t[l];
            if tt != 0.0 {
                for i in 0..3 {
                    h[(ok + i, ol + i)] += tt;
                    h[(ol + i, ok + i)] += tt;
                }
            }
            if a.t[k] != 0.0 {
                // r_k × p_l: t^a_k B^b_l.
                let s = c * a.t[k];
                for i in 0..3 {
                    for j in 0..4 {
                        let v = s * b.b[l][(i, j)];
                        h[(ok + i, ol + 3 + j)] += v;
                        h[(ol + 3 + j, ok + i)] += v;
                    }
                }
            }
            if b.t[l] != 0.0 {
                // p_k × r_l: B^a_kᵀ t^b_l.
                let s = c * b.t[l];
                for i in 0..4 {
                    for j in 0..3 {
                        let v = s * a.b[k][(j, i)];
                        h[(ok + 3 + i, ol + j)] += v;
                        h[(ol + j, ok + 3 + i)] += v;
                    }
                }
            }
            let pp = a.b[k].tr_mul(&b.b[l]) * c;
            for i in 0..4 {
                for j in 0..4 {
                    h[(ok + 3 + i, ol + 3 + j)] += pp[(i, j)];
                    h[(ol + 3 + j, ok + 3 + i)] += pp[(i, j)];
                }
            }
        }
    }
    linear_hessian(a, &(b.v * c), h);
    linear_hessian(b, &(a.v * c), h);
}

/// [`dot_hessian`] on the pair's Euler parameters ([`crate::jet::EULER`]) for two directions
/// (`t = 0`: the full Hessian is zero elsewhere): the same entries, added in the same order.
pub(crate) fn dot_hessian_euler(a: &Lin, b: &Lin, c: f64, h: &mut SMatrix<f64, 8, 8>) {
    if a.t != [0.0; 2] || b.t != [0.0; 2] {
        // Not two directions: the full Hessian, restricted.
        let mut full = LMat::zeros();
        dot_hessian(a, b, c, &mut full);
        for (x, &i) in super::EULER.iter().enumerate() {
            for (y, &j) in super::EULER.iter().enumerate() {
                h[(x, y)] += full[(i, j)];
            }
        }
        return;
    }
    for k in 0..2 {
        if !a.on[k] {
            continue;
        }
        for l in 0..2 {
            if !b.on[l] {
                continue;
            }
            let (ok, ol) = (4 * k, 4 * l);
            let pp = a.b[k].tr_mul(&b.b[l]) * c;
            for i in 0..4 {
                for j in 0..4 {
                    h[(ok + i, ol + j)] += pp[(i, j)];
                    h[(ol + j, ok + i)] += pp[(i, j)];
                }
            }
        }
    }
    linear_hessian_euler(a, &(b.v * c), h);
    linear_hessian_euler(b, &(a.v * c), h);
}

/// The joint frames of both sides as far as a joint's rows need them: origin difference
/// `d = o₁ − o₀` and axes (`None` where not needed).
pub(crate) struct Frames {
    /// The vectors in [`V`] order; those not needed are the constant zero.
    vectors: [Lin; 7],
}

impl Frames {
    /// The vectors `layout` uses, for the frames of `joint` at `pair` (written in place).
    #[inline(always)]
    fn of(joint: &Joint, pair: &Pair, rots: &JointRotations, layout: &[Row]) -> Self {
        let mut need = [false; 7];
        for row in layout {
            match *row {
                Row::Component(_) | Row::Length | Row::Thread => need[V::D as usize] = true,
                Row::Dot(a, b) => {
                    need[a as usize] = true;
                    need[b as usize] = true;
                }
            }
        }
        let axis = |slot: &mut Lin, k: usize, i: usize| {
            slot.set_vector(pair, rots.a[k], k, &rots.r[k].column(i).into_owned());
        };
        let mut f = Frames {
            vectors: [Lin::ZERO; 7],
        };
        for (v, slot) in f.vectors.iter_mut().enumerate() {
            if !need[v] {
                continue;
            }
            match v {
                0 => {
                    let o = |k: usize| &joint.body_from_joint[k].translation.vector;
                    slot.set_point(pair, rots.a[1], 1, o(1));
                    slot.subtract(&Lin::point(pair, rots.a[0], 0, o(0)));
                }
                // The axes `x₀ y₀ z₀ x₁ y₁ z₁`.
                _ => axis(slot, (v - 1) / 3, (v - 1) % 3),
            }
        }
        f
    }

    fn get(&self, v: V) -> &Lin {
        &self.vectors[v as usize]
    }
}

/// The rows of a joint ([`crate::joint::Spec::rows`], in [`crate::constraints::joint::rows`]
/// order), or `None` for a joint evaluated by the generic jets (a screw's thread row reads
/// its angle) or without rows.
fn layout(joint: &Joint) -> Option<&'static [Row]> {
    let spec = joint.kind.spec();
    (!joint.merged && spec.closed_form).then_some(spec.rows)
}

/// Whether the rows of `joint` have a closed form here.
pub(crate) fn supports(joint: &Joint) -> bool {
    layout(joint).is_some()
}

/// Values and gradients of the rows of `joint` (no Hessians), handed to `emit(k, Φ_k, ∇Φ_k)`
/// in row order: nothing collected, nothing copied. The reference of
/// `constraints::closed_rows`, which writes them into `Φ` and the triplets.
#[cfg(test)]
pub(crate) fn rows_each(
    joint: &Joint,
    pair: &Pair,
    rots: &JointRotations,
    mut emit: impl FnMut(usize, f64, &LVec),
) {
    let Some(layout) = layout(joint) else {
        return;
    };
    let f = Frames::of(joint, pair, rots, layout);
    for (k, row) in layout.iter().enumerate() {
        let mut g = LVec::zeros();
        let v = match *row {
            Row::Component(m) => {
                component_gradient(f.get(V::D), m, &mut g);
                f.get(V::D).v[m]
            }
            Row::Dot(a, b) => {
                let (a, b) = (f.get(a), f.get(b));
                dot_gradient(a, b, 1.0, &mut g);
                a.v.dot(&b.v)
            }
            Row::Length => {
                let d = f.get(V::D);
                dot_gradient(d, d, 1.0, &mut g);
                let length = joint.kind.parameter();
                d.v.dot(&d.v) - length * length
            }
            Row::Thread => unreachable!("a thread row has no closed form (Spec::closed_form)"),
        };
        emit(k, v, &g);
    }
}

/// Values of the rows of `joint` into `out` (cleared first): the vectors alone, without
/// derivatives (the tests' reference; `constraints::closed_rows` writes them into `Φ`).
#[cfg(test)]
pub(crate) fn values(joint: &Joint, pair: &Pair, rots: &JointRotations, out: &mut Vec<f64>) {
    out.clear();
    let Some(layout) = layout(joint) else {
        return;
    };
    let (a, r) = (rots.a, rots.r);
    let f = &joint.body_from_joint;
    // The same arithmetic as `Frames::of`: values equal those of `rows` to the last bit. Each
    // vector is formed once (a revolute's `z₀` serves two rows).
    let mut memo: [Option<Vector3<f64>>; 7] = [None; 7];
    let mut vector = |v: V| -> Vector3<f64> {
        if let Some(x) = memo[v as usize] {
            return x;
        }
        let axis = |k: usize, i: usize| a[k] * r[k].column(i).into_owned();
        let point = |k: usize| a[k] * f[k].translation.vector + pair.r[k];
        let x = match v {
            V::D => point(1) - point(0),
            _ => axis((v as usize - 1) / 3, (v as usize - 1) % 3),
        };
        memo[v as usize] = Some(x);
        x
    };
    for row in layout {
        out.push(match *row {
            Row::Component(m) => vector(V::D)[m],
            Row::Dot(a, b) => vector(a).dot(&vector(b)),
            Row::Length => {
                let length = joint.kind.parameter();
                vector(V::D).dot(&vector(V::D)) - length * length
            }
            Row::Thread => unreachable!("a thread row has no closed form (Spec::closed_form)"),
        });
    }
}

/// `Σ_r w_r ∇²Φ_r` over the rows of `joint` added into `h` (`w` one weight per row).
pub(crate) fn add_weighted_hessian(
    joint: &Joint,
    pair: &Pair,
    rots: &JointRotations,
    w: &[f64],
    h: &mut LMat,
) {
    let Some(layout) = layout(joint) else {
        return;
    };
    let f = Frames::of(joint, pair, rots, layout);
    let mut wd = Vector3::zeros();
    for (row, &c) in layout.iter().zip(w) {
        if c == 0.0 {
            continue;
        }
        match *row {
            Row::Component(m) => wd[m] += c,
            Row::Dot(a, b) => dot_hessian(f.get(a), f.get(b), c, h),
            Row::Length => dot_hessian(f.get(V::D), f.get(V::D), c, h),
            Row::Thread => unreachable!("a thread row has no closed form (Spec::closed_form)"),
        }
    }
    if wd != Vector3::zeros() {
        linear_hessian(f.get(V::D), &wd, h);
    }
}

/// The revolute angle `atan2(y₀·x₁, x₀·x₁)` about the parent's `z` (as
/// [`crate::kinematics::angle`], in (−π, π]), with the Hessian when `pair.hess`.
pub(crate) fn revolute_angle(joint: &Joint, pair: &Pair) -> Scalar {
    let (rot, r) = (Rotations::of(pair), frame_rotations(joint));
    let axis = |k: usize, i: usize| Lin::vector(pair, &rot.0[k], k, &r[k].column(i).into_owned());
    let (x0, y0, x1) = (axis(0, 0), axis(0, 1), axis(1, 0));
    let scalar = |a: &Lin, b: &Lin| {
        let mut g = LVec::zeros();
        dot_gradient(a, b, 1.0, &mut g);
        let h = pair.hess.then(|| {
            let mut h = Box::new(LMat::zeros());
            dot_hessian(a, b, 1.0, &mut h);
            h
        });
        Scalar {
            v: a.v.dot(&b.v),
            g,
            h,
        }
    };
    pair.atan2(&scalar(&y0, &x1), &scalar(&x0, &x1))
}

#[cfg(test)]
pub(crate) mod tests;
