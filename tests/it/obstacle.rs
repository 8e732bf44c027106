//! Obstacles of every collision shape (issue 13): a ball on a fixed cylinder, a box on a
//! fixed mesh (its convex hull) and a box held by friction on a tilted fixed box, each against
//! a closed form and `verify`.
use crate::common::contact::{assert_sticks_on_slope, assert_verified_contacts};
use crate::common::*;
use approx::assert_abs_diff_eq;
use nalgebra::Vector3;
use restpose::model::Friction;
use restpose::solver::ContactState;
use restpose::urdf::{load_file, ImportOptions};
use restpose::verify::{verify_with_options, Tolerances, Unilaterals};
use restpose::{Options, State};

/// A 1 kg ball (radius 0.1 m) at the end of a massless 0.5 m arm hinged about y at the
/// origin falls onto a world-fixed cylinder (radius 0.2 m, 1 m long) lying on its side along y,
/// its axis through `(0.6, ·, −0.4)`. Closed form: the ball's centre `b = 0.5 (cos θ, 0, −sin θ)`
/// touches when `|b − a| = 0.3` (`a` the axis point), `0.6 cos θ + 0.4 sin θ = 0.68`, the
/// smaller root; the contact point is `a + 0.2 n`, `n = (b − a)/0.3`, and moments about the
/// hinge give `f_n (b_x n_z − b_z n_x) = m g b_x`.
#[test]
fn a_ball_rests_on_a_fixed_cylinder_lying_on_its_side() {
    let m = model_from(
        r#"<robot name="ball_on_cylinder" xmlns:mech="urn:urdf-mech:1">
  <link name="world"/>
  <link name="log">
    <collision><origin xyz="0.6 0 -0.4" rpy="1.5707963267948966 0 0"/><geometry><cylinder radius="0.2" length="1"/></geometry></collision>
  </link>
  <joint name="mount" type="fixed"><parent link="world"/><child link="log"/></joint>
  <link name="arm">
    <inertial><origin xyz="0.5 0 0"/><mass value="1"/><inertia ixx="0.004" iyy="0.004" izz="0.004" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0.5 0 0"/><geometry><sphere radius="0.1"/></geometry></collision>
  </link>
  <joint name="pivot" type="continuous"><parent link="world"/><child link="arm"/><axis xyz="0 1 0"/></joint>
  <mech:obstacle link="log"/>
  <mech:contact link="arm"/>
</robot>"#,
    );
    let (s, r) = solve(&m);
    // 0.6 cos θ + 0.4 sin θ = A cos(θ − φ).
    let (amp, phi) = (0.52f64.sqrt(), 0.4f64.atan2(0.6));
    let theta = phi - (0.68 / amp).acos();
    let th = s.joint(&m, "pivot").unwrap()[0];
    assert_abs_diff_eq!(th, theta, epsilon = 1e-9);
    let a = Vector3::new(0.6, 0.0, -0.4);
    let b = Vector3::new(0.5 * theta.cos(), 0.0, -0.5 * theta.sin());
    let n = (b - a) / 0.3;
    assert_eq!(r.contacts.len(), 1, "{:?}", r.contacts);
    let c = &r.contacts[0];
    assert_eq!(c.ground, "log");
    let p = Vector3::from(c.point_world);
    assert!((p - (a + n * 0.2)).norm() < 1e-9, "{p:?}");
    assert!((Vector3::from(c.normal_world) - n).norm() < 1e-9);
    let f = 9.81 * b.x / (b.x * n.z - b.z * n.x);
    assert_abs_diff_eq!(c.normal_force, f, epsilon = 1e-8);
    assert_abs_diff_eq!(r.energy.total, 9.81 * b.z, epsilon = 1e-8);
    assert_verified_contacts(&m, &s, Friction::None);
    // Pushed into the cylinder, verify refuses it.
    let deeper = State::from_joint_values(&m, &[("pivot".to_string(), vec![th + 0.004])].into());
    let uni = Unilaterals::default();
    let v = verify_with_options(&m, &deeper, &Tolerances::default(), &uni).unwrap();
    assert!(!v.passed && v.unilateral.penetration > 5e-4, "{v:?}");
}

