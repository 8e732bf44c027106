//! `Constraints::add_hessian` over the rows of active stops: a stop weighted 0 (a redundant
//! stop's `μ = 0`) is neither evaluated nor summed, the same bits as without it.
use crate::constraints::unilateral::{Active, Bound, Unilateral};
use crate::constraints::Constraints;
use crate::model::JointId;
use crate::urdf::{load_str, ImportOptions};
use nalgebra::DVector;

/// `add_hessian` skips a stop whose row is weighted 0 (a redundant stop's `μ = 0`): the
/// sum is the same bits as without that stop among the rows, and a stop weighted other
/// than 0 is not skipped (its Hessian changes the sum).
#[test]
fn a_stop_weighted_zero_adds_nothing_to_the_hessian() {
    let link = r#"<inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>"#;
    let text = format!(
        r#"<robot name="r"><link name="world"/><link name="a">{link}</link><link name="b">{link}</link>
<joint name="j1" type="revolute"><parent link="world"/><child link="a"/><axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
<joint name="j2" type="revolute"><parent link="a"/><child link="b"/><origin xyz="0.3 0 0" rpy="0.2 0.1 0"/><axis xyz="0 0.6 0.8"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>"#
    );
    let model = load_str(&text, "r.urdf", &ImportOptions::default())
        .unwrap()
        .model;
    let mut q = crate::solver::initial_state(&model).q;
    // Away from the identity, so that the stops' angle Hessians are not zero.
    for (k, x) in q.iter_mut().enumerate() {
        *x += 0.05 * ((k * 7 % 11) as f64 - 5.0) / 5.0;
    }
    let stop = |j: usize, bound| Active {
        row: Unilateral::Limit {
            joint: JointId(j),
            bound,
            value: -1.0,
        },
        anchor: None,
    };
    let (a, b) = (stop(0, Bound::Lower), stop(1, Bound::Lower));
    let both = Constraints::new(&model, &[]).with_active(&model, &[a, b]);
    let only_b = Constraints::new(&model, &[]).with_active(&model, &[b]);
    assert_eq!(both.len(), only_b.len() + 1);
    let n = model.coordinate_count();
    let hessian = |cons: &Constraints, w: &DVector<f64>| {
        let mut h = nalgebra::DMatrix::zeros(n, n);
        cons.add_hessian(&model, &q, w, &mut h);
        h
    };
    // Weights on every row; stop `a`'s row (the first unilateral one) 0 or not.
    let first = both.len() - 2;
    let weight = |i: usize| 0.3 + 0.1 * (i % 5) as f64;
    let mut w = DVector::from_fn(both.len(), |i, _| weight(i));
    w[first] = 0.0;
    let w_b = DVector::from_fn(only_b.len(), |i, _| if i < first { w[i] } else { w[i + 1] });
    let skipped = hessian(&both, &w);
    assert_eq!(skipped, hessian(&only_b, &w_b));
    w[first] = 0.7;
    assert_ne!(hessian(&both, &w), skipped);
}
