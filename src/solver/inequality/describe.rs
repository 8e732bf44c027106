//! The report's stops and contacts at the end of the active-set iteration (module
//! `active_set`): each active row's multiplier as a stop's effort or a contact's normal and
//! tangential force, its required friction and state (touching, sticking, slipping).

use super::active_set::{force_scale, touch_point};
use crate::constraints::unilateral::{self, Active, Unilateral};
use crate::model::Model;
use crate::solver::options::Options;
use nalgebra::Vector3;

/// Fills the report's `contacts` and `active_limits` from the multipliers of the active rows;
/// returns each sticking contact's need and coefficient.
pub(super) fn describe(
    model: &Model,
    options: &Options,
    state: &crate::State,
    multipliers: &[(Active, Vec<f64>)],
    report: &mut crate::solver::Report,
) -> Vec<(f64, Option<f64>)> {
    let mut sticking = Vec::new();
    use crate::solver::report::{ActiveLimit, Contact, ContactState};
    let tiny = 1e-12 * force_scale(model);
    for (a, m) in multipliers {
        match a.row {
            Unilateral::Limit {
                joint,
                bound,
                value,
            } => {
                let effort = match bound {
                    unilateral::Bound::Lower => m[0],
                    unilateral::Bound::Upper => -m[0],
                };
                let (effort_limit, exceeds_effort_limit) =
                    crate::solver::friction::effort_check(model, joint, effort);
                report.active_limits.push(ActiveLimit {
                    joint: model.joints[joint.0].name.clone(),
                    bound: bound.name().into(),
                    value,
                    effort,
                    effort_limit,
                    exceeds_effort_limit,
                })
            }
            Unilateral::Contact { point, ground } => {
                let c = &model.contact_points[point];
                let x = unilateral::point_world(model, point, &state.q);
                let (_, normal) = unilateral::surface(model, ground, &x);
                let gap = unilateral::gap(model, &a.row, &state.q, &state.branches).unwrap_or(0.0);
                let mut ft = Vector3::zeros();
                if a.anchor.is_some() {
                    let [t1, t2] = unilateral::tangents(&normal);
                    ft = t1 * m[1] + t2 * m[2];
                }
                let fnorm = m[0];
                let required = crate::solver::friction::needs_mu(
                    fnorm,
                    if ft.norm() <= tiny { 0.0 } else { ft.norm() },
                );
                let mu = options.contact().mu_of(&c.settings);
                let contact_state = match (a.anchor, mu) {
                    (None, _) => ContactState::Touching,
                    (Some(_), Some(mu)) if crate::solver::friction::slips(required, mu) => {
                        ContactState::Slipping
                    }
                    (Some(_), _) => ContactState::Sticking,
                };
                if a.anchor.is_some() {
                    sticking.push((required, mu));
                }
                let p = touch_point(model, a, &state.q).unwrap_or_default();
                report.contacts.push(Contact {
                    link: c.link.clone(),
                    ground: unilateral::surface_name(model, ground).to_string(),
                    point_world: p.into(),
                    normal_world: normal.into(),
                    gap,
                    normal_force: fnorm,
                    tangential_force: ft.into(),
                    required_friction: required,
                    state: contact_state,
                });
            }
        }
    }
    sticking
}
