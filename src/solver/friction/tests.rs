//! Tests of module `friction` on rigid bodies whose contact wrenches are written here:
//! closed forms (a body on a slope, a ladder against a wall) and an independent solution of
//! the same problem (bisection on `μ` of a linear program over many-sided pyramids). The
//! linear program is the integration tests' oracle, `tests/it/common/pyramid.rs` (phase 1 of
//! the simplex method, each answer certified by its final basis or a Farkas vector), shared
//! here so that one implementation answers both; these tests need the crate's private
//! `Support`, so they stay unit tests.

use super::*;
use nalgebra::{DMatrix, Vector3};

/// The shared oracle (its rigid-body helpers are the integration tests').
#[allow(dead_code)]
#[path = "../../../tests/it/common/pyramid.rs"]
mod pyramid;

/// A contact of a rigid body: point, unit normal, whether it sticks.
struct Touch {
    p: Vector3<f64>,
    n: Vector3<f64>,
    stick: bool,
}

/// An orthonormal tangent basis of `n`.
fn tangents(n: &Vector3<f64>) -> [Vector3<f64>; 2] {
    let a = if n.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let t1 = n.cross(&a).normalize();
    [t1, n.cross(&t1)]
}

/// The wrench columns `[d; p × d]` of each force row, and the support of a body of weight
/// `w` (gravity `−w ẑ` rotated by `tilt` about y) at its origin on `touches`.
fn support(touches: &[Touch], w: f64, tilt: f64, mu: Option<f64>) -> (DMatrix<f64>, Support) {
    let mut cols = Vec::new();
    let mut holders = Vec::new();
    let mut mus = Vec::new();
    for t in touches {
        holders.push((
            cols.len(),
            if t.stick {
                Holder::Stick { c: Some(1.0) }
            } else {
                Holder::Smooth
            },
        ));
        mus.push(if t.stick { mu } else { None });
        let mut dirs = vec![t.n];
        if t.stick {
            dirs.extend(tangents(&t.n));
        }
        for d in dirs {
            let m = t.p.cross(&d);
            cols.push(DVector::from_vec(vec![d.x, d.y, d.z, m.x, m.y, m.z]));
        }
    }
    let g = DMatrix::from_columns(&cols);
    let weight = Vector3::new(-w * tilt.sin(), 0.0, -w * tilt.cos());
    let rhs = DVector::from_vec(vec![-weight.x, -weight.y, -weight.z, 0.0, 0.0, 0.0]);
    // By the guarded decompositions: `G` is wide and rank deficient, nalgebra's own SVD and
    // symmetric eigendecomposition can be wrong there (modules `solver::svd`, `eigen`).
    let svd = crate::solver::svd::svd(g.clone(), true, true).unwrap();
    let base = svd.solve(&rhs, 1e-12).unwrap();
    assert!((&g * &base - &rhs).amax() <= 1e-9 * rhs.amax().max(1.0));
    let (values, vectors) = crate::solver::eigen::symmetric_eigen(&(g.transpose() * &g));
    let top = values.amax();
    let null: Vec<DVector<f64>> = (0..g.ncols())
        .filter(|&i| values[i] <= 1e-10 * top)
        .map(|i| vectors.column(i).into_owned())
        .collect();
    let k = g.ncols();
    // Contacts with one normal are on one plane ground (module `friction::shortcut`).
    let plane = touches
        .iter()
        .map(|t| touches.iter().position(|u| u.n == t.n))
        .collect();
    let s = Support {
        plane,
        base,
        null: if null.is_empty() {
            DMatrix::zeros(k, 0)
        } else {
            DMatrix::from_columns(&null)
        },
        holders,
        mu: mus,
        weight: vec![1.0; k],
    };
    (g, s)
}

/// Whether forces inside `sides`-sided pyramids of half-aperture `mu` (edges on the cone of
/// `mu`: inscribed) balance the body; `None` where the oracle cannot certify either answer
/// (within rounding of the boundary).
fn pyramid_feasible(g: &DMatrix<f64>, s: &Support, mu: f64, sides: usize) -> Option<bool> {
    // Variables: per sticking contact `sides` edge weights, per smooth one its normal force.
    let rhs = g * &s.base;
    let mut cols = Vec::new();
    for &(first, h) in &s.holders {
        let n = g.column(first).into_owned();
        match h {
            Holder::Stick { .. } => {
                let (t1, t2) = (g.column(first + 1), g.column(first + 2));
                for j in 0..sides {
                    let a = std::f64::consts::TAU * j as f64 / sides as f64;
                    cols.push(&n + (t1 * a.cos() + t2 * a.sin()) * mu);
                }
            }
            _ => cols.push(n),
        }
    }
    pyramid::lp_feasible(&DMatrix::from_columns(&cols), &rhs)
}

