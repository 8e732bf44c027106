//! Will it stand? (issue 22) Legged robots with rigid legs on slopes: `required_mu = tan α`
//! where the feet can share the load along gravity, the stability margin against the support
//! polygon computed here, and an independent solution of the same cone problem.
//!
//! Why `tan α`: the contact forces `f_i = n_i ν + t_i` (ν the ground's normal) balance the
//! weight, `Σ f_i = −m g`, so `Σ n_i = m |g| cos α` and `|Σ t_i| = m |g| sin α`, and every
//! distribution needs `max_i |t_i| / n_i ≥ Σ |t_i| / Σ n_i ≥ tan α`. With every joint locked
//! the robot is one rigid body; when the centre of mass projects along gravity inside the
//! feet's polygon, the projection is a convex combination `Σ w_i p_i` of the feet's
//! projections, and the forces `f_i = −w_i m g` (parallel to gravity) balance force and
//! moment about the centre of mass, each needing exactly `tan α`. So `required_mu = tan α`.
use crate::common::contact::verify_with_options;
use crate::common::pyramid::{least_mu, Touch};
use nalgebra::Vector3;
use restpose::model::Friction;
use restpose::urdf::{load_file, load_str, ImportOptions};
use restpose::verify::{Tolerances, Unilaterals};
use restpose::Options;

fn stick(mu: f64) -> Options {
    Options {
        friction: Friction::Stick,
        mu: Some(mu),
        ..Default::default()
    }
}

fn unilaterals(mu: f64) -> Unilaterals {
    Unilaterals {
        friction: Friction::Stick,
        mu: Some(mu),
        ..Default::default()
    }
}

fn tilted(alpha: f64) -> Vector3<f64> {
    Vector3::new(-9.81 * alpha.sin(), 0.0, -9.81 * alpha.cos())
}

/// The centre of mass of `model` at `state`, from the bodies' masses and poses.
fn centre_of_mass(model: &restpose::Model, state: &restpose::State) -> (Vector3<f64>, f64) {
    let (mut sum, mut mass) = (Vector3::zeros(), 0.0);
    for id in model.body_ids() {
        let b = &model.bodies()[id.index()];
        sum += b.mass * (state.body_pose(id) * nalgebra::Point3::from(b.com)).coords;
        mass += b.mass;
    }
    (sum / mass, mass)
}

/// Signed distance of `p` to the convex polygon `poly` (counter-clockwise), positive inside.
fn signed_distance(poly: &[(f64, f64)], p: (f64, f64)) -> f64 {
    let mut d = f64::MAX;
    let mut inside = true;
    for i in 0..poly.len() {
        let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
        let (ex, ey) = (b.0 - a.0, b.1 - a.1);
        let t = (((p.0 - a.0) * ex + (p.1 - a.1) * ey) / (ex * ex + ey * ey)).clamp(0.0, 1.0);
        d = d.min((p.0 - a.0 - t * ex).hypot(p.1 - a.1 - t * ey));
        inside &= ex * (p.1 - a.1) - ey * (p.0 - a.0) >= 0.0;
    }
    if inside {
        d
    } else {
        -d
    }
}

