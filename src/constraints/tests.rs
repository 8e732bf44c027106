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
