//! The pendulum with spring of the paper (NOTES.md): closed-form reference values.
mod common;
use approx::assert_abs_diff_eq;
use common::*;
use restpose::{Method, Options};

#[test]
fn pendulum_reaches_the_papers_equilibrium() {
    let m = robot("pendulum");
    let (s, r) = solve(&m);
    let phi = s.joint(&m, "pivot").unwrap()[0];
    assert_abs_diff_eq!(phi, -1.381577, epsilon = 1e-6);
    assert_abs_diff_eq!(r.energy.total, -18.686957, epsilon = 1e-6);
    assert_abs_diff_eq!(r.history[0].potential_energy, -13.521666, epsilon = 1e-6);
    // Centre of mass at (0.188092, -0.982151).
    let bar = s.link_pose(&m, "bar").unwrap();
    let com = bar * nalgebra::Point3::new(1.0, 0.0, 0.0);
    assert_abs_diff_eq!(com.x, 0.188092, epsilon = 1e-6);
    assert_abs_diff_eq!(com.y, -0.982151, epsilon = 1e-6);
    assert_eq!(r.dof, 1);
    assert_eq!(
        r.stability.as_ref().unwrap().verdict,
        restpose::solver::Verdict::Stable
    );
    assert_verified_minimum(&m, &s);
}

/// The stationarity condition of V(φ) = 19.62 sin φ + 1.5 (l − 2)², solved independently by
/// bisection, agrees with the solver to 1e-9.
#[test]
fn pendulum_matches_bisection_of_the_closed_form() {
    let dv = |phi: f64| {
        let (xp, yp) = (2.0 * phi.cos(), 2.0 * phi.sin());
        let l = ((xp + 1.0).powi(2) + (yp + 2.0).powi(2)).sqrt();
        let dl = ((xp + 1.0) * (-2.0 * phi.sin()) + (yp + 2.0) * (2.0 * phi.cos())) / l;
        19.62 * phi.cos() + 3.0 * (l - 2.0) * dl
    };
    let (mut a, mut b) = (-1.5, -1.2);
    assert!(dv(a) * dv(b) < 0.0);
    for _ in 0..200 {
        let c = 0.5 * (a + b);
        if dv(a) * dv(c) <= 0.0 {
            b = c;
        } else {
            a = c;
        }
    }
    let m = robot("pendulum");
    let (s, _) = solve(&m);
    assert_abs_diff_eq!(
        s.joint(&m, "pivot").unwrap()[0],
        0.5 * (a + b),
        epsilon = 1e-9
    );
}

#[test]
fn quasi_newton_methods_agree() {
    let m = robot("pendulum");
    for method in [Method::Bfgs, Method::Dfp] {
        let (s, r) = restpose::solve(
            &m,
            &Options {
                method,
                ..Default::default()
            },
        )
        .unwrap();
        assert!(r.converged(), "{method:?}: {:?}", r.termination);
        assert_abs_diff_eq!(s.joint(&m, "pivot").unwrap()[0], -1.381577, epsilon = 1e-6);
        assert_abs_diff_eq!(r.energy.total, -18.686957, epsilon = 1e-6);
    }
}

/// Pivot reaction by hand: the joint carries the weight and the spring force.
#[test]
fn pivot_reaction_balances_weight_and_spring() {
    let m = robot("pendulum");
    let (s, r) = solve(&m);
    let phi = s.joint(&m, "pivot").unwrap()[0];
    let p = nalgebra::Vector3::new(2.0 * phi.cos(), 2.0 * phi.sin(), 0.0);
    let d = nalgebra::Vector3::new(-1.0, -2.0, 0.0) - p;
    let l = d.norm();
    let spring = d / l * (3.0 * (l - 2.0));
    let weight = nalgebra::Vector3::new(0.0, -19.62, 0.0);
    let expected = -(spring + weight);
    let (_, re) = r.reactions.iter().find(|(n, _)| n == "pivot").unwrap();
    for k in 0..3 {
        assert_abs_diff_eq!(re.force_world[k], expected[k], epsilon = 1e-8);
    }
    // A revolute joint carries no torque about its axis.
    assert_abs_diff_eq!(re.torque_world[2], 0.0, epsilon = 1e-8);
}
