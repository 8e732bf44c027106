//! The sparse path against the dense path on the same poses.
use super::*;
use crate::urdf::{load_str, ImportOptions};

fn verify_on(m: &Model, s: &State, tol: &Tolerances, sparse: bool) -> Result<Verification> {
    let backend = if sparse {
        crate::solver::system::Backend::Sparse
    } else {
        crate::solver::system::Backend::Dense
    };
    verify_by(m, s, tol, backend, super::Eigenvalues::WhenCheap)
}

fn verify_by(
    m: &Model,
    s: &State,
    tol: &Tolerances,
    backend: crate::solver::system::Backend,
    eigenvalues: super::Eigenvalues,
) -> Result<Verification> {
    super::run::verify_on(m, s, tol, &Unilaterals::default(), backend, eigenvalues)
}

fn load(text: &str) -> Model {
    load_str(text, "m.urdf", &ImportOptions::default())
        .unwrap()
        .model
}

/// A pose off equilibrium: every tree joint turned by a different angle.
fn bent(model: &Model) -> State {
    let values = model
        .joints
        .iter()
        .filter(|j| j.tree && j.kind.scalar_coordinates() == 1)
        .enumerate()
        .map(|(k, j)| (j.name.clone(), vec![0.05 * ((k * 7 % 5) as f64 - 2.0)]))
        .collect();
    State::from_joint_values(model, &values)
}

/// On a tree the efforts are `∂V/∂θ_k` on both paths: the sparse lock multipliers equal the
/// dense minimum-norm solution joint by joint, and the verdicts agree.
#[test]
fn sparse_efforts_equal_dense_efforts_on_a_tree() {
    let model = load(&crate::generate::chain(12, false));
    let state = bent(&model);
    let tol = Tolerances::default();
    let d = verify_on(&model, &state, &tol, false).unwrap();
    let s = verify_on(&model, &state, &tol, true).unwrap();
    assert!(!d.passed && !s.passed);
    assert_eq!(d.imbalance.len(), s.imbalance.len());
    let big = d
        .imbalance
        .iter()
        .fold(0.0f64, |a, i| a.max(i.effort.abs()));
    assert!(big > 1.0, "the bent chain needs efforts: {big}");
    for (a, b) in d.imbalance.iter().zip(&s.imbalance) {
        assert_eq!((&a.joint, a.dof), (&b.joint, b.dof));
        assert!(
            (a.effort - b.effort).abs() <= 1e-9 * big,
            "{}: dense {} sparse {}",
            a.joint,
            a.effort,
            b.effort
        );
    }
    assert!((d.potential_energy - s.potential_energy).abs() <= 1e-12 * big);
    assert!(d.unassigned <= 1e-9 * big && s.unassigned <= 1e-9 * big);
    // Both projected gradients vanish together: at the rest pose both are tiny.
    let (rest, _) = crate::solver::solve(&model, &Default::default()).unwrap();
    let d = verify_on(&model, &rest, &tol, false).unwrap();
    let s = verify_on(&model, &rest, &tol, true).unwrap();
    assert!(d.passed && s.passed, "{d:?} {s:?}");
    assert!(s.projected_gradient < 1e-6 && d.projected_gradient < 1e-6);
}

