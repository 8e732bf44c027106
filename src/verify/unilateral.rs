//! Stops and contacts at a given pose: which inequalities touch, the forces that balance the
//! pose on them, their signs and the friction they need.
//!
//! Every inequality `g_k(q) ≥ 0` of the model (module `constraints::unilateral`: joint stops,
//! contact points against the grounds) is evaluated at the pose. With `ε` the constraint
//! tolerance (on `‖D Φ‖∞`: below, `g_k` is the gap scaled as its row, a gap in m divided by
//! the characteristic length):
//! - `g_k < −ε`: the pose goes through a stop or into a ground, and fails;
//! - `|g_k| ≤ ε`: the inequality touches and may carry a force `λ_k ≥ 0` (a stop's effort, a
//!   contact's normal force). A sticking contact also carries a tangential force `f_t`, through
//!   the point where it touches (the rows `t_i·x_c(q)`, `x_c` the material point of the shape
//!   at the touching point, `t_1, t_2` a basis of the ground plane);
//! - `g_k > ε`: no force.
//!
//! The forces `λ` come from module `held`, with the joint efforts and reactions (the same on
//! the dense and the sparse path); this module finds the touching rows and reports them. A
//! normal force below `−τ` (`τ` the effort tolerance) would pull: the row is named, carries
//! nothing, and what it would have carried is left to the joint efforts, so a pose the stops
//! and contacts cannot hold fails there.
//!
//! Complementarity `g_k λ_k = 0` holds to `|g_k λ_k| ≤ ε λ_k` by construction (only touching
//! rows carry force); its largest value is reported. A sticking contact with a friction
//! coefficient `μ` (its link's `mech:contact mu`, else `--mu`) fails when `|f_t| > μ f_n`.

use crate::constraints::unilateral::{self, Active, Anchor, Unilateral};
use crate::jet::pair_of;
use crate::model::Model;
use crate::solver::friction;
use crate::solver::{ActiveLimit, Contact, ContactPolicy, ContactState, FrictionVerdict};
use crate::state::State;
use nalgebra::Vector3;

/// How `verify` treats stops and contacts: the solver's [`ContactPolicy`] (the same choices
/// as `analyze`'s options; a sticking contact needing more than its `mu` fails the pose).
pub type Unilaterals = ContactPolicy;

/// What the stops and contacts do at the pose.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct UnilateralCheck {
    /// Contacts touching (or penetrating) a ground, with the forces that balance the pose.
    pub contacts: Vec<Contact>,
    /// Joints on (or beyond) one of their stops, with the stop's effort.
    pub active_limits: Vec<ActiveLimit>,
    /// The largest violation `max(0, −g_k)` of any inequality \[m or rad\].
    pub penetration: f64,
    /// The same scaled as its row (a gap in m divided by the characteristic length): what
    /// the constraint tolerance bounds.
    #[serde(skip)]
    pub(crate) scaled_penetration: f64,
    /// The largest `|g_k λ_k|` of the touching inequalities \[J\].
    pub complementarity: f64,
    /// Why the pose fails (empty when it passes): points inside a ground or joints beyond a
    /// stop, stops or contacts that would have to pull, slipping contacts, the constraint
    /// residual, each joint effort beyond the tolerance (largest first), the unassigned force.
    pub failures: Vec<String>,
    /// The friction verdict, with sticking contacts (module `solver::friction`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub friction: Option<FrictionVerdict>,
}

impl UnilateralCheck {
    /// Whether the stops and contacts hold the pose given that the rest of the balance passed
    /// (`balanced`): nothing beyond `eps` through a stop or a ground, no contact slipping. The
    /// rows that would have had to pull are not a failure when the pose passes without them.
    pub(super) fn settle(&mut self, eps: f64, balanced: bool) -> bool {
        let holds = self.scaled_penetration <= eps
            && self
                .contacts
                .iter()
                .all(|c| c.state != ContactState::Slipping)
            && !self.friction.as_ref().is_some_and(|f| f.slipping);
        if balanced && holds {
            self.failures.retain(|f| !f.contains("would have to pull"));
        }
        holds
    }
}

/// A touching inequality: its rows as jets over its bodies' coordinates (`g`, then the
/// tangential rows of a sticking contact).
pub(super) struct Touching {
    pub(super) active: Active,
    pub(super) gap: f64,
    pub(super) mu: Option<f64>,
    pub(super) bodies: [Option<crate::model::BodyId>; 2],
    pub(super) rows: Vec<crate::jet::Scalar>,
}

impl Touching {
    /// `∇` of row `k` into `g` times `c` (unscaled coordinates).
    pub(super) fn add_gradient(&self, k: usize, c: f64, g: &mut nalgebra::DVector<f64>) {
        crate::jet::scatter(&self.bodies, &self.rows[k], c, g, None);
    }
}

