//! Every joint kind of the table ([`crate::joint::KINDS`]): its rows against the generic jets,
//! the closed forms and central differences, its coordinates against central differences,
//! and its motion against its rows and coordinates.

use super::*;
use crate::jet::closed;
use crate::jet::closed::tests::assert_same;
use crate::jet::hess_or_zero;
use crate::jet::testing::{check_scalar, every_kind, sample_joint, sample_pair};
use crate::model::JointKind;
use nalgebra::{Isometry3, Translation3, UnitQuaternion};

/// One closed-form row as a scalar: value and gradient from `closed::tests::rows`, Hessian from
/// [`closed::add_weighted_hessian`] with the unit weight on row `r`.
fn closed_row(j: &Joint, pair: &Pair, r: usize) -> Scalar {
    let mut out = Vec::new();
    closed::tests::rows(j, pair, &mut out);
    let mut w = vec![0.0; out.len()];
    w[r] = 1.0;
    let mut h = Box::new(crate::jet::LMat::zeros());
    let owned = closed::OwnedRotations::of(j, pair);
    let rots = owned.view();
    closed::add_weighted_hessian(j, pair, &rots, &w, &mut h);
    let mut values = Vec::new();
    closed::values(j, pair, &rots, &mut values);
    assert_eq!(values[r], out[r].v);
    Scalar {
        h: Some(h),
        ..out[r].clone()
    }
}

/// The closed-form rows equal the generic jets (value, gradient, Hessian contracted with
/// multipliers) to rounding, and their derivatives match central differences.
#[test]
fn closed_form_rows_equal_the_jets_and_finite_differences() {
    for kind in every_kind() {
        let j = sample_joint(kind);
        if !closed::supports(&j) {
            assert!(!kind.spec().closed_form, "{}", kind.name());
            continue;
        }
        for seed in 0..4 {
            let pair = sample_pair(seed);
            let mut jets = Vec::new();
            rows(&j, &pair, 0.0, &mut jets);
            assert_eq!(jets.len(), row_count(&j));
            for r in 0..jets.len() {
                let what = format!("{} row {} seed {seed}", kind.name(), row_names(&j)[r]);
                assert_same(&jets[r], &closed_row(&j, &pair, r), &what);
                check_scalar(&pair, &|q| closed_row(&j, q, r), &what);
            }
            // Multipliers: Σ w_r ∇²Φ_r at once.
            let w: Vec<f64> = (0..jets.len()).map(|r| 0.7 - 0.45 * r as f64).collect();
            let mut expected = crate::jet::LMat::zeros();
            for (s, c) in jets.iter().zip(&w) {
                expected += hess_or_zero(&s.h) * *c;
            }
            let mut got = crate::jet::LMat::zeros();
            let owned = closed::OwnedRotations::of(&j, &pair);
            let rots = owned.view();
            closed::add_weighted_hessian(&j, &pair, &rots, &w, &mut got);
            let d = (got - expected).amax();
            assert!(d <= 1e-12 * (1.0 + expected.amax()), "{}: {d}", kind.name());
        }
    }
}

#[test]
fn every_row_jacobian_and_hessian_match_finite_differences() {
    for kind in every_kind() {
        let j = sample_joint(kind);
        for seed in 0..3 {
            let pair = sample_pair(seed);
            let mut out = Vec::new();
            rows(&j, &pair, 0.0, &mut out);
            assert_eq!(out.len(), row_count(&j));
            assert_eq!(row_names(&j).len(), row_count(&j));
            for r in 0..out.len() {
                check_scalar(
                    &pair,
                    &|q| {
                        let mut o = Vec::new();
                        rows(&j, q, 0.0, &mut o);
                        o[r].clone()
                    },
                    &format!("{} row {}", kind.name(), row_names(&j)[r]),
                );
            }
            for dof in 0..kind.scalar_coordinates() {
                check_scalar(
                    &pair,
                    &|q| crate::kinematics::coordinate(&j, q, dof, 0.0).unwrap(),
                    &format!("{} coordinate {dof}", kind.name()),
                );
            }
        }
    }
}

/// Values of a joint of `kind` to place it at: its scalar coordinates, or the longest value
/// list it takes (a unit quaternion for a spherical joint, a translation and one for a
/// floating joint).
fn sample_values(kind: JointKind) -> Vec<f64> {
    let n = kind.value_counts().iter().copied().max().unwrap_or(0);
    let q = nalgebra::Vector4::new(0.8, -0.3, 0.4, 0.2).normalize();
    let quat = [q[0], q[1], q[2], q[3]];
    match n {
        4 => quat.to_vec(),
        7 => [0.3, -0.2, 0.5].into_iter().chain(quat).collect(),
        n => [0.4, -0.7, 2.9][..n].to_vec(),
    }
}

