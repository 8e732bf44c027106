//! The weighted Hessian `Σ_r w_r ∇²Φ_r` of a joint whose rows are all components of
//! `d = o₁ − o₀` or dot products of two axes (a revolute, a universal, a spherical, a fixed
//! joint...), over the 8 Euler parameters of its pair only.
//!
//! Such a Hessian is zero outside the `p_k p_l` blocks (module docs of `jet::closed`): a
//! component `wᵀd` adds `C(d, w) = 2 M(±s_k, w)` on the `p_k p_k` blocks, a dot product of two
//! axes `aᵀb` adds `B^a_kᵀ B^b_l` (and its transpose) and the curvatures `2 M(s^a_k, b)`,
//! `2 M(s^b_l, a)`. Only the axes the rows read are formed (their `A(p_k) s`, `B(p_k, s)`);
//! `d` enters by its body-frame offsets `s` alone (its curvature does not depend on `p`'s
//! value), so its factors are not formed. The entries are those of
//! [`super::add_weighted_hessian`] restricted to [`crate::jet::EULER`], added in the same
//! order from the same operands: the same numbers to the last bit.

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
    // The axes the rows read, each formed once in place as `Frames::of` forms it.
    let mut need = [false; 7];
    for (row, &c) in layout.iter().zip(w) {
        if let (Row::Dot(a, b), true) = (*row, c != 0.0) {
            need[a as usize] = true;
            need[b as usize] = true;
        }
    }
    let mut axes: [Option<Lin>; 7] = [None; 7];
    for (v, slot) in axes.iter_mut().enumerate().skip(1) {
        if need[v] {
            let (k, i) = ((v - 1) / 3, (v - 1) % 3);
            let axis = rots.r[k].column(i).into_owned();
            slot.insert(Lin::ZERO).set_vector(pair, rots.a[k], k, &axis);
        }
    }
    let mut wd = Vector3::zeros();
    for (row, &c) in layout.iter().zip(w) {
        if c == 0.0 {
            continue;
        }
        match *row {
            Row::Component(m) => wd[m] += c,
            Row::Dot(a, b) => {
                if let (Some(a), Some(b)) = (&axes[a as usize], &axes[b as usize]) {
                    dot_hessian_euler(a, b, c, hp);
                }
            }
            Row::Length | Row::Thread => unreachable!("not euler_only"),
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

    /// The Euler-parameter Hessian equals the full one bit for bit on its entries, the full one
    /// is zero elsewhere, and each row's Hessian so formed matches central differences of the
    /// row's gradient.
    #[test]
    fn euler_hessian_is_the_full_one_restricted_bit_for_bit() {
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
                let back = euler_to_local(&hp);
                for (x, y) in full.iter().zip(back.iter()) {
                    assert_eq!(x.to_bits(), y.to_bits(), "{} seed {seed}", kind.name());
                }
                for (a, &i) in EULER.iter().enumerate() {
                    for (b, &k) in EULER.iter().enumerate() {
                        assert_eq!(full[(i, k)].to_bits(), hp[(a, b)].to_bits());
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