/// With closed loops the split of the effort among a loop's joints differs (basic against
/// minimum-norm), but the verdict does not: a bent ladder fails on both, its rest pose passes
/// on both; a spherical joint's load is unassigned on both.
#[test]
fn sparse_and_dense_verdicts_agree_with_loops_and_spherical_joints() {
    let tol = Tolerances::default();
    let ladder = load(&crate::generate::ladder(4));
    let bent_ladder = crate::verify::assemble(&ladder, &bent(&ladder)).unwrap();
    for sparse in [false, true] {
        let v = verify_on(&ladder, &bent_ladder, &tol, sparse).unwrap();
        assert!(!v.passed, "sparse {sparse}: {v:?}");
        assert!(v.max_imbalance.unwrap().effort.abs() > 1e-3);
    }
    let (rest, _) = crate::solver::solve(&ladder, &Default::default()).unwrap();
    for sparse in [false, true] {
        let v = verify_on(&ladder, &rest, &tol, sparse).unwrap();
        assert!(v.passed, "sparse {sparse}: {v:?}");
    }
    let text = include_str!("../../robots/stewart_platform.urdf");
    let stewart = load(text);
    let start = crate::solver::initial_state(&stewart);
    let start = crate::verify::assemble(&stewart, &start).unwrap();
    let d = verify_on(&stewart, &start, &tol, false).unwrap();
    let s = verify_on(&stewart, &start, &tol, true).unwrap();
    assert_eq!(d.passed, s.passed);
    let (rest, _) = crate::solver::solve(&stewart, &Default::default()).unwrap();
    for sparse in [false, true] {
        let v = verify_on(&stewart, &rest, &tol, sparse).unwrap();
        assert!(v.passed, "stewart, sparse {sparse}: {v:?}");
    }
}

/// Where nothing touches, the first solve of the forces that hold a pose is the balance
/// check's own system: taken from it (`held::free_of`) the efforts, the unassigned force and
/// the resolution are those `held` finds with its own partition, on a chain, a ladder (with
/// redundant rows) and a chain with a lock of its own, at a rest and off it; and the locked
/// system built on the balance check's evaluated rows (module `model_rows`) gives them too,
/// to the bit.
#[test]
fn held_from_the_balance_checks_system_is_held_from_its_own() {
    let locked = crate::generate::chain(30, false).replace(
        "</robot>",
        "<mech:lock joint=\"joint3\" value=\"0.2\"/></robot>",
    );
    for text in [
        crate::generate::chain(30, false),
        crate::generate::ladder(5),
        locked,
    ] {
        let model = load(&text);
        let (rest, _) = crate::solver::solve(&model, &Default::default()).unwrap();
        for state in [rest, bent(&model)] {
            let locks = crate::solver::lock_values(&model);
            let backend = crate::solver::system::Backend::Sparse;
            let mut r = super::reduced::reduced(&model, &state, &locks, backend, true).unwrap();
            let values = super::run::tree_coordinates(&model, &state);
            let tau = 1e-9 * r.force_scale.max(1.0);
            let held = |free, rows| {
                super::held::held(&model, &state, &[], &values, backend, tau, free, rows).unwrap()
            };
            let own = held(super::held::Free::Solve, None);
            let (part, eval) = r.solved.as_ref().unwrap();
            let given = held(
                super::held::Free::Given(super::held::free_of(&r.sys, part, eval)),
                None,
            );
            // Without the first solve (`analyze`'s self-check): the same numbers (a zero
            // added or not: `==` takes −0 for 0).
            let skipped = held(super::held::Free::Skip { joint_space: false }, None);
            let potential = r.potential.clone();
            let rows = super::held::ModelRows::take(&mut r.sys, &state.q, values.len(), potential);
            assert!(rows.is_some(), "{}: the balance check's rows", model.name);
            let reused = held(super::held::Free::Skip { joint_space: false }, rows);
            for other in [&given, &skipped, &reused] {
                assert_eq!(own.efforts, other.efforts, "{}", model.name);
                assert_eq!(own.unassigned, other.unassigned, "{}", model.name);
                assert_eq!(own.locked, other.locked, "{}", model.name);
            }
        }
    }
}

