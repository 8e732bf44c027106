//! Property tests over randomly generated mechanisms (proptest).
//!
//! Chains and trees with random joint axes, offsets, masses and joint springs, and random
//! planar four-bar loops. For each: the answer satisfies the constraints, its projected
//! gradient vanishes, `verify` passes it and fails a perturbation of it. Invariances: rotating
//! the mechanism together with gravity, and expressing it in millimetres, leave the joint
//! angles unchanged; the same input gives byte-identical JSON (apart from `diagnostics.timings`). 24 cases per property here
//! (`PROPTEST_CASES` raises it).
use crate::common::builders::{four_bar, hinge, linear};
use nalgebra::{Isometry3, Matrix3, Translation3, Unit, UnitQuaternion, Vector3};
use proptest::prelude::*;
use restpose::export::json::AnalysisResult;
use restpose::model::{JointKind, ModelBuilder};
use restpose::verify::{pose_state, verify, Tolerances};
use restpose::{Model, Options};

#[derive(Clone, Debug)]
struct Link {
    parent: usize, // 0 = world, i = link i−1
    offset: [f64; 3],
    axis: [f64; 3],
    com: [f64; 3],
    mass: f64,
    stiffness: f64,
}

fn link() -> impl Strategy<Value = Link> {
    (
        prop::array::uniform3(-0.3..0.3f64),
        prop::array::uniform3(-1.0..1.0f64),
        prop::array::uniform3(-0.2..0.2f64),
        0.2..3.0f64,
        0.0..1.0f64,
    )
        .prop_filter("axis not degenerate", |(_, a, ..)| {
            a.iter().map(|x| x * x).sum::<f64>() > 0.1
        })
        .prop_map(|(offset, axis, com, mass, s)| Link {
            parent: 0,
            offset,
            axis,
            com,
            mass,
            stiffness: s,
        })
}

/// A tree of 1–5 links; each joint spring is stiff compared with the weight it carries.
fn tree() -> impl Strategy<Value = Vec<Link>> {
    prop::collection::vec((link(), 0..100usize), 1..6).prop_map(|v| {
        v.into_iter()
            .enumerate()
            .map(|(i, (mut l, p))| {
                l.parent = if i == 0 { 0 } else { p % (i + 1) };
                l
            })
            .collect()
    })
}

/// A tree built in code; lengths × `scale`, gravity `gravity`, the whole tree turned about the
/// world origin by `rpy` (root joint origins rotated, root joint frames turned).
fn tree_model(links: &[Link], scale: f64, gravity: [f64; 3], rpy: [f64; 3]) -> Model {
    let n = links.len() as f64;
    let v = |a: [f64; 3], s: f64| Vector3::new(a[0] * s, a[1] * s, a[2] * s);
    let mut b = ModelBuilder::new("tree");
    let mut bodies = Vec::new();
    for (i, l) in links.iter().enumerate() {
        let body = b.add_rigid_body(
            format!("l{i}"),
            l.mass,
            v(l.com, scale),
            Matrix3::identity(),
        );
        let (parent, origin) = if l.parent == 0 {
            let r = UnitQuaternion::from_euler_angles(rpy[0], rpy[1], rpy[2]);
            let at = Translation3::from(r * v(l.offset, scale));
            (None, Isometry3::from_parts(at, r))
        } else {
            let at = Translation3::from(v(l.offset, scale));
            (
                Some(bodies[l.parent - 1]),
                Isometry3::from_parts(at, UnitQuaternion::identity()),
            )
        };
        let axis = Unit::new_normalize(v(l.axis, 1.0));
        let j = hinge(
            &mut b,
            &format!("j{i}"),
            JointKind::Continuous,
            parent,
            origin,
            axis,
            body,
        );
        // Torque scale: total weight × 0.5 m × links; units follow the length scale squared.
        let k = (20.0 + 80.0 * l.stiffness) * n * 9.81 * scale * scale;
        b.add_joint_spring(j, 0, linear(k), 0.0);
        bodies.push(body);
    }
    b.set_gravity(v(gravity, scale));
    b.build().unwrap()
}

fn angles(m: &Model, s: &restpose::State) -> Vec<f64> {
    s.joint_values(m).into_iter().map(|(_, v)| v[0]).collect()
}

/// 24 cases per property, or `PROPTEST_CASES`.
fn cases() -> u32 {
    std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(24)
}

