//! The friction verdict (issue 22): the cases of the issue against closed forms, and `verify`
//! accepting every answer `analyze` gives with the same coefficient.
use crate::common::contact::verify_with_options;
use restpose::model::Friction;
use restpose::solver::ContactState;
use restpose::urdf::{load_str, ImportOptions};
use restpose::verify::{Tolerances, Unilaterals};
use restpose::Options;

/// A box of `mass` whose centre of mass is offset by `com`, on a ground sloping by `alpha`
/// about y (its normal `(sin α, 0, cos α)`).
fn crate_on(alpha: f64, mass: f64, com: [f64; 3]) -> restpose::Model {
    let text = format!(
        r#"<robot name="crate" xmlns:mech="urn:urdf-mech:1">
  <link name="crate">
    <inertial><origin xyz="{} {} {}"/><mass value="{mass}"/><inertia ixx="0.02" iyy="0.03" izz="0.04" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.5 0.4 0.3"/></geometry></collision>
  </link>
  <mech:ground normal="{} 0 {}" xyz="0 0 -0.15"/>
</robot>"#,
        com[0],
        com[1],
        com[2],
        alpha.sin(),
        alpha.cos()
    );
    let opts = ImportOptions {
        floating_base: true,
        ..Default::default()
    };
    load_str(&text, "crate.urdf", &opts).unwrap().model
}

fn stick(mu: f64) -> Options {
    Options {
        friction: Friction::Stick,
        mu: Some(mu),
        ..Default::default()
    }
}

/// A box at rest on a level floor with `mu = 0.001`: no friction force at all, sticking, and
/// `required_mu = 0`; the support polygon is the box's bottom face and the stability margin
/// the distance from the centre to its nearest edge (0.2 m − 0.05 m offset... 0.15 m here).
#[test]
fn a_level_box_needs_no_friction() {
    let m = crate_on(0.0, 2.0, [0.0, 0.0, 0.0]);
    let (s, r) = restpose::solve(&m, &stick(0.001)).unwrap();
    assert!(r.converged(), "{:?}", r.termination);
    let f = r.friction.clone().unwrap();
    assert!(f.required_mu < 1e-12 && !f.slipping, "{f:?}");
    for c in &r.contacts {
        assert!(c.tangential_force.iter().all(|x| x.abs() < 1e-9), "{c:?}");
        assert_eq!(c.state, ContactState::Sticking);
        assert!((c.normal_force - 2.0 * 9.81 / 4.0).abs() < 1e-9);
    }
    let b = r.balance.clone().unwrap();
    assert_eq!(b.support_polygon.len(), 4);
    assert!((b.stability_margin - 0.2).abs() < 1e-9, "{b:?}");
    let v = verify_with_options(&m, &s, &Tolerances::default(), &unilaterals(0.001)).unwrap();
    assert!(v.passed, "{:?}", v.unilateral.failures);
}

fn unilaterals(mu: f64) -> Unilaterals {
    Unilaterals {
        friction: Friction::Stick,
        mu: Some(mu),
        ..Default::default()
    }
}

/// The 1.6 kg crate of the issue on a ramp of α = 0.35 rad: `required_mu = tan α` (to 1e-9),
/// sticking for μ ≥ tan α and slipping below; verify accepts analyze's answer at 0.465 and at
/// tan α, and refuses it below, naming the friction alone.
#[test]
fn a_crate_on_a_ramp_sticks_from_tan_alpha() {
    let alpha = 0.35f64;
    let tan = alpha.tan();
    let m = crate_on(alpha, 1.6, [0.03, -0.02, 0.01]);
    for (mu, slipping) in [
        (0.465, false),
        (tan, false),
        (1.2 * tan, false),
        (tan - 1e-8, true),
        (0.2, true),
    ] {
        let (s, r) = restpose::solve(&m, &stick(mu)).unwrap();
        assert!(r.converged(), "{:?}", r.termination);
        let f = r.friction.clone().unwrap();
        assert!(
            (f.required_mu - tan).abs() < 1e-9,
            "{} vs {tan}",
            f.required_mu
        );
        assert_eq!(f.slipping, slipping, "mu {mu}");
        assert_eq!((f.margin.unwrap() - (mu - f.required_mu)).abs(), 0.0);
        assert_eq!(
            r.contacts.iter().any(|c| c.state == ContactState::Slipping),
            slipping
        );
        // Every corner needs tan α (to twice the least-norm choice's slack, 1e-6).
        for c in &r.contacts {
            assert!((c.required_friction - tan).abs() <= 2e-6 * tan, "{c:?}");
        }
        let v = verify_with_options(&m, &s, &Tolerances::default(), &unilaterals(mu)).unwrap();
        assert_eq!(v.passed, !slipping, "mu {mu}: {:?}", v.unilateral.failures);
        if slipping {
            assert_eq!(
                v.unilateral.failures.len(),
                1,
                "{:?}",
                v.unilateral.failures
            );
            assert!(v.unilateral.failures[0].contains("friction cones"));
        }
        let b = r.balance.unwrap();
        assert!(
            b.stability_margin > 0.0 && b.support_polygon.len() == 4,
            "{b:?}"
        );
    }
}

