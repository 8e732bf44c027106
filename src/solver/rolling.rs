//! Sticking spheres roll. A sticking contact is held at the material point that touched
//! (module `constraints::unilateral`). When the active-set search stops with a sphere turned by
//! `ψ` (the rotation vector of `A Aₒᵀ`, `Aₒ` the body's rotation at the first touch `a₀`) so that
//! another of its points touches, the anchor moves to that material point `s − ρ Aᵀ n` and to
//! the world point
//!
//! `a = a₀ + ρ ψ × n`
//!
//! where rolling without slip from the first touch brings it (`ċ = ω × ρ n` integrated for a
//! rotation about a fixed axis), and the round is solved again; it stops when no anchor moves by
//! more than `gap_tolerance · L`. At the answer the friction force acts at the touching point
//! with no slip there, as MuJoCo's condim-3 contact, and the pose is the rolling model's.

use super::options::Options;
use crate::constraints::unilateral::{self, Active, Unilateral};
use crate::model::Model;
use nalgebra::{DVector, Vector3};

/// Re-anchorings of rolling sticking contacts before the search gives up.
pub(crate) const MAX_ROLLS: usize = 50;

/// Moves the anchors of the sticking contacts with a radius to the material point touching now
/// and to `a₀ + ρ ψ × n` (module docs), when either moved by more than the gap tolerance;
/// returns whether any moved.
pub(crate) fn reanchor(
    model: &Model,
    options: &Options,
    active: &mut [Active],
    touched: &[Touch],
    q: &DVector<f64>,
) -> bool {
    let mut moved = false;
    for a in active.iter_mut() {
        let (Some(old), Unilateral::Contact { point, ground }) = (a.anchor, a.row) else {
            continue;
        };
        let c = &model.contact_points[point];
        let Some(first) = touched.iter().find(|t| t.row == a.row) else {
            continue;
        };
        if c.radius == 0.0 {
            continue;
        }
        let (_, n) = unilateral::surface(model, ground, &unilateral::point_world(model, point, q));
        let rot = body_rotation(c.body, q);
        // Rolling from the first touch by the rotation vector ψ moves the touching point by
        // ρ ψ × n along the ground.
        let psi = nalgebra::Rotation3::from_matrix_unchecked(rot * first.rotation.transpose())
            .scaled_axis();
        let anchor = unilateral::Anchor {
            world: first.world + psi.cross(&n) * c.radius,
            body: c.point - rot.transpose() * n * c.radius,
        };
        let tol = options.gap_tolerance * model.length_scale;
        if (anchor.body - old.body).norm() > tol || (anchor.world - old.world).norm() > tol {
            a.anchor = Some(anchor);
            moved = true;
        }
    }
    moved
}

/// Where and how a sticking sphere first touched: the world point, and the body's rotation.
pub(crate) struct Touch {
    row: Unilateral,
    world: Vector3<f64>,
    rotation: nalgebra::Matrix3<f64>,
}

/// The rotation matrix of body `body` at `q`.
fn body_rotation(body: crate::model::BodyId, q: &DVector<f64>) -> nalgebra::Matrix3<f64> {
    let i = 7 * body.0;
    crate::math::rotation(&nalgebra::Vector4::new(
        q[i + 3],
        q[i + 4],
        q[i + 5],
        q[i + 6],
    ))
}

/// Records the first touch of the sticking contacts among `active` not yet recorded (module
/// docs: the sphere then rolls from there).
pub(crate) fn record_touches(
    model: &Model,
    active: &[Active],
    q: &DVector<f64>,
    touched: &mut Vec<Touch>,
) {
    touched.retain(|t| active.iter().any(|a| a.row == t.row));
    for a in active {
        let (Some(anchor), Unilateral::Contact { point, .. }) = (a.anchor, a.row) else {
            continue;
        };
        if !touched.iter().any(|t| t.row == a.row) {
            touched.push(Touch {
                row: a.row,
                world: anchor.world,
                rotation: body_rotation(model.contact_points[point].body, q),
            });
        }
    }
}