/// A table mesh (OBJ: a 1 × 1 × 0.05 m top at `z = 0.7…0.75` on four 0.05 m square legs),
/// not convex; its convex hull is the box `[−0.5, 0.5]² × [0, 0.75]`.
fn write_table(dir: &std::path::Path) -> std::path::PathBuf {
    let mut obj = String::new();
    let mut faces = String::new();
    let mut n = 0;
    let mut cuboid = |lo: [f64; 3], hi: [f64; 3]| {
        for k in 0..8 {
            let pick = |i: usize, bit: usize| if k & bit == 0 { lo[i] } else { hi[i] };
            obj += &format!("v {} {} {}\n", pick(0, 1), pick(1, 2), pick(2, 4));
        }
        // Two triangles a side, vertices numbered from 1.
        for q in [
            [0, 2, 3, 1],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 4, 6, 2],
            [1, 3, 7, 5],
        ] {
            let v = |i: usize| n + q[i] + 1;
            faces += &format!(
                "f {} {} {}\nf {} {} {}\n",
                v(0),
                v(1),
                v(2),
                v(0),
                v(2),
                v(3)
            );
        }
        n += 8;
    };
    cuboid([-0.5, -0.5, 0.7], [0.5, 0.5, 0.75]);
    for (x, y) in [(-0.5, -0.5), (0.45, -0.5), (-0.5, 0.45), (0.45, 0.45)] {
        cuboid([x, y, 0.0], [x + 0.05, y + 0.05, 0.7]);
    }
    let path = dir.join("table.obj");
    std::fs::write(&path, obj + &faces).unwrap();
    path
}

/// A floating 2 kg box (0.4 × 0.3 × 0.2 m) released tilted above the table mesh rests flat on
/// its top: four vertices carrying `m g / 4` each at `z = 0.75`, `V = m g (0.75 + 0.1)`.
#[test]
fn a_box_rests_on_a_fixed_mesh_obstacle() {
    let dir = tempfile::tempdir().unwrap();
    let table = write_table(dir.path());
    let urdf = dir.path().join("box_on_mesh.urdf");
    std::fs::write(
        &urdf,
        format!(
            r#"<robot name="box_on_mesh" xmlns:mech="urn:urdf-mech:1">
  <link name="world"/>
  <link name="table">
    <collision><geometry><mesh filename="file://{}"/></geometry></collision>
  </link>
  <joint name="table_mount" type="fixed"><parent link="world"/><child link="table"/></joint>
  <link name="box">
    <inertial><mass value="2"/><inertia ixx="0.02" iyy="0.03" izz="0.04" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.4 0.3 0.2"/></geometry></collision>
  </link>
  <joint name="free" type="floating"><parent link="world"/><child link="box"/></joint>
  <mech:obstacle link="table"/>
  <mech:contact link="box"/>
  <mech:initial joint="free" value="0.05 -0.02 1.0 0.9950 0.0600 -0.0500 0.0500"/>
</robot>"#,
            table.display()
        ),
    )
    .unwrap();
    let m = load_file(&urdf, &ImportOptions::default()).unwrap().model;
    assert_eq!(m.obstacles().len(), 1);
    let (s, r) = solve(&m);
    let mg = 2.0 * 9.81;
    assert_abs_diff_eq!(r.energy.total, mg * 0.85, epsilon = mg * 1e-9);
    assert_eq!(r.contacts.len(), 4, "{:?}", r.contacts);
    for c in &r.contacts {
        assert_eq!(c.ground, "table");
        assert_abs_diff_eq!(c.normal_force, mg / 4.0, epsilon = 1e-8);
        assert_abs_diff_eq!(c.point_world[2], 0.75, epsilon = 1e-9);
        assert!((Vector3::from(c.normal_world) - Vector3::z()).norm() < 1e-12);
    }
    assert_verified_contacts(&m, &s, Friction::None);
}

