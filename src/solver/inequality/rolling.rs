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

use crate::constraints::unilateral::{self, Active, Unilateral};
use crate::model::Model;
use crate::solver::options::Options;
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
        let psi = crate::math::rotation_vector(&(rot * first.rotation.transpose()));
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

/// How far a sticking sphere may roll within one round: its touching material point moves at
/// most `ROLL_LIMIT · ρ` on the sphere from the anchor's (about `ROLL_LIMIT` rad of rolling).
///
/// Within a round the anchor's material point is held where it touched, so the sphere pivots
/// about it rather than rolls: its centre moves by `ρ sin φ` where rolling moves it by `ρ φ`,
/// and near `φ = π/2` the tangential rows lose their rank in the rotation (the held point is
/// on the sphere's side). Cutting the round at this limit (a guarded inequality, module
/// `active_set`) and re-anchoring keeps each round within `ρ (φ − sin φ) ≤ 0.003 ρ` of rolling
/// and away from that singularity; the re-anchorings then converge to the rolling rest.
pub(crate) const ROLL_LIMIT: f64 = 0.25;

/// The roll limit of one sticking sphere (module docs of [`ROLL_LIMIT`]).
pub(crate) struct RollLimit {
    point: usize,
    ground: usize,
    /// The anchor's material point (body frame).
    anchored: Vector3<f64>,
}

/// The roll limits of the sticking spheres (radius > 0) among `active`.
pub(crate) fn limits(model: &Model, active: &[Active]) -> Vec<RollLimit> {
    active
        .iter()
        .filter_map(|a| match (a.anchor, a.row) {
            (Some(anchor), Unilateral::Contact { point, ground })
                if model.contact_points[point].radius > 0.0 =>
            {
                Some(RollLimit {
                    point,
                    ground,
                    anchored: anchor.body,
                })
            }
            _ => None,
        })
        .collect()
}

impl RollLimit {
    /// `(ROLL_LIMIT ρ − |s(q) − s_a|) / L`: `s(q)` the material point touching at `q`, `s_a`
    /// the anchor's, `L` the characteristic length; negative past the limit.
    pub(crate) fn margin(&self, model: &Model, q: &DVector<f64>) -> f64 {
        let c = &model.contact_points[self.point];
        let x = unilateral::point_world(model, self.point, q);
        let (_, n) = unilateral::surface(model, self.ground, &x);
        let touching = c.point - body_rotation(c.body, q).transpose() * n * c.radius;
        (ROLL_LIMIT * c.radius - (touching - self.anchored).norm()) / model.length_scale
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Friction;
    use crate::urdf::{load_str, ImportOptions};

    /// A sticking ball (ρ = 0.02 m) whose body turned by 1e-9 rad since it first touched, its
    /// Euler parameters 1e-12 off the unit sphere (the normalization row holds to the
    /// constraint tolerance, not exactly): rolling moves its touching point by ρ · 1e-9 m, far
    /// below the gap tolerance, so it is not re-anchored, and a turn of 0.01 rad is (by
    /// `ρ ψ × n` within 1e-15 m). The rotation vector was read as `acos` of the trace, a turn
    /// of ~2e-6 rad, which moved the anchor 4e-8 m: on the Spirit 40 lying on its legs the
    /// toes' redundant tangential rows then contradicted the thighs' by 9.5e-9 m ("inconsistent
    /// over-constrained model").
    #[test]
    fn a_ball_that_did_not_roll_keeps_its_anchor() {
        let text = r#"<robot name="ball" xmlns:mech="urn:urdf-mech:1">
  <link name="ball"><inertial><mass value="1"/><inertia ixx="1e-4" ixy="0" ixz="0" iyy="1e-4" iyz="0" izz="1e-4"/></inertial>
    <collision><geometry><sphere radius="0.02"/></geometry></collision></link>
  <mech:ground xyz="0 0 -0.02"/>
</robot>"#;
        let options = ImportOptions {
            floating_base: true,
            ..Default::default()
        };
        let model = load_str(text, "ball.urdf", &options).unwrap().model;
        let opts = Options {
            friction: Friction::Stick,
            ..Default::default()
        };
        let q0 = crate::State::initial(&model).q;
        let u = super::super::active_set::inequalities(&model, &opts)[0];
        let mut active = vec![super::super::active_set::activate(&model, &opts, u, &q0)];
        let first = active[0].anchor.unwrap();
        let mut touched = Vec::new();
        record_touches(&model, &active, &q0, &mut touched);
        let turned = |angle: f64, scale: f64| {
            let turn = crate::math::euler_parameters(&nalgebra::UnitQuaternion::from_scaled_axis(
                Vector3::y() * angle,
            ));
            let p = crate::math::compose(&turn, &q0.fixed_rows::<4>(3).into_owned()) * scale;
            let mut q = q0.clone();
            q.fixed_rows_mut::<4>(3).copy_from(&p);
            q
        };
        for scale in [1.0 + 1e-12, 1.0 - 1e-12] {
            let q = turned(1e-9, scale);
            assert!(
                !reanchor(&model, &opts, &mut active, &touched, &q),
                "{scale}"
            );
            assert_eq!(active[0].anchor.unwrap(), first);
        }
        let q = turned(0.01, 1.0 + 1e-12);
        assert!(reanchor(&model, &opts, &mut active, &touched, &q));
        let moved = active[0].anchor.unwrap().world - first.world;
        assert!(
            (moved - Vector3::x() * 0.02 * 0.01).norm() < 1e-15,
            "{moved}"
        );
    }
}
