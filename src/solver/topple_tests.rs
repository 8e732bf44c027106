use super::*;
use crate::model::Friction;
use crate::urdf::{load_str, ImportOptions};

fn sticking() -> Options {
    Options {
        friction: Friction::Stick,
        ..Default::default()
    }
}

/// A floating link made of spheres of radius `radius` at `centres`, its centre of mass at
/// `com`, on the ground z = 0, placed by the ground start.
fn body(centres: &[[f64; 3]], radius: f64, com: [f64; 3]) -> (Model, DVector<f64>) {
    let spheres: String = centres
        .iter()
        .map(|c| {
            format!(
                r#"<collision><origin xyz="{} {} {}"/><geometry><sphere radius="{radius}"/></geometry></collision>"#,
                c[0], c[1], c[2]
            )
        })
        .collect();
    let text = format!(
        r#"<robot name="r"><link name="b"><inertial><origin xyz="{} {} {}"/><mass value="2"/>
  <inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>{spheres}</link></robot>"#,
        com[0], com[1], com[2]
    );
    let options = ImportOptions {
        floating_base: true,
        ground: true,
        ..Default::default()
    };
    let model = load_str(&text, "r.urdf", &options).unwrap().model;
    let start = crate::solver::assemble::grounded_start(&model, crate::State::initial(&model));
    (model, start.q)
}

/// An octagonal prism (circumradius 0.1 m, vertices at ±0.05 m along y, a face down) with its
/// centre of mass 0.08 m to the side of its axis, at the axis's height: its support, the
/// bottom face's half-width 0.1 sin(π/8) = 0.0383 m, does not hold it. It rolls over one edge
/// (the centre of mass then 0.08 cos(π/4) = 0.0566 m out) and a second, 2 steps of π/4, until
/// the centre of mass is straight below the axis; the energy falls at each step, by the
/// closed form `m g Δh`.
#[test]
fn an_octagon_rolls_two_faces_and_the_energy_falls_at_each() {
    use std::f64::consts::PI;
    let mut centres = Vec::new();
    for k in 0..8 {
        let t = PI / 8.0 + k as f64 * PI / 4.0;
        for y in [-0.05, 0.05] {
            centres.push([0.1 * t.cos(), y, 0.1 * t.sin()]);
        }
    }
    let (model, mut q) = body(&centres, 0.0, [0.08, 0.0, 0.0]);
    let paths = paths(&model, &mut q, &sticking());
    assert_eq!(paths.len(), 1);
    let path = &paths[0];
    assert_eq!(path.toppled.steps, 2, "{:?}", path.toppled);
    assert!((path.toppled.angle - PI / 2.0).abs() < 1e-12);
    assert!(path.toppled.stopped.is_none());
    for w in path.energies.windows(2) {
        assert!(w[1] < w[0], "{:?}", path.energies);
    }
    // The axis at the apothem 0.1 cos(π/8) above the ground throughout; the centre of mass
    // from the axis's height to 0.08 m below it.
    let g = 2.0 * 9.81;
    let released = g * 0.08;
    assert!(
        (path.toppled.energy_released - released).abs() < 1e-12,
        "{} {released}",
        path.toppled.energy_released
    );
    let first = g * 0.08 * (PI / 4.0).sin();
    assert!((path.energies[0] - path.energies[1] - first).abs() < 1e-12);
    assert!((path.toppled.com_outside - (0.08 - 0.1 * (PI / 8.0).sin())).abs() < 1e-12);
}

/// Random clouds of equal spheres under a random centre of mass, on their ground start: every
/// topple lowers the energy at each step, ends with the centre of mass over the support and
/// no sphere in the ground.
#[test]
fn random_bodies_topple_downhill_onto_a_support_that_holds_them() {
    let mut rng = crate::lcg::Lcg::new(21);
    let mut toppled = 0;
    for case in 0..200 {
        let n = 3 + case % 12;
        let centres: Vec<[f64; 3]> = (0..n)
            .map(|_| [0.3 * rng.signed(), 0.3 * rng.signed(), 0.3 * rng.signed()])
            .collect();
        let com = [0.3 * rng.signed(), 0.3 * rng.signed(), 0.3 * rng.signed()];
        let radius = if case % 2 == 0 { 0.0 } else { 0.01 };
        let (model, mut q) = body(&centres, radius, com);
        let paths = paths(&model, &mut q, &sticking());
        let Some(path) = paths.first() else { continue };
        toppled += 1;
        assert!(
            path.toppled.stopped.is_none(),
            "case {case}: {:?}",
            path.toppled
        );
        for w in path.energies.windows(2) {
            assert!(w[1] < w[0], "case {case}: {:?}", path.energies);
        }
        for k in 0..model.contact_points.len() {
            let x = crate::constraints::unilateral::point_world(&model, k, &q);
            assert!(
                x.z - radius >= -1e-12,
                "case {case}: point {k} at {}",
                x.z - radius
            );
        }
        // Toppled again, it stands.
        assert!(
            super::paths(&model, &mut q.clone(), &sticking()).is_empty(),
            "case {case}"
        );
    }
    assert!(toppled > 100, "{toppled} of 200 toppled");
}

/// Frictionless contacts, `--topple off` or a centre of mass over the support: no topple.
#[test]
fn nothing_topples_without_friction_when_off_or_when_it_stands() {
    let corners: Vec<[f64; 3]> = [[-0.1, -0.1], [0.1, -0.1], [0.1, 0.1], [-0.1, 0.1]]
        .iter()
        .map(|c| [c[0], c[1], 0.0])
        .collect();
    let (model, q) = body(&corners, 0.0, [0.3, 0.0, 0.1]);
    assert_eq!(paths(&model, &mut q.clone(), &sticking()).len(), 1);
    assert!(paths(&model, &mut q.clone(), &Options::default()).is_empty());
    let off = Options {
        topple: super::super::options::Topple::Off,
        ..sticking()
    };
    assert!(paths(&model, &mut q.clone(), &off).is_empty());
    let (model, q) = body(&corners, 0.0, [0.1, 0.05, 0.1]);
    assert!(paths(&model, &mut q.clone(), &sticking()).is_empty());
}

#[test]
fn the_landing_angle_is_the_first_descending_root() {
    // h = 0.5 + 0.5 cos θ − sin θ: h(0) = 1, descending.
    let t = landing(0.5, 0.5, -1.0).unwrap();
    assert!((0.5 + 0.5 * t.cos() - t.sin()).abs() < 1e-14);
    assert!(t > 0.0 && t < std::f64::consts::PI);
    // A point that rises as it leaves the ground lands again only beyond π.
    assert!(landing(0.1, 0.0, 1.0).is_none());
    assert!((landing(0.0, 0.0, 1.0).unwrap() - std::f64::consts::PI).abs() < 1e-15);
    // Out of reach.
    assert!(landing(2.0, 1.0, 0.0).is_none());
}
