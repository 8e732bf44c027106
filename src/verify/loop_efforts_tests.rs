//! The efforts in joint coordinates: `∂V/∂θ` and `J_θ` against central finite differences
//! along the joint coordinates, the self-check on loops against `verify`'s general partition,
//! and the structures left to it.

use super::*;
use crate::constraints::{Constraints, Triplets};
use crate::state::{JointValues, State};
use crate::verify::test_support::{model as load, same_report};
use crate::verify::{Eigenvalues, Tolerances, Unilaterals, Verification};

fn slider_crank() -> String {
    include_str!("../../robots/slider_crank.urdf").to_string()
}

/// Every coordinate joint turned or slid off its initial value, differently (the loops left
/// open: the tree's forward kinematics).
fn bent_values(model: &Model) -> JointValues {
    model
        .joints
        .iter()
        .enumerate()
        .filter(|(_, j)| j.tree && !j.merged && coordinate_kind(j.kind))
        .map(|(i, j)| (j.name.clone(), vec![0.07 * ((i * 37 % 11) as f64 - 5.0)]))
        .collect()
}

/// The model's rows at `state`: values and triplets.
fn rows(model: &Model, state: &State) -> (DVector<f64>, Triplets) {
    let cons = Constraints::new(model, &[]).on_branches(state.branches.clone());
    let mut phi = DVector::zeros(cons.len());
    let mut jac = Triplets::default();
    cons.evaluate(model, &state.q, &mut phi, Some(&mut jac));
    (phi, jac)
}

/// `V` and `∇V` at `state`.
fn energy(model: &Model, state: &State) -> (f64, DVector<f64>) {
    let mut g = DVector::zeros(state.q.len());
    let e = crate::forces::potential(model, &state.branches, &state.q, &mut g, None).unwrap();
    (e.total, g)
}

/// `∂V/∂θ_k` (the wrenches summed leaves to root) and every component's `J_c = ∂Φ_L/∂θ`
/// equal central differences along the joint coordinates (the tree moved by its forward
/// kinematics) to 1e-7 of their scale, and every loop row's difference along a coordinate
/// off its paths (above the common ancestor, or another loop's) vanishes: on a ladder, the
/// slider-crank (a prismatic joint) and a ladder with a sliding rung, at bent poses with the
/// loops closed.
#[test]
fn rates_and_the_closure_jacobian_are_the_finite_differences() {
    let sliding = crate::generate::ladder(3).replacen(
        "type=\"continuous\"><parent link=\"left1\"/>",
        "type=\"prismatic\"><limit lower=\"-1\" upper=\"1\" effort=\"1\" velocity=\"1\"/><parent link=\"left1\"/>",
        1,
    );
    assert_ne!(sliding, crate::generate::ladder(3));
    for text in [crate::generate::ladder(3), slider_crank(), sliding] {
        let model = load(&text, false);
        let loops = Loops::of(&model, 0).expect("a tree closed by loops");
        // Closed loops: a loop row's derivative along a joint above its common ancestor is
        // `ω × d` for a gap `d` in world components, zero where the loop closes.
        let opened = State::from_joint_values(&model, &bent_values(&model));
        let closed = crate::verify::assemble(&model, &opened).unwrap();
        let values: JointValues = closed.joint_values(&model).into_iter().collect();
        let state = State::from_joint_values(&model, &values);
        let (_, grad) = energy(&model, &state);
        let (_, jac) = rows(&model, &state);
        let axes = axes(&model, &state.q, &loops.up);
        let rates = loops.rates(&model, &state.q, &grad, &axes);
        let jacobians = loops.closure_jacobians(&model, &state.q, &jac.entries, &axes);
        let h = 1e-6;
        let at = |name: &str, d: f64| {
            let mut v = values.clone();
            v.get_mut(name).unwrap()[0] += d;
            State::from_joint_values(&model, &v)
        };
        let (mut checked, mut zeros) = (0, 0);
        for (k, j) in model.joints.iter().enumerate() {
            if !values.contains_key(&j.name) {
                continue;
            }
            let (plus, minus) = (at(&j.name, h), at(&j.name, -h));
            let dv = (energy(&model, &plus).0 - energy(&model, &minus).0) / (2.0 * h);
            let scale = dv.abs().max(1.0);
            assert!(
                (rates[k] - dv).abs() <= 1e-7 * scale,
                "{} {}: {} against {dv}",
                model.name,
                j.name,
                rates[k]
            );
            let dphi = (rows(&model, &plus).0 - rows(&model, &minus).0) / (2.0 * h);
            for (comp, jc) in loops.components.iter().zip(&jacobians) {
                let column = comp.joints.iter().position(|&c| c == k);
                let mut r0 = 0;
                for &i in &comp.loops {
                    let l = &loops.loops[i];
                    for r in 0..l.powers.len() {
                        let fd = dphi[l.first + r];
                        match column {
                            Some(c) => {
                                let a = jc[(r0 + r, c)];
                                assert!(
                                    (a - fd).abs() <= 1e-7 * fd.abs().max(1.0),
                                    "{} {} row {}: {a} against {fd}",
                                    model.name,
                                    j.name,
                                    l.first + r
                                );
                                checked += 1;
                            }
                            None => {
                                assert!(fd.abs() <= 1e-7, "{} {}: {fd}", model.name, j.name);
                                zeros += 1;
                            }
                        }
                    }
                    r0 += l.powers.len();
                }
            }
        }
        assert!(checked > 10, "{}: {checked}", model.name);
        if model.name.starts_with("ladder") {
            assert!(zeros > 10, "{}: {zeros}", model.name);
        }
    }
}

