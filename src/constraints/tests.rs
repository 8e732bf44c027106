//! The constraint rows' bookkeeping: names and kinds of rows made from the blocks.

use super::unilateral::{Active, Bound, Unilateral};
use super::*;

/// Row names are made on demand from the blocks: every kind of row, with the names the
/// rows were given when they were stored (`joint.row`, `body.normalization`, …).
#[test]
fn row_names_follow_the_blocks() {
    use crate::model::{JointKind, Mimic, ModelBuilder};
    use nalgebra::{Isometry3, Matrix3, Vector3};
    let mut b = ModelBuilder::new("r");
    let inertia = Matrix3::identity();
    let a = b.add_rigid_body("a", 1.0, Vector3::zeros(), inertia);
    let c = b.add_rigid_body("b", 1.0, Vector3::zeros(), inertia);
    let f = Isometry3::identity();
    let j1 = b.add_joint("j1", JointKind::Revolute, None, f, Some(a), f);
    let j2 = b.add_joint("j2", JointKind::Revolute, Some(a), f, Some(c), f);
    b.set_limits(j1, -1.0, 1.0);
    b.add_mimic(Mimic {
        joint: j2,
        reference: j1,
        multiplier: 2.0,
        offset: 0.0,
    });
    let model = b.build().unwrap();
    let active = Active {
        row: Unilateral::Limit {
            joint: j1,
            bound: Bound::Lower,
            value: -1.0,
        },
        anchor: None,
    };
    let cons = Constraints::new(&model, &[(j1, 0, 0.5)]).with_active(&model, &[active]);
    let names: Vec<String> = (0..cons.len()).map(|i| cons.row_name(&model, i)).collect();
    let expected = [
        "j1.pos_x",
        "j1.pos_y",
        "j1.pos_z",
        "j1.axis_x",
        "j1.axis_y",
        "j2.pos_x",
        "j2.pos_y",
        "j2.pos_z",
        "j2.axis_x",
        "j2.axis_y",
        "a.normalization",
        "b.normalization",
        "j1.lock[0]",
        "j2.mimic",
        "j1.lower_limit",
    ];
    assert_eq!(names, expected);
    let normalization: Vec<usize> = (0..cons.len())
        .filter(|&i| cons.is_normalization(i))
        .collect();
    assert_eq!(normalization, [10, 11]);
}

/// `Φ` and `Φ_q` of the closed forms (joint rows by `closed_rows`, revolute lock rows by
/// `kinematics::revolute_first_order`) equal the generic jets' to rounding, with the same
/// triplet positions, at a bent pose off the unit sphere; `Φ` alone is the same.
#[test]
fn closed_forms_equal_the_jets_in_evaluate() {
    use crate::model::{JointKind, ModelBuilder};
    use nalgebra::{Isometry3, Matrix3, Translation3, UnitQuaternion, Vector3};
    let mut b = ModelBuilder::new("r");
    let inertia = Matrix3::identity();
    let a = b.add_rigid_body("a", 1.0, Vector3::zeros(), inertia);
    let c = b.add_rigid_body("b", 1.0, Vector3::zeros(), inertia);
    let f = Isometry3::from_parts(
        Translation3::new(0.1, -0.2, 0.3),
        UnitQuaternion::from_euler_angles(0.4, -0.3, 0.2),
    );
    let j1 = b.add_joint("j1", JointKind::Revolute, None, f, Some(a), f.inverse());
    let j2 = b.add_joint("j2", JointKind::Continuous, Some(a), f, Some(c), f);
    let model = b.build().unwrap();
    let mut closed = Constraints::new(&model, &[(j1, 0, 0.5), (j2, 0, -2.0)]);
    let mut lcg = crate::lcg::Lcg::new(5);
    let q = DVector::from_fn(14, |i, _| {
        let x = lcg.signed();
        if i % 7 == 3 {
            0.9 + 0.1 * x
        } else {
            0.4 * x
        }
    });
    let mut generic = closed.clone();
    generic.closed_form = false;
    let eval = |cons: &Constraints, jac: bool| {
        let mut phi = DVector::zeros(cons.len());
        let mut t = Triplets::default();
        cons.evaluate(&model, &q, &mut phi, jac.then_some(&mut t));
        (phi, t.entries)
    };
    for branch in [0.0, 7.0] {
        closed.branches.set(j1, 0, branch);
        generic.branches.set(j1, 0, branch);
        let ((p0, t0), (p1, t1)) = (eval(&closed, true), eval(&generic, true));
        assert!((&p0 - &p1).amax() <= 1e-15, "{p0} {p1}");
        assert_eq!(eval(&closed, false).0, p0);
        assert_eq!(t0.len(), t1.len());
        for (x, y) in t0.iter().zip(&t1) {
            assert_eq!((x.0, x.1), (y.0, y.1));
            assert!(
                (x.2 - y.2).abs() <= 1e-14 * (1.0 + y.2.abs()),
                "{x:?} {y:?}"
            );
        }
    }
}
