//! Tests of the rows of stops and contacts: derivatives against finite differences, the
//! values-only path against the jets' values.
use super::*;
use crate::jet::testing::{check_scalar, sample_pair};
use crate::model::{ContactPoint, ContactSettings, Ground, ModelBuilder};
use nalgebra::Matrix3;

/// The gap and tangential rows of a contact match finite differences (gradient and
/// Hessian).
#[test]
fn contact_rows_match_finite_differences() {
    let mut b = ModelBuilder::new("t");
    let body = b.add_rigid_body("b", 1.0, Vector3::zeros(), Matrix3::identity());
    b.add_ground(
        "g",
        Vector3::new(0.1, -0.2, 0.3),
        Vector3::new(0.2, 0.3, 1.0),
    )
    .unwrap();
    let mut m = b.build().unwrap();
    m.contact_points.push(ContactPoint {
        link: "b".into(),
        body,
        point: Vector3::new(0.3, -0.1, 0.2),
        radius: 0.05,
        settings: ContactSettings::default(),
    });
    let _ = Ground::default();
    let a = Active {
        row: Unilateral::Contact {
            point: 0,
            ground: 0,
        },
        anchor: Some(Anchor {
            world: Vector3::new(0.5, 0.4, -0.1),
            body: Vector3::new(0.2, -0.3, 0.1),
        }),
    };
    for k in 0..3 {
        check_scalar(
            &sample_pair(7),
            &|p: &Pair| rows(&m, &a, p, &Branches::default()).unwrap()[k].clone(),
            "contact row",
        );
    }
}

/// Against an obstacle the gap row's value equals the gap, its gradient equals central
/// differences of the gap and its Hessian (with the surface's curvature, module
/// `model::curvature`) central differences of the gradient (a box's face and edge, a
/// sphere, a cylinder's side).
#[test]
fn obstacle_gap_rows_match_finite_differences() {
    use crate::geometry::ShapeKind;
    use crate::model::Obstacle;
    for (shape, at) in [
        (
            ShapeKind::Box {
                size: Vector3::new(1.0, 0.8, 0.6),
            },
            Vector3::new(0.1, 0.0, 0.9),
        ),
        (
            ShapeKind::Box {
                size: Vector3::new(1.0, 0.8, 0.6),
            },
            Vector3::new(0.9, 0.0, 0.9),
        ),
        (
            ShapeKind::Sphere { radius: 0.4 },
            Vector3::new(0.3, 0.2, 0.9),
        ),
        (
            ShapeKind::Cylinder {
                radius: 0.3,
                length: 2.0,
            },
            Vector3::new(0.3, 0.2, 0.1),
        ),
    ] {
        let mut b = ModelBuilder::new("t");
        let body = b.add_rigid_body("b", 1.0, Vector3::zeros(), Matrix3::identity());
        let mut m = b.build().unwrap();
        m.obstacles.push(Obstacle {
            link: "o".into(),
            world_from_shape: nalgebra::Isometry3::rotation(Vector3::new(0.1, -0.2, 0.05)),
            shape,
            hull: None,
        });
        m.contact_points.push(ContactPoint {
            link: "b".into(),
            body,
            point: Vector3::new(0.05, -0.02, 0.03),
            radius: 0.05,
            settings: ContactSettings::default(),
        });
        let a = Active {
            row: Unilateral::Contact {
                point: 0,
                ground: 0,
            },
            anchor: None,
        };
        let tilt = nalgebra::UnitQuaternion::from_scaled_axis(Vector3::new(0.2, 0.1, -0.3));
        let q = DVector::from_vec(vec![at.x, at.y, at.z, tilt.w, tilt.i, tilt.j, tilt.k]);
        let pair = pair_of(&[Some(body), None], &q, false);
        let row = rows(&m, &a, &pair, &Branches::default()).unwrap()[0].clone();
        let g = gap(&m, &a.row, &q, &Branches::default()).unwrap();
        assert!((row.v - g).abs() < 1e-14, "{} {g}", row.v);
        for i in 0..7 {
            let h = 1e-6;
            let (mut up, mut down) = (q.clone(), q.clone());
            up[i] += h;
            down[i] -= h;
            let fd = (gap(&m, &a.row, &up, &Branches::default()).unwrap()
                - gap(&m, &a.row, &down, &Branches::default()).unwrap())
                / (2.0 * h);
            assert!(
                (row.g[i] - fd).abs() < 1e-8,
                "coordinate {i}: {} vs {fd}",
                row.g[i]
            );
        }
        let with_hessian = pair_of(&[Some(body), None], &q, true);
        let row = rows(&m, &a, &with_hessian, &Branches::default()).unwrap()[0].clone();
        let hess = row.h.expect("asked for");
        let grad = |q: &DVector<f64>| {
            rows(
                &m,
                &a,
                &pair_of(&[Some(body), None], q, false),
                &Branches::default(),
            )
            .unwrap()[0]
                .g
        };
        for i in 0..7 {
            let h = 1e-6;
            let (mut up, mut down) = (q.clone(), q.clone());
            up[i] += h;
            down[i] -= h;
            let fd = (grad(&up) - grad(&down)) / (2.0 * h);
            for j in 0..7 {
                assert!(
                    (hess[(j, i)] - fd[j]).abs() < 1e-7,
                    "{:?} H[{j},{i}]: {} vs {}",
                    m.obstacles[0].shape,
                    hess[(j, i)],
                    fd[j]
                );
            }
        }
    }
}

/// The values-only rows ([`values`]) are the jets' values of [`rows`] bit for bit, and so is
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