/// The touching inequalities at `state`, the violations recorded in `out`.
pub(super) fn touching(
    model: &Model,
    state: &State,
    opts: &Unilaterals,
    eps: f64,
    out: &mut UnilateralCheck,
) -> Vec<Touching> {
    let mut list = Vec::new();
    for u in unilateral::inequalities(model, opts.enforces_limits()) {
        let Some(g) = unilateral::gap(model, &u, &state.q, &state.branches) else {
            continue;
        };
        // The gap scaled as its row (module `solver::system::residual`).
        let scaled = g / model.length_scale.powi(unilateral::length_power(model, &u));
        if scaled > eps {
            continue;
        }
        let what = unilateral::name(model, &u);
        if scaled < -eps {
            out.penetration = out.penetration.max(-g);
            out.scaled_penetration = out.scaled_penetration.max(-scaled);
            out.failures.push(match u {
                Unilateral::Limit { .. } => {
                    format!("`{what}`: the joint is beyond its stop by {:.3e}", -g)
                }
                Unilateral::Contact { .. } => {
                    format!("`{what}`: the point is {:.3e} m inside the ground", -g)
                }
            });
        }
        let (anchor, mu) = match u {
            Unilateral::Contact { point, ground } => {
                let c = &model.contact_points[point];
                let stick = opts.sticks(&c.settings);
                let anchor = stick.then(|| {
                    let x = unilateral::point_world(model, point, &state.q);
                    let (_, normal) = unilateral::surface(model, ground, &x);
                    let i = 7 * c.body.0;
                    let p = nalgebra::Vector4::new(
                        state.q[i + 3],
                        state.q[i + 4],
                        state.q[i + 5],
                        state.q[i + 6],
                    );
                    let a = crate::math::rotation(&p);
                    Anchor {
                        world: x - normal * c.radius,
                        body: c.point - a.transpose() * normal * c.radius,
                    }
                });
                (anchor, opts.mu_of(&c.settings).filter(|_| stick))
            }
            Unilateral::Limit { .. } => (None, None),
        };
        let active = Active { row: u, anchor };
        let bodies = unilateral::bodies(model, &u);
        let pair = pair_of(&bodies, &state.q, false);
        let Some(rows) = unilateral::rows(model, &active, &pair, &state.branches) else {
            continue;
        };
        list.push(Touching {
            active,
            gap: g,
            mu,
            bodies,
            rows,
        });
    }
    list
}

/// Reports the touching inequalities `list` with their `forces` (module `held`) into `out`:
/// the contacts and stops, the complementarity, the rows that would have to pull (`pulling`:
/// index and force) and the friction each sticking contact needs. Returns the inequalities
/// that carry a force (`λ > tau`: the stability's tangent space) and those that touch without
/// one (its critical cone).
pub(super) fn report(
    model: &Model,
    state: &State,
    list: &[Touching],
    forces: &[Vec<f64>],
    pulling_rows: &[(usize, f64)],
    chosen: crate::solver::friction::Chosen,
    tau: f64,
    out: &mut UnilateralCheck,
) -> (Vec<Active>, Vec<Active>) {
    let (mut strong, mut weak) = (Vec::new(), Vec::new());
    let mut sticking = Vec::new();
    for (t, lambda) in list.iter().zip(forces) {
        if lambda[0] > tau {
            strong.push(t.active);
        } else {
            weak.push(t.active);
        }
        out.complementarity = out.complementarity.max((t.gap * lambda[0]).abs());
        sticking.extend(describe(model, state, t, lambda, tau, out));
    }
    for &(i, f) in pulling_rows {
        out.failures.push(pulling(model, &list[i].active.row, f));
    }
    // The verdict of the cone feasibility problem (module `solver::friction`), the same
    // routine `analyze` calls: slipping only when no forces inside the cones balance the pose.
    out.friction = friction::verdict(&sticking, chosen);
    friction::settle_states(&mut out.contacts, out.friction.as_ref());
    if let Some(v) = out.friction.as_ref().filter(|v| v.slipping) {
        out.failures.push(super::friction::slipping(v));
    }
    (strong, weak)
}

/// The failure of a stop or contact `u` that would have to pull with `force` to hold the pose.
fn pulling(model: &Model, u: &Unilateral, force: f64) -> String {
    format!(
        "`{}` would have to pull ({:.3e} {}) to hold the pose",
        unilateral::name(model, u),
        force,
        if unilateral::length_power(model, u) == 0 {
            "N m"
        } else {
            "N"
        }
    )
}

/// Adds the contact or stop `t` with its forces `lambda` to `out`; returns, for a sticking
/// contact, the friction coefficient it needs and the one it has.
fn describe(
    model: &Model,
    state: &State,
    t: &Touching,
    lambda: &[f64],
    tau: f64,
    out: &mut UnilateralCheck,
) -> Option<(f64, Option<f64>)> {
    match t.active.row {
        Unilateral::Limit {
            joint,
            bound,
            value,
        } => {
            let (effort_limit, exceeds_effort_limit) =
                friction::effort_check(model, joint, lambda[0]);
            out.active_limits.push(ActiveLimit {
                joint: model.joints[joint.0].name.clone(),
                bound: bound.name().into(),
                value,
                effort: match bound {
                    unilateral::Bound::Lower => lambda[0],
                    unilateral::Bound::Upper => -lambda[0],
                },
                effort_limit,
                exceeds_effort_limit,
            });
            None
        }
        Unilateral::Contact { point, ground } => {
            let c = &model.contact_points[point];
            let x = unilateral::point_world(model, point, &state.q);
            let (_, normal) = unilateral::surface(model, ground, &x);
            let mut ft = Vector3::zeros();
            if t.active.anchor.is_some() {
                let [t1, t2] = unilateral::tangents(&normal);
                ft = t1 * lambda[1] + t2 * lambda[2];
            }
            let fnorm = lambda[0];
            let required =
                friction::needs_mu(fnorm, if ft.norm() <= tau { 0.0 } else { ft.norm() });
            let state_ = match (t.active.anchor, t.mu) {
                (None, _) => ContactState::Touching,
                (Some(_), Some(mu)) if friction::slips(required, mu) => ContactState::Slipping,
                (Some(_), _) => ContactState::Sticking,
            };
            let x = x - normal * c.radius;
            out.contacts.push(Contact {
                link: c.link.clone(),
                ground: unilateral::surface_name(model, ground).to_string(),
                point_world: x.into(),
                normal_world: normal.into(),
                gap: t.gap,
                normal_force: fnorm,
                tangential_force: ft.into(),
                required_friction: required,
                state: state_,
            });
            t.active.anchor.map(|_| (required, t.mu))
        }
    }
}
