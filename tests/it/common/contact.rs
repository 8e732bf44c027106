//! `verify` on poses resting on stops, grounds and obstacles, on both linear-algebra paths.

use nalgebra::Vector3;
use restpose::model::Friction;
use restpose::verify::{verify_using, Tolerances, Unilaterals, Verification};
use restpose::LinearAlgebra;
use restpose::State;

/// Asserts that `verify` accepts `s` (with `friction`).
pub(crate) fn assert_verified_contacts(m: &restpose::Model, s: &State, friction: Friction) {
    let v = check(m, s, friction);
    assert!(v.passed, "{}: {v:?}", m.name());
}

pub(crate) fn check(m: &restpose::Model, s: &State, friction: Friction) -> Verification {
    let uni = Unilaterals {
        friction,
        ..Default::default()
    };
    verify_with_options(m, s, &Tolerances::default(), &uni).unwrap()
}

/// `verify` on the dense path, after asserting that the sparse path (module
/// `verify::unilateral_sparse`) gives the same verdict, the same failures, the same stops and
/// contacts with the same forces (to `1e-9` of the largest, where the pose passes: a failing
/// pose's forces are a least-squares fit on the dense path and a basic solution on the
/// sparse one), penetration and stability verdict.
pub(crate) fn verify_with_options(
    m: &restpose::Model,
    s: &State,
    tol: &Tolerances,
    uni: &Unilaterals,
) -> restpose::Result<Verification> {
    let d = verify_using(m, s, tol, uni, LinearAlgebra::Dense)?;
    let sp = verify_using(m, s, tol, uni, LinearAlgebra::Sparse)?;
    assert_paths_agree(m.name(), &d, &sp);
    Ok(d)
}

/// The assertions of [`verify_with_options`].
fn assert_paths_agree(name: &str, d: &Verification, s: &Verification) {
    let (du, su) = (&d.unilateral, &s.unilateral);
    assert_eq!(d.passed, s.passed, "{name}: dense {d:?}\nsparse {s:?}");
    assert_eq!(du.failures, su.failures, "{name}");
    assert_eq!(du.penetration, su.penetration, "{name}");
    assert_eq!(du.contacts.len(), su.contacts.len(), "{name}");
    assert_eq!(du.active_limits.len(), su.active_limits.len(), "{name}");
    assert_eq!(
        d.stability.as_ref().map(|v| v.verdict),
        s.stability.as_ref().map(|v| v.verdict),
        "{name}"
    );
    if !d.passed {
        return;
    }
    let big = du
        .contacts
        .iter()
        .map(|c| c.normal_force.abs())
        .chain(du.active_limits.iter().map(|l| l.effort.abs()))
        .fold(1e-12f64, f64::max);
    for (a, b) in du.contacts.iter().zip(&su.contacts) {
        assert_eq!((&a.link, a.state), (&b.link, b.state), "{name}");
        assert!(
            (a.normal_force - b.normal_force).abs() <= 1e-9 * big,
            "{name} `{}`: dense {} sparse {}",
            a.link,
            a.normal_force,
            b.normal_force
        );
        let ft = Vector3::from(a.tangential_force) - Vector3::from(b.tangential_force);
        assert!(ft.norm() <= 1e-9 * big, "{name} `{}`: {ft}", a.link);
    }
    for (a, b) in du.active_limits.iter().zip(&su.active_limits) {
        assert_eq!((&a.joint, &a.bound), (&b.joint, &b.bound), "{name}");
        assert!(
            (a.effort - b.effort).abs() <= 1e-9 * big,
            "{name} `{}`: dense {} sparse {}",
            a.joint,
            a.effort,
            b.effort
        );
    }
}

/// Sticking contacts hold a body of weight `weight` on a plane tilted by `slope`: at least three
/// contacts, their forces balance the weight, `Σ f_n = W cos α` and `|Σ f_t| = W sin α` (closed
/// form), so the friction they need is `tan α`; every contact sticks.
pub(crate) fn assert_sticks_on_slope(r: &restpose::Report, weight: f64, slope: f64) {
    use restpose::solver::ContactState;
    assert!(r.converged(), "{:?}", r.termination);
    assert!(r.contacts.len() >= 3, "{:?}", r.contacts);
    let fnorm: f64 = r.contacts.iter().map(|c| c.normal_force).sum();
    let ft: Vector3<f64> = r
        .contacts
        .iter()
        .map(|c| Vector3::from(c.tangential_force))
        .sum();
    approx::assert_abs_diff_eq!(fnorm, weight * slope.cos(), epsilon = 1e-8);
    approx::assert_abs_diff_eq!(ft.norm(), weight * slope.sin(), epsilon = 1e-8);
    approx::assert_abs_diff_eq!(ft.norm() / fnorm, slope.tan(), epsilon = 1e-9);
    assert!(r.contacts.iter().all(|c| c.state == ContactState::Sticking));
}