/// `verify` through the tree factors equals `verify` through the sparse ones (the same
/// partition, other factors): the same verdicts, efforts, reduced gradient and energy to
/// 1e-9 relative (eigenvalues 1e-7), on a chain and a chain with locked joints, at rest and
/// bent; a ladder (whose loops do not fit the tree factors' border) too.
#[test]
fn verify_through_the_tree_factors_equals_verify_through_the_sparse_ones() {
    use crate::solver::system::Backend;
    let locked = crate::generate::chain(50, false).replace(
        "</robot>",
        "<mech:lock joint=\"joint3\" value=\"0.2\"/><mech:lock joint=\"joint17\"/></robot>",
    );
    // Every joint limited to ±0.02 rad: at rest most lean on a stop.
    let stops = crate::generate::chain(50, false)
        .replace("type=\"continuous\"", "type=\"revolute\"")
        .replace(
            "<axis ",
            "<limit lower=\"-0.02\" upper=\"0.02\" effort=\"1\" velocity=\"1\"/><axis ",
        );
    for text in [
        crate::generate::chain(60, false),
        locked,
        stops,
        crate::generate::ladder(4),
    ] {
        let model = load(&text);
        let (rest, report) = crate::solver::solve(&model, &Default::default()).unwrap();
        if model.joints.iter().any(|j| j.limits.is_some()) {
            assert!(report.active_limits.len() > 10, "{}", model.name);
        }
        let tol = Tolerances::default();
        for state in [rest, bent(&model)] {
            let all = super::Eigenvalues::Always;
            let s = verify_by(&model, &state, &tol, Backend::Sparse, all).unwrap();
            let t = verify_by(&model, &state, &tol, Backend::Tree, all).unwrap();
            let what = &model.name;
            assert_eq!(s.passed, t.passed, "{what}");
            let close = |a: f64, b: f64, scale: f64| (a - b).abs() <= 1e-9 * scale.max(1.0);
            assert!(close(
                s.potential_energy,
                t.potential_energy,
                s.potential_energy.abs()
            ));
            assert!(
                close(s.projected_gradient, t.projected_gradient, s.force_scale),
                "{what}"
            );
            assert!(close(s.unassigned, t.unassigned, s.force_scale), "{what}");
            assert_eq!(s.imbalance.len(), t.imbalance.len());
            let scale = s
                .imbalance
                .iter()
                .fold(0.0f64, |a, i| a.max(i.effort.abs()));
            assert!(
                scale > 0.0 || s.passed,
                "{what}: efforts all zero off the rest"
            );
            for (a, b) in s.imbalance.iter().zip(&t.imbalance) {
                assert_eq!((&a.joint, a.dof, a.locked), (&b.joint, b.dof, b.locked));
                assert!(
                    close(a.effort, b.effort, scale),
                    "{what} {}: {} vs {}",
                    a.joint,
                    a.effort,
                    b.effort
                );
            }
            match (&s.stability, &t.stability) {
                (Some(a), Some(b)) => {
                    assert_eq!(a.verdict, b.verdict, "{what}");
                    assert_eq!(a.eigenvalues.len(), b.eigenvalues.len(), "{what}");
                    let top = a.eigenvalues.iter().fold(0.0f64, |x, e| x.max(e.abs()));
                    for (x, y) in a.eigenvalues.iter().zip(&b.eigenvalues) {
                        assert!((x - y).abs() <= 1e-7 * top.max(1.0), "{what}: {x} vs {y}");
                    }
                }
                (None, None) => {}
                _ => panic!("{what}: a verdict on one path only"),
            }
        }
    }
}