/// A 1 kg box (0.4 × 0.3 × 0.2 m) on a fixed 2 × 2 × 0.2 m box tilted by `tilt` about y.
fn on_tilted_box(tilt: f64) -> restpose::Model {
    let n = Vector3::new(tilt.sin(), 0.0, tilt.cos());
    let at = n * 0.21;
    model_from(&format!(
        r#"<robot name="box_on_tilted_box" xmlns:mech="urn:urdf-mech:1">
  <link name="world"/>
  <link name="ramp">
    <collision><origin rpy="0 {tilt} 0"/><geometry><box size="2 2 0.2"/></geometry></collision>
  </link>
  <joint name="ramp_mount" type="fixed"><parent link="world"/><child link="ramp"/></joint>
  <link name="box">
    <inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.4 0.3 0.2"/></geometry></collision>
  </link>
  <joint name="free" type="floating"><parent link="world"/><child link="box"/></joint>
  <mech:obstacle link="ramp"/>
  <mech:contact link="box"/>
  <mech:initial joint="free" value="{} 0 {} {} 0 {} 0"/>
</robot>"#,
        at.x,
        at.z,
        (tilt / 2.0).cos(),
        (tilt / 2.0).sin()
    ))
}

/// Sticking friction holds the box on the tilted obstacle: the obstacle's force balances the
/// weight, `Σ f_n = m g cos(tilt)`, `|Σ f_t| = m g sin(tilt)`, so the friction needed is
/// `tan(tilt)` (closed form); with `mu` below it a contact slips.
#[test]
fn friction_holds_a_box_on_a_tilted_fixed_box() {
    let tilt = 0.3f64;
    let m = on_tilted_box(tilt);
    let stick = Options {
        friction: Friction::Stick,
        ..Default::default()
    };
    let (s, r) = restpose::solve(&m, &stick).unwrap();
    assert_sticks_on_slope(&r, 9.81, tilt);
    for c in &r.contacts {
        assert_eq!(c.ground, "ramp");
        let n = Vector3::from(c.normal_world);
        assert!((n - Vector3::new(tilt.sin(), 0.0, tilt.cos())).norm() < 1e-12);
    }
    assert_verified_contacts(&m, &s, Friction::Stick);
    let weak = Options {
        mu: Some(0.8 * tilt.tan()),
        ..stick.clone()
    };
    let (_, r) = restpose::solve(&m, &weak).unwrap();
    assert!(
        r.contacts.iter().any(|c| c.state == ContactState::Slipping),
        "{:?}",
        r.contacts
    );
    let enough = Options {
        mu: Some(1.2 * tilt.tan()),
        ..stick
    };
    let (_, r) = restpose::solve(&m, &enough).unwrap();
    assert!(r.converged(), "{:?}", r.termination);
    assert!(r.contacts.iter().all(|c| c.state == ContactState::Sticking));
}

/// A flat mesh (one square) has no volume to rest on: the import refuses it, naming the file,
/// the line of `mech:obstacle`, the link and the mesh.
#[test]
fn a_flat_mesh_obstacle_is_refused_with_its_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let flat = dir.path().join("flat.obj");
    std::fs::write(
        &flat,
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\n",
    )
    .unwrap();
    let urdf = dir.path().join("flat.urdf");
    std::fs::write(
        &urdf,
        format!(
            r#"<robot name="flat" xmlns:mech="urn:urdf-mech:1">
  <link name="world"/>
  <link name="sheet">
    <collision><geometry><mesh filename="file://{}"/></geometry></collision>
  </link>
  <joint name="mount" type="fixed"><parent link="world"/><child link="sheet"/></joint>
  <mech:obstacle link="sheet"/>
</robot>"#,
            flat.display()
        ),
    )
    .unwrap();
    let Err(e) = load_file(&urdf, &ImportOptions::default()) else {
        panic!("a flat obstacle is refused");
    };
    let e = e.to_string();
    for want in ["flat.urdf", ":7", "sheet", "flat.obj", "no volume"] {
        assert!(e.contains(want), "`{want}` not in: {e}");
    }
}