/// The smallest `mu` for which the pyramids balance the body, by bisection (as the oracle's
/// `least_mu`): the upper end of the bracket, feasible.
fn pyramid_mu(g: &DMatrix<f64>, s: &Support, sides: usize) -> f64 {
    let (mut lo, mut hi) = (0.0, 4.0);
    for _ in 0..40 {
        let mid = 0.5 * (lo + hi);
        match pyramid_feasible(g, s, mid, sides) {
            Some(true) => hi = mid,
            Some(false) => lo = mid,
            None => break,
        }
    }
    assert!(
        hi - lo < 1e-6,
        "bracket [{lo}, {hi}] not certified narrower"
    );
    hi
}

/// A 0.5 × 0.4 box's four bottom corners, the centre of mass `h` above their plane and
/// shifted by `dx`.
fn box_corners(h: f64, dx: f64, stick: bool) -> Vec<Touch> {
    [(-0.25, -0.2), (0.25, -0.2), (-0.25, 0.2), (0.25, 0.2)]
        .iter()
        .map(|&(x, y)| Touch {
            p: Vector3::new(x - dx, y, -h),
            n: Vector3::z(),
            stick,
        })
        .collect()
}

/// A box on a slope of `α` (gravity tilted by `α`): `required_mu = tan α`, and the pyramid
/// bisection brackets it (inscribed pyramids need more, circumscribed less).
#[test]
fn a_box_on_a_slope_needs_tan_alpha() {
    for alpha in [0.0, 0.1, 0.2, 0.35] {
        let (g, s) = support(&box_corners(0.15, 0.03, true), 15.7, alpha, Some(0.5));
        let d = distribute(&s, 15.7).unwrap();
        let need = d.required_mu.unwrap();
        let tan = f64::tan(alpha);
        assert!(
            (need - tan).abs() <= 1e-9 * tan.max(1.0),
            "{alpha}: {need} vs {tan}"
        );
        assert_eq!(d.slipping, slips(tan, 0.5));
        // Balanced: G λ = G λ₀.
        assert!((&g * &d.forces - &g * &s.base).amax() < 1e-9);
        let sides = 64;
        let inscribed = pyramid_mu(&g, &s, sides);
        let circumscribed = inscribed * (std::f64::consts::PI / sides as f64).cos();
        assert!(
            need <= inscribed + 1e-8 && need >= circumscribed - 1e-8,
            "{need} {inscribed}"
        );
        if alpha == 0.0 {
            // A level floor: no friction at all, m g / 4 per corner by symmetry... of the
            // least-norm distribution.
            for &(first, _) in &s.holders {
                assert!(d.forces[first + 1].abs() + d.forces[first + 2].abs() < 1e-9);
            }
        }
    }
}

/// A uniform ladder of length 2 at angle β to the floor, its feet at `y = ±0.2` on the floor
/// and its top against a wall (normal −x). Friction at the floor only: `μ = cot β / 2`; at
/// both ends: `tan β = (1 − μ²) / (2 μ)`, `μ = sec β − tan β`.
#[test]
fn a_ladder_against_a_wall() {
    for beta in [1.0f64, 1.2, 1.35] {
        let (c, s_) = (beta.cos(), beta.sin());
        // Origin at the ladder's middle (its centre of mass).
        let foot = Vector3::new(-c, 0.0, -s_);
        let top = Vector3::new(c, 0.0, s_);
        let make = |wall_sticks: bool| {
            let mut t = Vec::new();
            for y in [-0.2, 0.2] {
                t.push(Touch {
                    p: foot + Vector3::new(0.0, y, 0.0),
                    n: Vector3::z(),
                    stick: true,
                });
                t.push(Touch {
                    p: top + Vector3::new(0.0, y, 0.0),
                    n: -Vector3::x(),
                    stick: wall_sticks,
                });
            }
            t
        };
        let (g, s) = support(&make(false), 100.0, 0.0, None);
        let need = distribute(&s, 100.0).unwrap().required_mu.unwrap();
        let expect = 0.5 / beta.tan();
        assert!((need - expect).abs() < 1e-9, "{beta}: {need} vs {expect}");
        let inscribed = pyramid_mu(&g, &s, 64);
        assert!(
            need <= inscribed + 1e-8 && inscribed < need * 1.002,
            "{need} {inscribed}"
        );
        let (g, s) = support(&make(true), 100.0, 0.0, None);
        let need = distribute(&s, 100.0).unwrap().required_mu.unwrap();
        let expect = 1.0 / beta.cos() - beta.tan();
        assert!((need - expect).abs() < 1e-9, "{beta}: {need} vs {expect}");
        let inscribed = pyramid_mu(&g, &s, 64);
        assert!(
            need <= inscribed + 1e-8 && inscribed < need * 1.002,
            "{need} {inscribed}"
        );
    }
}