fn check_rest(m: &Model, s: &restpose::State) {
    let v = verify(m, s, &Tolerances::default()).unwrap();
    assert!(v.constraint_residual < 1e-10, "{v:?}");
    assert!(v.projected_gradient < 1e-6, "{v:?}");
    assert!(v.passed, "{v:?}");
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(cases()))]

    #[test]
    fn random_trees_rest_verify_and_perturbations_fail(links in tree(), which in 0..100usize, sign in prop::bool::ANY) {
        let m = tree_model(&links, 1.0, [0.0, 0.0, -9.81], [0.0; 3]);
        let (s, r) = restpose::solve(&m, &Options::default()).unwrap();
        prop_assert!(r.converged(), "{:?}", r.termination);
        check_rest(&m, &s);
        let k = which % links.len();
        let mut values: restpose::state::JointValues = s.joint_values(&m).into_iter().collect();
        values.get_mut(&format!("j{k}")).unwrap()[0] += if sign { 0.02 } else { -0.02 };
        let (p, _) = pose_state(&m, &values).unwrap();
        let v = verify(&m, &p, &Tolerances::default()).unwrap();
        prop_assert!(!v.passed);
        let e = v.imbalance.iter().find(|i| i.joint == format!("j{k}")).unwrap();
        prop_assert!(e.effort.abs() > 1e-6, "perturbed joint j{} effort {}", k, e.effort);
    }

    #[test]
    fn rotating_mechanism_and_gravity_together_changes_nothing(links in tree(), rpy in prop::array::uniform3(-1.5..1.5f64)) {
        let g = nalgebra::Vector3::new(0.0, 0.0, -9.81);
        let rot = nalgebra::UnitQuaternion::from_euler_angles(rpy[0], rpy[1], rpy[2]);
        let gr = rot * g;
        let m1 = tree_model(&links, 1.0, [g.x, g.y, g.z], [0.0; 3]);
        let m2 = tree_model(&links, 1.0, [gr.x, gr.y, gr.z], rpy);
        let (s1, r1) = restpose::solve(&m1, &Options::default()).unwrap();
        let (s2, r2) = restpose::solve(&m2, &Options::default()).unwrap();
        prop_assert!(r1.converged() && r2.converged());
        for (a, b) in angles(&m1, &s1).iter().zip(angles(&m2, &s2)) {
            prop_assert!((a - b).abs() < 1e-7, "{} vs {}", a, b);
        }
        prop_assert!((r1.energy.total - r2.energy.total).abs() < 1e-7 * (1.0 + r1.energy.total.abs()));
    }

    #[test]
    fn millimetres_give_the_same_angles(links in tree()) {
        let m1 = tree_model(&links, 1.0, [0.0, 0.0, -9.81], [0.0; 3]);
        let m2 = tree_model(&links, 1000.0, [0.0, 0.0, -9.81], [0.0; 3]);
        let (s1, r1) = restpose::solve(&m1, &Options::default()).unwrap();
        // Energies are 10⁶ times larger in kg mm² / s²: the gradient tolerance scales with them.
        let opts = Options { gradient_tolerance: 1e-2, ..Options::default() };
        let (s2, r2) = restpose::solve(&m2, &opts).unwrap();
        prop_assert!(r1.converged() && r2.converged(), "{:?} {:?}", r1.termination, r2.termination);
        for (a, b) in angles(&m1, &s1).iter().zip(angles(&m2, &s2)) {
            prop_assert!((a - b).abs() < 1e-7, "{} vs {}", a, b);
        }
        prop_assert_eq!(r1.independent_coordinates, r2.independent_coordinates);
    }

    #[test]
    fn random_four_bars_rest_and_are_deterministic(
        a in 0.15..0.35f64, b in 0.9..1.2f64, c in 0.5..0.9f64, t in 0.3..2.5f64,
        masses in prop::array::uniform3(0.2..2.0f64), k in 5.0..50.0f64,
    ) {
        let Some((m, _)) = four_bar([a, b, c], t, masses, k) else { return Ok(()) };
        let m = m.build().unwrap();
        let (s, mut r) = restpose::solve(&m, &Options::default()).unwrap();
        prop_assert!(r.converged(), "{:?}", r.termination);
        prop_assert_eq!(r.dof, 1);
        prop_assert_eq!(r.redundant_constraints.len(), 3);
        check_rest(&m, &s);
        // Identical apart from the wall times of `diagnostics.timings`.
        r.diagnostics.timings = Default::default();
        let j1 = AnalysisResult::new(&m, &s, &r).to_json();
        let (s2, mut r2) = restpose::solve(&m, &Options::default()).unwrap();
        r2.diagnostics.timings = Default::default();
        prop_assert_eq!(j1, AnalysisResult::new(&m, &s2, &r2).to_json());
    }
}