/// Each kind's motion and its rows and coordinates agree: at the pose `motion(v)` places the
/// child at (from a parent at a general pose), every row is zero, in closed form too, each
/// scalar coordinate reads back its value of `v` (angles on the branch of `v`), a kind
/// without scalar coordinates reads back `v` from the relative motion, and the result JSON
/// takes as many values.
#[test]
fn motion_satisfies_the_rows_and_reads_back_its_values() {
    let parent = Isometry3::from_parts(
        Translation3::new(0.5, -0.1, 0.2),
        UnitQuaternion::from_euler_angles(0.7, 0.1, -0.4),
    );
    for kind in every_kind() {
        let j = sample_joint(kind);
        let v = sample_values(kind);
        let m = crate::kinematics::motion(kind, &v);
        let child = parent * j.body_from_joint[0] * m * j.body_from_joint[1].inverse();
        let mut q = nalgebra::DVector::zeros(14);
        for (k, pose) in [parent, child].iter().enumerate() {
            let (t, r) = (pose.translation.vector, pose.rotation);
            let coordinates = [t.x, t.y, t.z, r.w, r.i, r.j, r.k];
            q.rows_mut(7 * k, 7).copy_from_slice(&coordinates);
        }
        let pair = crate::jet::pair_of(&j.bodies, &q, false);
        let reference = v.first().copied().unwrap_or(0.0);
        let mut out = Vec::new();
        rows(&j, &pair, reference, &mut out);
        for (r, s) in out.iter().enumerate() {
            let what = format!("{} row {}", kind.name(), row_names(&j)[r]);
            assert!(s.v.abs() < 1e-12, "{what}: {}", s.v);
        }
        let mut values = Vec::new();
        closed::values(
            &j,
            &pair,
            &closed::OwnedRotations::of(&j, &pair).view(),
            &mut values,
        );
        assert!(values.iter().all(|x| x.abs() < 1e-12), "{}", kind.name());
        let n = kind.scalar_coordinates();
        for (dof, &expected) in v.iter().enumerate().take(n) {
            let read = crate::kinematics::coordinate(&j, &pair, dof, expected).unwrap();
            let what = format!("{} coordinate {dof}", kind.name());
            assert!((read.v - expected).abs() < 1e-12, "{what}: {}", read.v);
        }
        let read = if n > 0 {
            v[..n].to_vec()
        } else {
            let rel = (parent * j.body_from_joint[0]).inverse() * child * j.body_from_joint[1];
            (kind.spec().values_of_motion)(&rel)
        };
        assert_eq!(read.len(), kind.position_len(), "{}", kind.name());
        if !read.is_empty() {
            let d = read
                .iter()
                .zip(&v)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            assert!(d < 1e-12, "{}: {read:?} ≠ {v:?}", kind.name());
        }
    }
}

/// Each row's pattern ([`crate::joint::Row::pattern`]) holds its gradient's entries that are
/// not zero at every `q`: at random poses and frames, the entries left out are exactly zero in
/// closed form and in the generic jets (a pattern that left out a nonzero entry fails here),
/// and every entry kept is nonzero at some pose (none kept for nothing).
#[test]
fn row_patterns_leave_out_only_entries_zero_at_every_pose() {
    for kind in every_kind() {
        let j = sample_joint(kind);
        let layout = kind.spec().rows;
        let mut seen = vec![0u16; layout.len()];
        for seed in 0..8 {
            let pair = sample_pair(seed);
            let mut jets = Vec::new();
            rows(&j, &pair, 0.0, &mut jets);
            let mut closed_rows = Vec::new();
            closed::tests::rows(&j, &pair, &mut closed_rows);
            for (r, row) in layout.iter().enumerate() {
                let pattern = row.pattern();
                let what = |i| format!("{} row {} entry {i}", kind.name(), row_names(&j)[r]);
                for s in std::iter::once(&jets[r]).chain(closed_rows.get(r)) {
                    for i in 0..crate::jet::NL {
                        if pattern & (1 << i) == 0 {
                            assert_eq!(s.g[i], 0.0, "{} seed {seed}", what(i));
                        } else if s.g[i] != 0.0 {
                            seen[r] |= 1 << i;
                        }
                    }
                }
            }
        }
        for (r, row) in layout.iter().enumerate() {
            let name = row_names(&j)[r];
            assert_eq!(seen[r], row.pattern(), "{} row {name}", kind.name());
        }
    }
}