/// The verdict at a given `μ`: sticking from `required_mu` on (to `10⁻⁹`), slipping below;
/// the forces reported when slipping are the least-friction ones.
#[test]
fn slips_exactly_below_required_mu() {
    let alpha = 0.35f64;
    let tan = alpha.tan();
    for (mu, slipping) in [
        (tan, false),
        (tan + 1e-9, false),
        (tan - 1e-8, true),
        (0.2, true),
    ] {
        let (_, s) = support(&box_corners(0.15, -0.05, true), 15.7, alpha, Some(mu));
        let d = distribute(&s, 15.7).unwrap();
        assert_eq!(d.slipping, slipping, "{mu}");
    }
    // Different coefficients: the corners needing more may rely on the others.
    let (_, mut s) = support(&box_corners(0.15, 0.0, true), 15.7, alpha, None);
    s.mu = vec![Some(0.3), Some(0.3), Some(0.6), Some(0.6)];
    let d = distribute(&s, 15.7).unwrap();
    assert!(!d.slipping, "{d:?}");
    s.mu = vec![Some(0.3), Some(0.3), Some(0.3), Some(0.3)];
    assert!(distribute(&s, 15.7).unwrap().slipping);
}

/// A contact that would have to pull: no distribution.
#[test]
fn no_distribution_when_a_contact_must_pull() {
    // The centre of mass outside the corners (shifted by 0.4 m).
    let (_, s) = support(&box_corners(0.15, 0.4, false), 10.0, 0.0, None);
    assert!(distribute(&s, 10.0).is_none());
}

/// The closed form of module `friction::shortcut` (the least-norm distribution at the lower
/// bound `‖F_t‖ / F_n`) gives what the cone programs alone give on the box on slopes: the
/// same `required_mu` (1e-9) and forces (1e-5 of the weight: the cone path's least-norm
/// choice has a slack of 1e-6 on the bound).
#[test]
fn shortcuts_agree_with_the_cone_programs() {
    for alpha in [0.0, 0.1, 0.35] {
        for dx in [0.0, 0.03] {
            let (_, s) = support(&box_corners(0.15, dx, true), 15.7, alpha, Some(0.5));
            let fast = distribute(&s, 15.7).unwrap();
            // The cone programs alone: least need, then least norm within it.
            let ones = vec![Some(1.0); 4];
            let (need, z) = least_need(&s, &ones, 15.7).unwrap();
            let forces = least_norm(&s, &ones, need, &at(&s, &z), 15.7);
            let a = fast.required_mu.unwrap();
            assert!((a - need).abs() <= 1e-9, "{alpha} {dx}: {a} vs {need}");
            assert!(
                (&fast.forces - &forces).amax() <= 1e-5 * 15.7,
                "{alpha} {dx}: {} vs {}",
                fast.forces,
                forces
            );
            // Every loaded corner's force parallel to gravity: each needs tan α exactly.
            for &(first, _) in &s.holders {
                let t = fast.forces[first + 1].hypot(fast.forces[first + 2]);
                assert!((t - f64::tan(alpha) * fast.forces[first]).abs() < 1e-12 * 15.7);
            }
            assert_eq!(fast.slipping, slips(need, 0.5));
        }
    }
    // The lower bound of a box on one ground is tan α; none for the ladder (its floor's total
    // force depends on the wall's share).
    let (_, s) = support(&box_corners(0.15, 0.03, true), 15.7, 0.2, None);
    let b = crate::solver::friction::shortcut::lower_bound(&s)
        .unwrap()
        .0;
    assert!((b - f64::tan(0.2)).abs() < 1e-12, "{b}");
}

/// Two contacts (the distributions a line: the squeeze between them): no pushing distribution
/// when the centre of mass lies beyond one of them, decided by intervals as by the cone
/// program.
#[test]
fn nothing_pushes_on_a_line_as_the_cone_program_says() {
    for (dx, expect) in [(0.0, false), (0.1, false), (0.4, true), (-0.3, true)] {
        let touches: Vec<Touch> = [-0.25, 0.25]
            .iter()
            .map(|&x| Touch {
                p: Vector3::new(x - dx, 0.0, -0.15),
                n: Vector3::z(),
                stick: true,
            })
            .collect();
        let (_, s) = support(&touches, 10.0, 0.0, None);
        assert_eq!(s.null.ncols(), 1);
        let fast = crate::solver::friction::shortcut::nothing_pushes_on_a_line(&s, 10.0);
        let ones = vec![Some(1.0); 2];
        let cone = least_need(&s, &ones, 10.0).is_none();
        assert_eq!((fast, cone), (expect, expect), "{dx}");
    }
}