/// The Solo-12 of `robots/solo12` with its 12 joints locked in the published
/// `straight_standing` state (rigid legs), sticking feet, on slopes of 0, 0.1, 0.2, 0.3 rad
/// (gravity tilted about y): `required_mu = tan α` (1e-9; module docs), and a 64-sided pyramid
/// bisection on the same rigid body (the feet where restpose put them, the centre of mass
/// computed here) brackets it; the stability margin equals the signed distance, computed
/// here, of the centre of mass projected along gravity to the feet's polygon (1e-9 m);
/// analyze and verify stick at `tan α` and slip 1e-8 below it.
#[test]
fn a_locked_solo12_on_slopes_needs_tan_alpha() {
    let path = format!(
        "{}/robots/solo12/solo12_ground.urdf",
        env!("CARGO_MANIFEST_DIR")
    );
    let mut locks = Vec::new();
    for leg in ["FL", "FR", "HL", "HR"] {
        let s = if leg.starts_with('F') { 1.0 } else { -1.0 };
        locks.push((format!("{leg}_HAA"), 0, Some(0.0)));
        locks.push((format!("{leg}_HFE"), 0, Some(0.8 * s)));
        locks.push((format!("{leg}_KFE"), 0, Some(-1.6 * s)));
    }
    for alpha in [0.0f64, 0.1, 0.2, 0.3] {
        let opts = ImportOptions {
            floating_base: true,
            gravity: tilted(alpha),
            locks: locks.clone(),
            ..Default::default()
        };
        let m = load_file(std::path::Path::new(&path), &opts).unwrap().model;
        let tan = alpha.tan();
        let (s, r) = restpose::solve(&m, &stick(1.0)).unwrap();
        assert!(r.converged(), "{alpha}: {:?}", r.termination);
        assert_eq!(r.contacts.len(), 4, "{alpha}");
        let need = r.friction.as_ref().unwrap().required_mu;
        assert!((need - tan).abs() <= 1e-9, "{alpha}: {need} vs {tan}");

        // The centre of mass and the polygon, computed here.
        let (com, mass) = centre_of_mass(&m, &s);
        let b = r.balance.clone().unwrap();
        assert!(
            (com - Vector3::from(b.centre_of_mass)).amax() < 1e-12,
            "{alpha}"
        );
        let down = m.gravity().normalize();
        let e1 = Vector3::y().cross(&down).normalize();
        let e2 = down.cross(&e1);
        let flat = |p: &Vector3<f64>| (p.dot(&e1), p.dot(&e2));
        let feet: Vec<Vector3<f64>> = r
            .contacts
            .iter()
            .map(|c| Vector3::from(c.point_world))
            .collect();
        // The four feet, counter-clockwise seen against gravity (e1 × e2 = down).
        let mut poly: Vec<(f64, f64)> = feet.iter().map(flat).collect();
        let (cx, cy) = (
            poly.iter().map(|p| p.0).sum::<f64>() / 4.0,
            poly.iter().map(|p| p.1).sum::<f64>() / 4.0,
        );
        poly.sort_by(|a, b| {
            (a.1 - cy)
                .atan2(a.0 - cx)
                .total_cmp(&(b.1 - cy).atan2(b.0 - cx))
        });
        let margin = signed_distance(&poly, flat(&com));
        assert!(margin > 0.05, "{alpha}: {margin}");
        assert!(
            (b.stability_margin - margin).abs() < 1e-9,
            "{alpha}: {} vs {margin}",
            b.stability_margin
        );

        // The same cone problem solved independently: inscribed and circumscribed pyramids.
        let touches: Vec<Touch> = r
            .contacts
            .iter()
            .map(|c| Touch {
                p: Vector3::from(c.point_world),
                n: Vector3::from(c.normal_world),
            })
            .collect();
        let sides = 64;
        let (lo, inscribed) = least_mu(&touches, &com, &(mass * m.gravity()), sides);
        assert!(inscribed - lo < 1e-9, "{alpha}: [{lo}, {inscribed}]");
        let circumscribed = inscribed * (std::f64::consts::PI / sides as f64).cos();
        assert!(
            need <= inscribed + 1e-8 && need >= circumscribed - 1e-8,
            "{alpha}: {need} not in [{circumscribed}, {inscribed}]"
        );

        // Sticks at tan α, slips just below; verify agrees.
        for (mu, slipping) in [(tan, false), (tan - 1e-8, true)] {
            if mu < 0.0 {
                continue;
            }
            let (s2, r2) = restpose::solve(&m, &stick(mu)).unwrap();
            assert_eq!(r2.friction.unwrap().slipping, slipping, "{alpha} {mu}");
            let v = verify_with_options(&m, &s2, &Tolerances::default(), &unilaterals(mu)).unwrap();
            assert_eq!(
                v.passed, !slipping,
                "{alpha} {mu}: {:?}",
                v.unilateral.failures
            );
        }
    }
}

/// A rigid table on four sphere feet, the fourth 1e-11 m higher than the others (below the
/// gap tolerance, so the four touch): its sticking contacts are 12 rows on 6 coordinates, the
/// redundant ones consistent only to 1e-11 m. It stands (this stopped in the assembly with
/// "inconsistent over-constrained model" when the redundant rows had to hold to the solver's
/// tolerance instead of the redundant rows' floor), the four feet carry the weight, and on a
/// slope of 0.2 rad it needs `tan α`, as verify agrees with its default tolerances.
#[test]
fn a_table_whose_feet_touch_within_the_gap_tolerance_stands() {
    for alpha in [0.0f64, 0.2] {
        let text = r#"<robot name="table" xmlns:mech="urn:urdf-mech:1">
  <link name="table">
    <inertial><origin xyz="0.01 0.02 0"/><mass value="3"/><inertia ixx="0.02" iyy="0.03" izz="0.04" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0.2 0.15 -0.1"/><geometry><sphere radius="0.02"/></geometry></collision>
    <collision><origin xyz="-0.2 0.15 -0.1"/><geometry><sphere radius="0.02"/></geometry></collision>
    <collision><origin xyz="0.2 -0.15 -0.1"/><geometry><sphere radius="0.02"/></geometry></collision>
    <collision><origin xyz="-0.2 -0.15 -0.09999999999"/><geometry><sphere radius="0.02"/></geometry></collision>
  </link>
  <mech:ground normal="0 0 1" xyz="0 0 -0.12"/>
</robot>"#;
        let opts = ImportOptions {
            floating_base: true,
            gravity: tilted(alpha),
            ..Default::default()
        };
        let m = load_str(text, "table.urdf", &opts).unwrap().model;
        let (s, r) = restpose::solve(&m, &stick(0.5)).unwrap();
        assert!(r.converged(), "{alpha}: {:?}", r.termination);
        assert_eq!(r.contacts.len(), 4, "{alpha}: {:?}", r.contacts);
        let total: f64 = r.contacts.iter().map(|c| c.normal_force).sum();
        assert!((total - 3.0 * 9.81 * alpha.cos()).abs() < 1e-9, "{total}");
        assert!(
            r.contacts.iter().all(|c| c.normal_force > 1.0),
            "{:?}",
            r.contacts
        );
        let need = r.friction.unwrap().required_mu;
        assert!((need - alpha.tan()).abs() < 1e-9, "{alpha}: {need}");
        // verify's defaults: a contact touches within the solver's gap tolerance (1e-9), the
        // band in which the active set took the fourth foot as touching.
        let v = verify_with_options(&m, &s, &Tolerances::default(), &unilaterals(0.5)).unwrap();
        assert!(v.passed, "{alpha}: {:?}", v.unilateral.failures);
    }
}
