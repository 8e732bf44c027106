//! Tests of the rows of stops and contacts: derivatives against finite differences (the
//! values-only path against the jets' values: `solver::inequality::values_tests`).
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