/// The kinds of failure a verification reports: efforts, unassigned force, constraint residual.
fn kinds(v: &Verification, tol: &Tolerances) -> (bool, bool, bool) {
    (
        v.max_imbalance
            .as_ref()
            .is_some_and(|m| m.effort.abs() > v.effort_tolerance),
        v.unassigned > v.effort_tolerance,
        v.scaled_constraint_residual > tol.constraint,
    )
}

/// `analyze`'s self-check on loops (the efforts in joint coordinates) reports what `verify`
/// (the general partition) reports: the same pass and kinds of failure, the residuals, force
/// scale, energy and unassigned force `==`; with at most `MAX_DEPENDENT` loop rows (the
/// least efforts, unique) every effort within 1e-9 of the force scale, above (the
/// basic efforts, which depend on the locks dropped) within the effort tolerance at rest. On
/// ladders of 12 and 45 rungs and the slider-crank: at rest (passing), bent with the loops
/// closed (failing on an effort) and bent with the loops open (failing on the residual).
#[test]
fn the_self_check_in_joint_space_reports_what_verify_reports() {
    use crate::solver::system::Backend;
    let (mut passed, mut efforts, mut open) = (0, 0, 0);
    for text in [
        crate::generate::ladder(12),
        crate::generate::ladder(45),
        slider_crank(),
        include_str!("../../robots/four_bar_spatial.urdf").to_string(),
        include_str!("../../robots/stewart_platform.urdf").to_string(),
    ] {
        let model = load(&text, false);
        // The four-bar (a spherical joint in the tree) and the Stewart platform (floating
        // legs) are left to the general partition: the same numbers.
        let general = Loops::of(&model, 0).is_none();
        let least = Loops::of(&model, 0)
            .is_none_or(|l| l.dependent() <= crate::verify::held::MAX_DEPENDENT);
        assert_eq!(least, model.name != "ladder45", "{}", model.name);
        let (rest, _) = crate::solver::solve(&model, &Default::default()).unwrap();
        let opened = State::from_joint_values(&model, &bent_values(&model));
        let closed = crate::verify::assemble(&model, &opened).unwrap();
        for (state, what) in [(rest, "rest"), (closed, "bent"), (opened, "open")] {
            let tol = Tolerances::default();
            let uni = Unilaterals::default();
            let run =
                |e| crate::verify::run::verify_on(&model, &state, &tol, &uni, Backend::Sparse, e);
            let v = run(Eigenvalues::WhenCheap).unwrap();
            let s = run(Eigenvalues::Skip).unwrap();
            let what = format!("{} {what}", model.name);
            assert_eq!(kinds(&v, &tol), kinds(&s, &tol), "{what}");
            let worst = same_report(&v, &s, &what);
            if general {
                assert_eq!(worst, 0.0, "{what}");
            }
            let bound = if kinds(&v, &tol).2 {
                // Open loops: the rows' world components turn with a common ancestor (the
                // structural zeros of `J_θ` hold where the loops close); the residual fails.
                f64::INFINITY
            } else if least {
                // The least efforts are unique: both paths find them (the general path's
                // least-squares choice by the guarded SVD, module `solver::svd`).
                1e-9 * v.force_scale
            } else if v.passed {
                v.effort_tolerance
            } else {
                f64::INFINITY
            };
            assert!(worst <= bound, "{what}: {worst:e} of {:e}", v.force_scale);
            match kinds(&v, &tol) {
                _ if v.passed => passed += 1,
                (true, false, false) => efforts += 1,
                (_, _, true) => open += 1,
                k => panic!("{what}: {k:?}"),
            }
        }
    }
    assert!(
        passed == 5 && efforts >= 4 && open >= 4,
        "{passed} {efforts} {open}"
    );
}

/// Left to the general partition (checked on the structure, before any work): a chain (no
/// loop: the tree path), a floating ladder, the four-bar (a spherical joint in the tree), the
/// Stewart platform (floating legs), a ladder with a lock of its own, a chain with a mimic.
#[test]
fn other_structures_are_left_to_the_general_partition() {
    let locked = crate::generate::ladder(3).replace(
        "</robot>",
        "<mech:lock joint=\"hang_left1\" value=\"0.1\"/></robot>",
    );
    let cases = [
        (crate::generate::chain(12, false), false),
        (crate::generate::ladder(3), true),
        (
            include_str!("../../robots/four_bar_spatial.urdf").to_string(),
            false,
        ),
        (
            include_str!("../../robots/stewart_platform.urdf").to_string(),
            false,
        ),
        (locked, false),
        (
            include_str!("../../robots/panda_class.urdf").to_string(),
            false,
        ),
    ];
    for (text, floating) in cases {
        let model = load(&text, floating);
        let locks = crate::solver::lock_values(&model).len();
        assert!(Loops::of(&model, locks).is_none(), "{}", model.name);
    }
    // A lock of the model, given or not, is left to the general partition.
    let model = load(&crate::generate::ladder(3), false);
    assert!(Loops::of(&model, 1).is_none());
}
