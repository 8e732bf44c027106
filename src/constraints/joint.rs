//! Joint constraint equations, evaluated as second-order jets from the rows each kind's file
//! lists ([`crate::joint::Spec::rows`], Haug 1989, Nikravesh 1988):
//!
//! - spherical: `d = r_j + A_j s_j − r_i − A_i s_i = 0` (3 rows);
//! - dot-1: `a_iᵀ b_j = 0` for body vectors `a_i = A_i a'`, `b_j = A_j b'`;
//! - dot-2: `a_iᵀ d = 0`;
//! - length `dᵀd − L²`, thread `d·z_i − h θ`.
//!
//! These generic jets are the reference the closed forms of [`crate::jet::closed`] are tested
//! against, and evaluate the rows without a closed form (a screw's thread). Joint frames and
//! coordinates come from [`crate::kinematics`].
//!
//! ## References
//! - E. J. Haug, *Computer-Aided Kinematics and Dynamics of Mechanical Systems* (1989), ch. 3.

use crate::jet::{Pair, Scalar, Vec3Jet};
use crate::joint::{Row, V};
use crate::kinematics::{angle, frames, on_branch, vector};
use crate::model::Joint;
use nalgebra::Vector3;

fn component(pair: &Pair, d: &Vec3Jet, k: usize) -> Scalar {
    let mut e = Vector3::zeros();
    e[k] = 1.0;
    let mut g = crate::jet::LVec::zeros();
    for i in 0..crate::jet::NL {
        g[i] = d.j[(k, i)];
    }
    let h = pair.hess.then(|| Box::new(d.contract(&e)));
    Scalar { v: d.v[k], g, h }
}

/// Number of constraint rows of a joint (0 for merged and floating joints).
pub(crate) fn row_count(joint: &Joint) -> usize {
    if joint.merged {
        return 0;
    }
    joint.kind.spec().rows.len()
}

/// Names of the constraint rows of a joint, in row order.
pub(crate) fn row_names(joint: &Joint) -> &'static [&'static str] {
    if joint.merged {
        return &[];
    }
    joint.kind.spec().row_names
}

/// Power of length in the unit of a joint row named `name` (`pos_x` is in m, `length` in m²,
/// dot products of unit vectors are dimensionless).
pub(crate) fn length_power(name: &str) -> i32 {
    if name.starts_with("pos")
        || name.starts_with("slide")
        || name.starts_with("line")
        || name == "plane"
        || name == "thread"
    {
        1
    } else if name == "length" {
        2
    } else {
        0
    }
}

/// Evaluates the constraint rows of a joint into `out` (cleared first); a screw's thread row
/// reads its angle on the branch `reference` (see [`crate::kinematics::Branches`]), so that a
/// screw advances over many turns.
pub(crate) fn rows(joint: &Joint, pair: &Pair, reference: f64, out: &mut Vec<Scalar>) {
    out.clear();
    let layout = joint.kind.spec().rows;
    if joint.merged || layout.is_empty() {
        return;
    }
    let f = frames(joint, pair);
    for row in layout {
        out.push(match *row {
            Row::Component(k) => component(pair, &f.d, k),
            Row::Dot(a, b) => pair.dot(vector(&f, a), vector(&f, b)),
            Row::Length => {
                let length = joint.kind.parameter();
                pair.dot(&f.d, &f.d).minus(length * length)
            }
            Row::Thread => {
                let t = on_branch(angle(pair, &f), reference).scale(-joint.kind.parameter());
                pair.dot(vector(&f, V::Z0), &f.d).add(&t)
            }
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::jet::closed;
    use crate::jet::closed::tests::assert_same;
    use crate::jet::hess_or_zero;
    use crate::jet::testing::{check_scalar, sample_pair};
    use crate::model::{BodyId, JointKind};
    use nalgebra::{Isometry3, Translation3, UnitQuaternion};

    fn joint(kind: JointKind) -> Joint {
        let f0 = Isometry3::from_parts(
            Translation3::new(0.1, 0.2, -0.3),
            UnitQuaternion::from_euler_angles(0.3, -0.2, 0.9),
        );
        let f1 = Isometry3::from_parts(
            Translation3::new(-0.2, 0.05, 0.4),
            UnitQuaternion::from_euler_angles(-0.5, 0.4, 0.1),
        );
        Joint {
            name: "j".into(),
            kind,
            parent_link: "a".into(),
            child_link: "b".into(),
            bodies: [Some(BodyId(0)), Some(BodyId(1))],
            body_from_joint: [f0, f1],
            tree: false,
            merged: false,
            limits: None,
            effort_limit: None,
            source: None,
        }
    }

    const KINDS: [JointKind; 11] = [
        JointKind::Revolute,
        JointKind::Continuous,
        JointKind::Prismatic,
        JointKind::Fixed,
        JointKind::Planar,
        JointKind::Spherical,
        JointKind::Universal,
        JointKind::Cylindrical,
        JointKind::Screw { pitch: 0.01 },
        JointKind::Distance { length: 0.7 },
        JointKind::PointOnLine,
    ];

    /// One closed-form row as a scalar: value and gradient from [`closed::rows`], Hessian from
    /// [`closed::add_weighted_hessian`] with the unit weight on row `r`.
    fn closed_row(j: &Joint, pair: &Pair, r: usize) -> Scalar {
        let mut out = Vec::new();
        closed::rows(j, pair, &mut out);
        let mut w = vec![0.0; out.len()];
        w[r] = 1.0;
        let mut h = Box::new(crate::jet::LMat::zeros());
        closed::add_weighted_hessian(j, pair, &w, &mut h);
        let mut values = Vec::new();
        closed::values(j, pair, &mut values);
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
        for kind in KINDS {
            let j = joint(kind);
            if !closed::supports(&j) {
                assert!(matches!(kind, JointKind::Screw { .. }));
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
                closed::add_weighted_hessian(&j, &pair, &w, &mut got);
                let d = (got - expected).amax();
                assert!(d <= 1e-12 * (1.0 + expected.amax()), "{}: {d}", kind.name());
            }
        }
    }

    #[test]
    fn every_row_jacobian_and_hessian_match_finite_differences() {
        for kind in KINDS {
            let j = joint(kind);
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
}
