//! The stop search's shortcut for stops out of reach ([`Reading::unreachable`]): on random
//! poses, tangents and step lengths, the list with the shortcut holds exactly the stops of the
//! full list (bit for bit: index, body, `α_k`) that the line search can read (`α_k < α_max`),
//! and the shortcut does skip stops; the probe's difference quotient never exceeds the bound.
use super::*;
use crate::constraints::Constraints;
use crate::solver::inequality::active_set::inequalities;
use crate::solver::options::Options;
use crate::solver::system::Backend;
use crate::state::State;
use crate::urdf::{load_str, ImportOptions};

/// A chain of `n` revolute links (axes alternating, as `generate::chain`) limited to `±limit`,
/// and a branch of three links with a prismatic joint off its second link.
fn limited_chain(n: usize, limit: f64) -> String {
    let mut s = String::from("<robot name=\"limited\">\n  <link name=\"world\"/>\n");
    let inertial = "<inertial><origin xyz=\"0.1 0 0\"/><mass value=\"1\"/><inertia ixx=\"1e-4\" ixy=\"0\" ixz=\"0\" iyy=\"3.4e-3\" iyz=\"0\" izz=\"3.4e-3\"/></inertial>";
    for i in 0..n + 3 {
        s += &format!("  <link name=\"link{i}\">{inertial}</link>\n");
    }
    let joint = |s: &mut String, i: usize, kind: &str, parent: String, axis: &str| {
        let x = if i == 0 { 0.0 } else { 0.2 };
        *s += &format!(
            "  <joint name=\"joint{i}\" type=\"{kind}\"><parent link=\"{parent}\"/><child link=\"link{i}\"/><origin xyz=\"{x} 0.01 0\" rpy=\"0.1 0 0\"/><axis xyz=\"{axis}\"/><limit lower=\"{}\" upper=\"{limit}\" effort=\"1\" velocity=\"1\"/></joint>\n",
            -limit
        );
    };
    for i in 0..n {
        let parent = if i == 0 {
            "world".to_string()
        } else {
            format!("link{}", i - 1)
        };
        joint(
            &mut s,
            i,
            "revolute",
            parent,
            if i % 2 == 0 { "0 1 0" } else { "0 0 1" },
        );
    }
    joint(&mut s, n, "revolute", "link1".into(), "1 0 0");
    joint(&mut s, n + 1, "prismatic", format!("link{n}"), "0 0 1");
    joint(&mut s, n + 2, "revolute", format!("link{}", n + 1), "0 1 1");
    s + "</robot>\n"
}

#[test]
fn skips_only_stops_the_line_search_cannot_read() {
    let options = Options::default();
    let mut lcg = crate::lcg::Lcg::new(11);
    let (mut kept, mut full) = (0, 0);
    for (n, limit, floating) in [(6, 1.2, false), (9, 3.0, true), (12, 0.4, false)] {
        let import = ImportOptions {
            floating_base: floating,
            ..ImportOptions::default()
        };
        let model = load_str(&limited_chain(n, limit), "limited.urdf", &import)
            .unwrap()
            .model;
        let all = inequalities(&model, &options);
        assert_eq!(all.len(), 2 * (n + 3));
        for _ in 0..12 {
            // Joint values anywhere within the stops (some within reach of a short step).
            let values = model
                .joints
                .iter()
                .filter(|j| j.limits.is_some())
                .map(|j| (j.name.clone(), vec![0.98 * limit * lcg.signed()]))
                .collect();
            let start = State::from_joint_values(&model, &values);
            let q = start.q;
            let cons = Constraints::new(&model, &[]).on_branches(start.branches);
            let mut sys = System::new(&model, cons, Backend::of(&model, &options));
            let part = sys.partition(&q);
            let eval = sys.evaluate(&q, &part).unwrap();
            let scale = 10f64.powf(2.0 * lcg.signed());
            let d = DVector::from_fn(part.independent.len(), |_, _| scale * lcg.signed());
            let dq = sys.tangent_step(&part, &eval, &d);
            let guard = Guard::new(&model, &options, all.clone(), &[], 1e-9, &q);
            let every = guard.stops(&sys, &q, &dq, f64::INFINITY);
            for alpha_max in [1e-3, 0.02, 0.3, 1.0, 4.0] {
                let reads = |s: &&Stop| s.alpha < alpha_max;
                let short = guard.stops(&sys, &q, &dq, alpha_max);
                let a: Vec<_> = every
                    .iter()
                    .filter(reads)
                    .map(|s| (s.k, s.body, s.alpha.to_bits()))
                    .collect();
                let b: Vec<_> = short
                    .iter()
                    .filter(reads)
                    .map(|s| (s.k, s.body, s.alpha.to_bits()))
                    .collect();
                assert_eq!(a, b, "n {n}, α_max {alpha_max}");
                kept += short.len();
                full += every.len();
            }
            // The bound of the rate against the probe's difference quotient of every joint.
            let branches = &sys.problem.cons.branches;
            let qp = sys.problem.retraction.point(&q, &dq, PROBE);
            let omega = angular_velocities(&q, &dq);
            for (i, j) in model.joints.iter().enumerate() {
                let joint = JointId(i);
                let Some(r) = Reading::at(&model, joint, &q, branches, || &omega) else {
                    continue;
                };
                assert_eq!(
                    Some(r.theta.to_bits()),
                    unilateral::limit_angle(&model, joint, &q, branches).map(f64::to_bits)
                );
                let Some(bound) = r.rate else {
                    assert!(j.kind == crate::model::JointKind::Prismatic, "{}", j.name);
                    continue;
                };
                let t1 = unilateral::limit_angle(&model, joint, &qp, branches).unwrap();
                let quotient = ((t1 - r.theta) / PROBE).abs();
                assert!(
                    quotient <= bound * (1.0 + 1e-9) + 1e-9,
                    "{}: {quotient} > {bound}",
                    j.name
                );
            }
        }
    }
    // The shortcut is taken (else this test would check nothing).
    assert!(kept < full / 2, "{kept} of {full} stops kept");
}