/// `analyze`'s self-check ([`super::Eigenvalues::Skip`]) on the dense path: no null-space
/// basis and no first solve of the forces, the balance check's rows handed to the locked
/// system. It reports what `verify` reports there (the pass, the failures, the residual, the
/// efforts, the unassigned force, the force scale the energy and the stops' and contacts' report, `==`), with
/// `projected_gradient` NaN and no verdict: on a chain, a chain leaning on its stops, a
/// ladder, the Stewart platform and a rope on the ground (frictionless and sticking), at rest
/// and bent.
#[test]
fn the_self_check_on_the_dense_path_reports_what_verify_reports() {
    use crate::solver::system::Backend;
    let stops = crate::generate::chain(12, false)
        .replace("type=\"continuous\"", "type=\"revolute\"")
        .replace(
            "<axis ",
            "<limit lower=\"-0.02\" upper=\"0.02\" effort=\"1\" velocity=\"1\"/><axis ",
        );
    let stick = Unilaterals {
        friction: crate::model::Friction::Stick,
        ..Default::default()
    };
    let cases = [
        (crate::generate::chain(12, false), Unilaterals::default()),
        (stops, Unilaterals::default()),
        (crate::generate::ladder(4), Unilaterals::default()),
        (
            include_str!("../../robots/stewart_platform.urdf").to_string(),
            Unilaterals::default(),
        ),
        (crate::generate::rope(8), Unilaterals::default()),
        (crate::generate::rope(8), stick),
    ];
    let (mut passed, mut failed, mut touching) = (0, 0, 0);
    for (text, uni) in cases {
        let model = load(&text);
        let options = crate::solver::Options {
            friction: uni.friction,
            ..Default::default()
        };
        let (rest, _) = crate::solver::solve(&model, &options).unwrap();
        let bent = crate::verify::assemble(&model, &bent(&model)).unwrap();
        for state in [rest, bent] {
            let tol = Tolerances::default();
            let run = |e| super::run::verify_on(&model, &state, &tol, &uni, Backend::Dense, e);
            let v = run(super::Eigenvalues::WhenCheap).unwrap();
            let s = run(super::Eigenvalues::Skip).unwrap();
            let what = &model.name;
            // Failures, contacts and stops with their forces, penetration, friction verdict.
            let worst = super::test_support::same_report(&v, &s, what);
            assert_eq!(worst, 0.0, "{what}");
            assert_eq!(v.unilateral, s.unilateral, "{what}");
            assert_eq!(v.constraint_residual, s.constraint_residual, "{what}");
            assert_eq!(v.effort_tolerance, s.effort_tolerance, "{what}");
            assert!(
                s.projected_gradient.is_nan() && s.stability.is_none(),
                "{what}"
            );
            assert!(v.projected_gradient.is_finite(), "{what}");
            touching += v.unilateral.contacts.len() + v.unilateral.active_limits.len();
            if v.passed {
                passed += 1;
            } else {
                failed += 1;
            }
        }
    }
    // The cases pass and fail, with stops and contacts touching.
    assert!(
        passed >= 5 && failed >= 4 && touching > 10,
        "{passed} {failed} {touching}"
    );
}

/// `analyze`'s self-check on the tree path, where the locked system is partitioned by bodies
/// (module `tree_partition`), reports what `verify` reports there to rounding: the same pass
/// and failures, the residuals, force scale, unassigned force and energy `==`, every effort
/// within 1e-12 of the force scale; on a chain of 60 bodies and the same chain with locks of
/// its own, at rest and bent.
#[test]
fn the_self_check_on_the_tree_path_reports_what_verify_reports() {
    use crate::solver::system::Backend;
    let locked = crate::generate::chain(60, false).replace(
        "</robot>",
        "<mech:lock joint=\"joint3\" value=\"0.2\"/><mech:lock joint=\"joint17\"/></robot>",
    );
    let (mut passed, mut failed) = (0, 0);
    for text in [crate::generate::chain(60, false), locked] {
        let model = load(&text);
        let (rest, _) = crate::solver::solve(&model, &Default::default()).unwrap();
        let bent = crate::verify::assemble(&model, &bent(&model)).unwrap();
        for state in [rest, bent] {
            let tol = Tolerances::default();
            let uni = Unilaterals::default();
            let run = |e| super::run::verify_on(&model, &state, &tol, &uni, Backend::Tree, e);
            let v = run(super::Eigenvalues::WhenCheap).unwrap();
            let s = run(super::Eigenvalues::Skip).unwrap();
            let what = &model.name;
            let worst = super::test_support::same_report(&v, &s, what);
            assert_eq!(v.unilateral, s.unilateral, "{what}");
            assert!(
                worst <= 1e-12 * v.force_scale,
                "{what}: {worst:e} of {:e}",
                v.force_scale
            );
            if v.passed {
                passed += 1;
            } else {
                failed += 1;
            }
        }
    }
    assert!(passed >= 2 && failed >= 2, "{passed} {failed}");
}