/// The Solo-12 (joint springs, sticking feet) standing on slopes of 0, 0.1, 0.2, 0.3 rad
/// (gravity tilted about y): a `required_mu` is reported; analyze sticks at exactly that
/// coefficient and slips 1 % below, and verify agrees on both; the stability margin equals the
/// distance, computed here, from the centre of mass's projection to the nearest edge of the
/// feet's rectangle.
#[test]
fn solo12_on_slopes_reports_required_mu_and_margin() {
    let dir = env!("CARGO_MANIFEST_DIR");
    for alpha in [0.0f64, 0.1, 0.2, 0.3] {
        let opts = ImportOptions {
            floating_base: true,
            gravity: nalgebra::Vector3::new(-9.81 * alpha.sin(), 0.0, -9.81 * alpha.cos()),
            ..Default::default()
        };
        let path = format!("{dir}/robots/solo12/solo12_ground.urdf");
        let m = restpose::urdf::load_file(std::path::Path::new(&path), &opts)
            .unwrap()
            .model;
        let (s, r) = restpose::solve(&m, &stick(10.0)).unwrap();
        assert!(r.converged(), "{alpha}: {:?}", r.termination);
        let need = r.friction.as_ref().unwrap().required_mu;
        assert!(need > 0.0 && need < 1.0, "{alpha}: {need}");
        for (mu, slipping) in [(need, false), (0.99 * need, true)] {
            let (s2, r2) = restpose::solve(&m, &stick(mu)).unwrap();
            assert_eq!(r2.friction.unwrap().slipping, slipping, "{alpha} {mu}");
            let v = verify_with_options(&m, &s2, &Tolerances::default(), &unilaterals(mu)).unwrap();
            assert_eq!(
                v.passed, !slipping,
                "{alpha} {mu}: {:?}",
                v.unilateral.failures
            );
        }
        let b = r.balance.unwrap();
        assert_eq!(b.support_polygon.len(), 4);
        // Gravity is in the x-z plane: the projection keeps y, and the polygon's edges are
        // the feet's x and y extremes in the projected plane.
        let down = m.gravity().normalize();
        let e1 = nalgebra::Vector3::y().cross(&down).normalize();
        let flat = |p: [f64; 3]| {
            let p = nalgebra::Vector3::from(p);
            (p.dot(&e1), p.y)
        };
        let feet: Vec<(f64, f64)> = r.contacts.iter().map(|c| flat(c.point_world)).collect();
        let (cx, cy) = flat(b.centre_of_mass);
        let xmin = feet.iter().map(|f| f.0).fold(f64::MAX, f64::min);
        let xmax = feet.iter().map(|f| f.0).fold(f64::MIN, f64::max);
        let ymin = feet.iter().map(|f| f.1).fold(f64::MAX, f64::min);
        let ymax = feet.iter().map(|f| f.1).fold(f64::MIN, f64::max);
        let expect = (cx - xmin).min(xmax - cx).min(cy - ymin).min(ymax - cy);
        // The feet form a rectangle only to the solve's accuracy.
        assert!(
            (b.stability_margin - expect).abs() < 1e-6,
            "{alpha}: {} vs {expect}",
            b.stability_margin
        );
        let _ = s;
    }
}