/// [`Guard::stops_from`] with `at_boundary` (the valley correction's path, module
/// `solver::valley`): a joint at a stop (within the tolerance) that the path closes is held
/// from `α = 0`, one that the path opens is not listed, and every other stop is listed as by
/// [`Guard::stops`], bit for bit; without `at_boundary` a stop at its boundary is never listed.
#[test]
fn a_stop_at_its_boundary_that_the_path_closes_is_held_from_the_start() {
    let options = Options::default();
    let limit = 1.2;
    let model = load_str(
        &limited_chain(6, limit),
        "limited.urdf",
        &ImportOptions::default(),
    )
    .unwrap()
    .model;
    let all = inequalities(&model, &options);
    let mut lcg = crate::lcg::Lcg::new(5);
    let (mut closing, mut opening) = (0, 0);
    for trial in 0..16 {
        // joint1 on its upper stop (within 10⁻¹² rad), the others inside.
        let values = model
            .joints
            .iter()
            .filter(|j| j.limits.is_some())
            .map(|j| {
                let v = if j.name == "joint1" {
                    limit - 1e-12
                } else {
                    0.5 * limit * lcg.signed()
                };
                (j.name.clone(), vec![v])
            })
            .collect();
        let start = State::from_joint_values(&model, &values);
        let q = start.q;
        let cons = Constraints::new(&model, &[]).on_branches(start.branches);
        let mut sys = System::new(&model, cons, Backend::of(&model, &options));
        let part = sys.partition(&q);
        let eval = sys.evaluate(&q, &part).unwrap();
        let d = DVector::from_fn(part.independent.len(), |_, _| lcg.signed());
        let dq = sys.tangent_step(&part, &eval, &d);
        let guard = Guard::new(&model, &options, all.clone(), &[], 1e-9, &q);
        let upper = all
            .iter()
            .position(|u| {
                matches!(u, Unilateral::Limit { joint, bound: unilateral::Bound::Upper, .. }
                    if model.joints[joint.0].name == "joint1")
            })
            .unwrap();
        let plain = guard.stops(&sys, &q, &dq, f64::INFINITY);
        let held = guard.stops_from(&sys, &q, &dq, f64::INFINITY, true);
        assert!(plain.iter().all(|s| s.k != upper), "trial {trial}");
        let key = |s: &Stop| (s.k, s.body, s.alpha.to_bits());
        let others: Vec<_> = held.iter().filter(|s| s.k != upper).map(key).collect();
        assert_eq!(
            others,
            plain.iter().map(key).collect::<Vec<_>>(),
            "trial {trial}"
        );
        // Whether the path closes joint1's upper stop: its angle rises along the probe.
        let branches = &sys.problem.cons.branches;
        let joint = model
            .joints
            .iter()
            .position(|j| j.name == "joint1")
            .unwrap();
        let angle = |x: &DVector<f64>| {
            unilateral::limit_angle(&model, JointId(joint), x, branches).unwrap()
        };
        let qp = sys.problem.retraction.point(&q, &dq, PROBE);
        let at = held.iter().find(|s| s.k == upper);
        if angle(&qp) > angle(&q) {
            closing += 1;
            assert_eq!(at.map(|s| s.alpha), Some(0.0), "trial {trial}");
        } else {
            opening += 1;
            assert!(at.is_none(), "trial {trial}");
        }
    }
    // Both cases were met.
    assert!(
        closing > 0 && opening > 0,
        "{closing} closing, {opening} opening"
    );
}