/// The ball of the cylinder test on a two-axis arm (`swing` about x, with a torsion spring,
/// then `pivot` about y), started swung out by 0.2 rad, lands on a fixed sphere (radius 0.2 m,
/// centre `(0.6, 0, −0.4)`) and slides around it back to `swing = 0`: the rest of the
/// cylinder test (same closed form, `0.6 cos θ + 0.4 sin θ = 0.68`). Sliding on the sphere is
/// a motion along its curved surface: with the sphere's curvature in the gap's Hessian
/// (module `model::curvature`) Newton converges quadratically (it was linear, ratio 0.32, and
/// 17 iterations, without it).
#[test]
fn a_ball_slides_around_a_fixed_sphere_with_newton_convergence() {
    let m = model_from(
        r#"<robot name="ball_on_sphere" xmlns:mech="urn:urdf-mech:1">
  <link name="world"/>
  <link name="rock">
    <collision><origin xyz="0.6 0 -0.4"/><geometry><sphere radius="0.2"/></geometry></collision>
  </link>
  <joint name="mount" type="fixed"><parent link="world"/><child link="rock"/></joint>
  <link name="yoke"/>
  <joint name="swing" type="continuous"><parent link="world"/><child link="yoke"/><axis xyz="1 0 0"/></joint>
  <link name="arm">
    <inertial><origin xyz="0.5 0 0"/><mass value="1"/><inertia ixx="0.004" iyy="0.004" izz="0.004" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0.5 0 0"/><geometry><sphere radius="0.1"/></geometry></collision>
  </link>
  <joint name="pivot" type="continuous"><parent link="yoke"/><child link="arm"/><axis xyz="0 1 0"/></joint>
  <mech:obstacle link="rock"/>
  <mech:contact link="arm"/>
  <mech:initial joint="swing" value="0.2"/>
  <mech:joint_spring joint="swing" stiffness="2"/>
</robot>"#,
    );
    let (s, r) = solve(&m);
    let (amp, phi) = (0.52f64.sqrt(), 0.4f64.atan2(0.6));
    let theta = phi - (0.68 / amp).acos();
    assert_abs_diff_eq!(s.joint(&m, "pivot").unwrap()[0], theta, epsilon = 1e-9);
    assert_abs_diff_eq!(s.joint(&m, "swing").unwrap()[0], 0.0, epsilon = 1e-9);
    assert_eq!(r.contacts.len(), 1, "{:?}", r.contacts);
    let a = Vector3::new(0.6, 0.0, -0.4);
    let b = Vector3::new(0.5 * theta.cos(), 0.0, -0.5 * theta.sin());
    let n = (b - a) / 0.3;
    let f = 9.81 * b.x / (b.x * n.z - b.z * n.x);
    assert_abs_diff_eq!(r.contacts[0].normal_force, f, epsilon = 1e-8);
    assert_verified_contacts(&m, &s, Friction::None);
    // Quadratic convergence: once below 0.1 J, each gradient is below the square of the one
    // before (linear convergence at ratio 0.32 gives 2.6e3 · g² near 1e-4 J).
    let g: Vec<f64> = r.history.iter().map(|h| h.gradient_norm).collect();
    for w in g.windows(2).filter(|w| w[0] < 0.1) {
        assert!(w[1] <= w[0] * w[0], "{g:?}");
    }
    assert!(r.iterations <= 6, "{} iterations: {g:?}", r.iterations);
}
