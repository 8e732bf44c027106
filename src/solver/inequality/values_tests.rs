//! The rows of stops and contacts by value alone (`constraints::unilateral::values`, the
//! evaluation of `Φ` without its Jacobian) against the jets' values, bit for bit (here, above
//! the importer's layer, to read the model from URDF).

use crate::constraints::unilateral::{bodies, inequalities, rows, values};
use crate::constraints::unilateral::{Active, Anchor, Unilateral};
use crate::jet::pair_of;
use crate::kinematics::Branches;
use nalgebra::{DVector, Vector3};

/// The values-only rows (`values`) are the jets' values of `rows` bit for bit, and so is
/// `Φ` evaluated without the Jacobian: stops on both sides, sliding and sticking contacts,
/// on a ground and on an obstacle, at configurations off the manifold.
#[test]
fn values_only_rows_equal_the_jets_values_bit_for_bit() {
    let text = r#"<robot name="v" xmlns:mech="urn:urdf-mech:1">
  <link name="world"/>
  <link name="table"><collision><origin xyz="0.4 0 -0.2"/><geometry><box size="0.5 0.5 0.1"/></geometry></collision></link>
  <joint name="fix" type="fixed"><parent link="world"/><child link="table"/></joint>
  <link name="a"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial><collision><origin xyz="0.3 0 0"/><geometry><sphere radius="0.05"/></geometry></collision></link>
  <link name="b"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial><collision><origin xyz="0.3 0.1 0"/><geometry><box size="0.1 0.2 0.05"/></geometry></collision></link>
  <joint name="j0" type="revolute"><parent link="world"/><child link="a"/><origin xyz="0 0 0.5"/><axis xyz="0 1 0"/><limit lower="-0.7" upper="1.1" effort="1" velocity="1"/></joint>
  <joint name="j1" type="prismatic"><parent link="a"/><child link="b"/><origin xyz="0.3 0 0"/><axis xyz="1 0 0"/><limit lower="-0.2" upper="0.3" effort="1" velocity="1"/></joint>
  <mech:ground normal="0.1 0.2 1"/>
  <mech:obstacle link="table"/>
  <mech:contact link="a"/>
  <mech:contact link="b" friction="stick"/>
</robot>"#;
    let model = crate::urdf::load_str(text, "v.urdf", &crate::urdf::ImportOptions::default())
        .unwrap()
        .model;
    let q0 = crate::State::initial(&model).q;
    // Every inequality active; the contacts of `b` (sticking) held at an anchor.
    let active: Vec<Active> = inequalities(&model, true)
        .into_iter()
        .map(|u| {
            let anchor = match u {
                Unilateral::Contact { point, .. } if model.contact_points[point].link == "b" => {
                    Some(Anchor {
                        world: Vector3::new(0.5, 0.1 * point as f64, 0.01),
                        body: model.contact_points[point].point,
                    })
                }
                _ => None,
            };
            Active { row: u, anchor }
        })
        .collect();
    assert!(active.iter().any(|a| a.anchor.is_some()));
    assert!(active
        .iter()
        .any(|a| matches!(a.row, Unilateral::Limit { .. })));
    assert!(active
        .iter()
        .any(|a| matches!(a.row, Unilateral::Contact { ground, .. } if ground > 0)));
    let cons = crate::constraints::Constraints::new(&model, &[]).with_active(&model, &active);
    let branches = Branches::default();
    for seed in 0..20u64 {
        let mut q = q0.clone();
        for (i, x) in q.iter_mut().enumerate() {
            let h = (seed * 131 + i as u64 * 7919) % 1000;
            *x += 0.3 * (h as f64 / 1000.0 - 0.5);
        }
        for a in &active {
            let pair = pair_of(&bodies(&model, &a.row), &q, false);
            let jets = rows(&model, a, &pair, &branches).unwrap();
            let mut out = [f64::NAN; 3];
            let k = values(&model, a, &pair, &branches, &mut out).unwrap();
            assert_eq!(k, jets.len());
            for (v, s) in out.iter().zip(&jets) {
                assert_eq!(v.to_bits(), s.v.to_bits(), "{a:?} at seed {seed}");
            }
        }
        let (mut alone, mut with) = (DVector::zeros(cons.len()), DVector::zeros(cons.len()));
        let mut jac = crate::constraints::Triplets::default();
        cons.evaluate(&model, &q, &mut alone, None);
        cons.evaluate(&model, &q, &mut with, Some(&mut jac));
        for (x, y) in alone.iter().zip(with.iter()) {
            assert_eq!(x.to_bits(), y.to_bits());
        }
    }
}
