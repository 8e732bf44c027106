//! The weighted Hessian `Σ_r w_r ∇²Φ_r` of a joint whose rows are all components of
//! `d = o₁ − o₀` or dot products of two axes (a revolute, a universal, a spherical, a fixed
//! joint...), over the 8 Euler parameters of its pair only.
//!
//! Such a Hessian is zero outside the `p_k p_l` blocks (module docs of `jet::closed`): a
//! component `wᵀd` adds `C(d, w) = 2 M(±s_k, w)` on the `p_k p_k` blocks, a dot product of two
//! axes `aᵀb` adds `B^a_kᵀ B^b_l` (and its transpose) and the curvatures `2 M(s^a_k, b)`,
//! `2 M(s^b_l, a)`. Only the axes the rows read are formed (their `A(p_k) s`, `B(p_k, s)`);
//! `d` enters by its body-frame offsets `s` alone (its curvature does not depend on `p`'s
//! value), so its factors are not formed. The dot rows that share their first axis `a` are
//! summed before the product: `Σ_r c_r aᵀb_r = aᵀu` with `u = Σ_r c_r b_r` (one direction
//! per side of the `b_r`, its body-frame vector `Σ_r c_r s_r`), so a revolute's two axis
//! rows form one `B` matrix and one product fewer. The entries are those of
//! [`super::add_weighted_hessian`] restricted to [`crate::jet::EULER`] up to rounding.

#[cfg(test)]
use super::OwnedRotations;
use super::{dot_hessian_euler, layout, linear_hessian_euler, JointRotations, Lin};
use crate::jet::Pair;
use crate::joint::{Row, V};
use crate::model::Joint;
use nalgebra::{Matrix3x4, SMatrix, Vector3};

/// Whether every row of `joint` has a Hessian zero outside the Euler parameters (no
/// length row, no dot product with `d`); `false` for a joint without a closed form.
pub(crate) fn euler_only(joint: &Joint) -> bool {
    layout(joint).is_some_and(|rows| {
        rows.iter().all(|row| match *row {
            Row::Component(_) => true,
            Row::Dot(a, b) => a != V::D && b != V::D,
            Row::Length | Row::Thread => false,
        })
    })
}

/// `Σ_r w_r ∇²Φ_r` over the rows of `joint` added into `hp` (the Euler-parameter rows and
/// columns of the pair), for a joint with [`euler_only`] rows (else nothing is added).
pub(crate) fn add_weighted_hessian_euler(
    joint: &Joint,
    pair: &Pair,
    rots: &JointRotations,
    w: &[f64],
    hp: &mut SMatrix<f64, 8, 8>,
) {
    let Some(layout) = layout(joint).filter(|_| euler_only(joint)) else {
        return;
    };
    // The dot rows `Σ_r c_r a_rᵀ b_r` summed by their first axis and the side of their second:
    // `Σ c aᵀb_r = aᵀ(Σ c b_r)`, and `Σ c b_r = A(p_k) Σ c s_r` is one direction of side `k`
    // (a revolute's two rows `z₀ᵀx₁`, `z₀ᵀy₁` are `z₀ᵀu₁`, `u₁ = A(p₁)(c₁ x + c₂ y)`): one
    // product `aᵀu` in place of one per row (the same Hessian up to rounding).
    let mut combined: [[Option<Vector3<f64>>; 2]; 7] = [[None; 2]; 7];
    let mut wd = Vector3::zeros();
    for (row, &c) in layout.iter().zip(w) {
        if c == 0.0 {
            continue;
        }
        match *row {
            Row::Component(m) => wd[m] += c,
            Row::Dot(a, b) => {
                let (k, i) = ((b as usize - 1) / 3, (b as usize - 1) % 3);
                let s = rots.r[k].column(i) * c;
                let slot = &mut combined[a as usize][k];
                *slot = Some(slot.map_or(s, |x| x + s));
            }
            Row::Length | Row::Thread => unreachable!("not euler_only"),
        }
    }
    for (v, sides) in combined.iter().enumerate().skip(1) {
        if sides.iter().all(Option::is_none) {
            continue;
        }
        let (k, i) = ((v - 1) / 3, (v - 1) % 3);
        let a = Lin::vector(pair, rots.a[k], k, &rots.r[k].column(i).into_owned());
        for (l, s) in sides.iter().enumerate() {
            if let Some(s) = s {
                let u = Lin::vector(pair, rots.a[l], l, s);
                dot_hessian_euler(&a, &u, 1.0, hp);
            }
        }
    }
    if wd != Vector3::zeros() {
        // `d`'s offsets as `Lin::point(1).minus(&Lin::point(0))` forms them; its value and
        // factors do not enter its curvature.
        let f = &joint.body_from_joint;
        let zero = Matrix3x4::zeros();
        let d = Lin {
            v: Vector3::zeros(),
            t: [-1.0, 1.0],
            s: [
                Vector3::zeros() - f[0].translation.vector,
                f[1].translation.vector,
            ],
            b: [zero, zero],
            on: [true, true],
        };
        linear_hessian_euler(&d, &wd, hp);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::jet::testing::{check_scalar, every_kind, sample_joint, sample_pair};
    use crate::jet::{euler_to_local, LMat, Scalar, EULER};

    /// The Euler-parameter Hessian equals the full one on its entries to 1e-12 of the largest
    /// (the dot rows summed before their product), the full one is zero elsewhere, and each row's Hessian so formed matches central differences of the
    /// row's gradient.
    #[test]
    fn euler_hessian_is_the_full_one_restricted() {
        let mut seen = 0;
        for kind in every_kind() {
            let j = sample_joint(kind);
            if !euler_only(&j) {
                continue;
            }
            seen += 1;
            let rows = layout(&j).expect("closed form").len();
            for seed in 0..4 {
                let pair = sample_pair(seed);
                let w: Vec<f64> = (0..rows).map(|r| 0.7 - 0.45 * r as f64).collect();
                let mut full = LMat::zeros();
                let owned = OwnedRotations::of(&j, &pair);
                let rots = owned.view();
                super::super::add_weighted_hessian(&j, &pair, &rots, &w, &mut full);
                let mut hp = SMatrix::<f64, 8, 8>::zeros();
                add_weighted_hessian_euler(&j, &pair, &rots, &w, &mut hp);
                assert!(hp.amax() > 0.0, "{}", kind.name());
                // The general Hessian to rounding (the dot rows summed first), zero outside
                // the Euler parameters.
                let back = euler_to_local(&hp);
                let scale = full.amax();
                for (x, y) in full.iter().zip(back.iter()) {
                    assert!(
                        (x - y).abs() <= 1e-12 * scale,
                        "{} seed {seed}: {x} against {y}",
                        kind.name()
                    );
                }
                for (a, &i) in EULER.iter().enumerate() {
                    for (b, &k) in EULER.iter().enumerate() {
                        assert!((full[(i, k)] - hp[(a, b)]).abs() <= 1e-12 * scale);
                    }
                }
                // Each row against central differences of its closed-form gradient.
                for r in 0..rows {
                    let row = |q: &Pair| {
                        let mut out = Vec::new();
                        super::super::tests::rows(&j, q, &mut out);
                        let mut unit = vec![0.0; rows];
                        unit[r] = 1.0;
                        let mut hp = SMatrix::<f64, 8, 8>::zeros();
                        let owned = OwnedRotations::of(&j, q);
                        let rots = owned.view();
                        add_weighted_hessian_euler(&j, q, &rots, &unit, &mut hp);
                        Scalar {
                            h: Some(Box::new(euler_to_local(&hp))),
                            ..out[r].clone()
                        }
                    };
                    check_scalar(&pair, &row, &format!("{} row {r}", kind.name()));
                }
            }
        }
        assert!(seen >= 3, "{seen}");
    }
}
