//! Stops and contacts at a given pose: which inequalities touch, the forces that balance the
//! pose on them, their signs and the friction they need.
//!
//! Every inequality `g_k(q) ≥ 0` of the model (module `constraints::unilateral`: joint stops,
//! contact points against the grounds) is evaluated at the pose. With `ε` the constraint
//! tolerance (m or rad):
//! - `g_k < −ε`: the pose goes through a stop or into a ground, and fails;
//! - `|g_k| ≤ ε`: the inequality touches and may carry a force `λ_k ≥ 0` (a stop's effort, a
//!   contact's normal force). A sticking contact also carries a tangential force `f_t`, through
//!   the point where it touches (the rows `t_i·x_c(q)`, `x_c` the material point of the shape
//!   at the touching point, `t_1, t_2` a basis of the ground plane);
//! - `g_k > ε`: no force.
//!
//! With `N` the orthonormal basis of the feasible motions of the equality rows (module docs of
//! `verify`), `S` the coordinate scaling and `G` the gradients of the touching rows, the forces
//! solve the least-squares balance
//!
//! `min ‖Nᵀ S (∇V − G λ)‖₂` subject to `λ_k ≥ 0` on the normal rows,
//!
//! (columns of `Nᵀ S G` normalized to unit length). The unconstrained minimum-norm solution is
//! taken when its normal forces are all ≥ `−τ` (`τ` the effort tolerance): it is the minimum-
//! norm force distribution of a statically indeterminate support (a box flat on four vertices
//! gets `m g / 4` on each). Otherwise the forces come from a non-negative least-squares solve
//! (Lawson–Hanson), and the rows whose unconstrained force was negative are named: the pose
//! would need them to pull. What the forces leave, `Nᵀ S (∇V − G λ)`, goes to the joint
//! imbalance check as before, so a pose the stops and contacts cannot hold fails there.
//!
//! That balance is the dense path's; the sparse path computes the forces from the solver's
//! sparse partition instead (module `unilateral_sparse`) and shares the rest of this module
//! (which rows touch, the report, the friction check).
//!
//! Complementarity `g_k λ_k = 0` holds to `|g_k λ_k| ≤ ε λ_k` by construction (only touching
//! rows carry force); its largest value is reported. A sticking contact with a friction
//! coefficient `μ` (its link's `mech:contact mu`, else `--mu`) fails when `|f_t| > μ f_n`.
//!
//! ## References
//! - C. L. Lawson, R. J. Hanson, *Solving Least Squares Problems*, SIAM (1995), ch. 23
//!   (algorithm NNLS).

use crate::constraints::unilateral::{self, Active, Anchor, Unilateral};
use crate::jet::{pair_of, scatter};
use crate::model::{Friction, Model};
use crate::solver::friction;
use crate::solver::{ActiveLimit, Contact, ContactState, FrictionVerdict, Limits};
use crate::state::State;
use nalgebra::{DMatrix, DVector, Vector3};

/// How `verify` treats stops and contacts (the same choices as `analyze`'s options).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Unilaterals {
    /// URDF joint limits: enforced (a pose may rest on a stop, and may not go beyond one) or
    /// ignored.
    pub limits: Limits,
    /// Contacts without a friction setting in `mech:contact`: frictionless, or able to carry a
    /// tangential force (sticking).
    pub friction: Friction,
    /// Friction coefficient of sticking contacts without `mu` in `mech:contact`.
    pub mu: Option<f64>,
}

impl Default for Unilaterals {
    /// Limits enforced, frictionless, no coefficient (as `analyze`).
    fn default() -> Self {
        Unilaterals {
            limits: Limits::Enforce,
            friction: Friction::None,
            mu: None,
        }
    }
}

/// What the stops and contacts do at the pose.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct UnilateralCheck {
    /// Contacts touching (or penetrating) a ground, with the forces that balance the pose.
    pub contacts: Vec<Contact>,
    /// Joints on (or beyond) one of their stops, with the stop's effort.
    pub active_limits: Vec<ActiveLimit>,
    /// The largest violation `max(0, −g_k)` of any inequality \[m or rad\].
    pub penetration: f64,
    /// The largest `|g_k λ_k|` of the touching inequalities \[J\].
    pub complementarity: f64,
    /// Why the stops and contacts refuse the pose (empty when they do not).
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
        let holds = self.penetration <= eps
            && !self.friction.as_ref().is_some_and(|f| f.slipping)
            && self
                .contacts
                .iter()
                .all(|c| c.state != ContactState::Slipping);
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
    pub(super) fn add_gradient(&self, k: usize, c: f64, g: &mut DVector<f64>) {
        scatter(&self.bodies, &self.rows[k], c, g, None);
    }

    /// The scaled gradients `S ∇g` of its rows.
    fn columns(&self, n: usize, scale: &[f64]) -> Vec<DVector<f64>> {
        (0..self.rows.len())
            .map(|k| {
                let mut g = DVector::zeros(n);
                self.add_gradient(k, 1.0, &mut g);
                for (c, &f) in scale.iter().enumerate() {
                    g[c] *= f;
                }
                g
            })
            .collect()
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
    for u in unilateral::inequalities(model, opts.limits == Limits::Enforce) {
        let Some(g) = unilateral::gap(model, &u, &state.q, &state.branches) else {
            continue;
        };
        if g > eps {
            continue;
        }
        let what = unilateral::name(model, &u);
        if g < -eps {
            out.penetration = out.penetration.max(-g);
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
                let stick = c.settings.friction.unwrap_or(opts.friction) == Friction::Stick;
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
                (anchor, c.settings.mu.or(opts.mu).filter(|_| stick))
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

/// Minimizes `‖M x − b‖₂` subject to `x_i ≥ 0` for `signed[i]` (Lawson–Hanson, with the
/// unsigned variables always free). `M`'s columns are assumed normalized.
fn nnls(m: &DMatrix<f64>, b: &DVector<f64>, signed: &[bool]) -> DVector<f64> {
    let k = m.ncols();
    let solve_on = |passive: &[bool]| -> DVector<f64> {
        let idx: Vec<usize> = (0..k).filter(|&i| passive[i]).collect();
        let mut z = DVector::zeros(k);
        if idx.is_empty() {
            return z;
        }
        let sub = DMatrix::from_fn(m.nrows(), idx.len(), |r, c| m[(r, idx[c])]);
        let svd = sub.svd(true, true);
        let eps = 1e-12 * svd.singular_values.max().max(1e-300);
        if let Ok(s) = svd.solve(b, eps) {
            for (c, &i) in idx.iter().enumerate() {
                z[i] = s[c];
            }
        }
        z
    };
    let mut passive: Vec<bool> = signed.iter().map(|s| !s).collect();
    let mut x = solve_on(&passive);
    let tol = 1e-12 * b.amax().max(1e-300) * (k as f64);
    for _ in 0..(3 * k + 10) {
        let w = m.transpose() * (b - m * &x);
        let Some(j) = (0..k)
            .filter(|&i| !passive[i] && w[i] > tol)
            .max_by(|&a, &c| w[a].total_cmp(&w[c]))
        else {
            break;
        };
        passive[j] = true;
        for _ in 0..(3 * k + 10) {
            let z = solve_on(&passive);
            let blocking: Vec<usize> = (0..k)
                .filter(|&i| passive[i] && signed[i] && z[i] <= 0.0)
                .collect();
            if blocking.is_empty() {
                x = z;
                break;
            }
            let alpha = blocking
                .iter()
                .map(|&i| x[i] / (x[i] - z[i]).max(1e-300))
                .fold(1.0f64, f64::min);
            x += (&z - &x) * alpha;
            for i in 0..k {
                if passive[i] && signed[i] && x[i] <= 1e-15 * x.amax().max(1e-300) {
                    passive[i] = false;
                    x[i] = 0.0;
                }
            }
        }
    }
    x
}

/// Checks the stops and contacts at `state`: `p` holds the basis `N`, the scaled gradient
/// `S ∇V` and the scaling `S`; `eps` the constraint tolerance, `tau` the effort
/// tolerance. Returns the report and the scaled generalized force the touching rows carry
/// (`S G λ`), to be taken off `S ∇V` before the joint imbalance is computed, and the rows that
/// carry a force (the strongly active ones) and those that touch without one (weakly active).
pub(super) fn check(
    model: &Model,
    state: &State,
    opts: &Unilaterals,
    p: &super::dense::Projection,
    eps: f64,
    tau: f64,
) -> (UnilateralCheck, DVector<f64>, Vec<Active>, Vec<Active>) {
    let (null, grad_s, scale) = (&p.null, &p.grad_s, &p.scale[..]);
    let mut out = UnilateralCheck::default();
    let list = touching(model, state, opts, eps, &mut out);
    let n = state.q.len();
    let columns: Vec<Vec<DVector<f64>>> = list.iter().map(|t| t.columns(n, scale)).collect();
    let mut carried = DVector::zeros(n);
    if list.is_empty() {
        return (out, carried, Vec::new(), Vec::new());
    }
    // Columns of the balance, normalized; `signed` marks the normal rows.
    let mut cols = Vec::new();
    let mut signed = Vec::new();
    let mut norms = Vec::new();
    for t in &columns {
        for (r, c) in t.iter().enumerate() {
            let projected = null.transpose() * c;
            let len = projected.norm();
            norms.push(len);
            cols.push(if len > 0.0 {
                projected / len
            } else {
                projected
            });
            signed.push(r == 0);
        }
    }
    let rhs = null.transpose() * grad_s;
    let m = if null.ncols() > 0 {
        DMatrix::from_columns(&cols)
    } else {
        DMatrix::zeros(0, cols.len())
    };
    // Unconstrained minimum-norm solution first.
    let free = if m.nrows() > 0 {
        let svd = m.clone().svd(true, true);
        let e = 1e-10 * svd.singular_values.max().max(1e-300);
        svd.solve(&rhs, e)
            .unwrap_or_else(|_| DVector::zeros(cols.len()))
    } else {
        DVector::zeros(cols.len())
    };
    let unscale = |x: &DVector<f64>| -> DVector<f64> {
        DVector::from_fn(
            x.len(),
            |i, _| {
                if norms[i] > 0.0 {
                    x[i] / norms[i]
                } else {
                    0.0
                }
            },
        )
    };
    let free_forces = unscale(&free);
    let negative: Vec<usize> = (0..cols.len())
        .filter(|&i| signed[i] && free_forces[i] < -tau)
        .collect();
    // Every least-squares balance is `free + null(M) y`: module `solver::friction` picks the
    // distribution needing the least friction (then the least norm), as analyze does.
    let items: Vec<(Active, Option<f64>)> = list.iter().map(|t| (t.active, t.mu)).collect();
    let chosen = super::friction::distribution(model, &m, &free_forces, &norms, &items);
    let verdict = chosen.as_ref().map(|d| (d.required_mu, d.slipping));
    let negative = if chosen.is_some() {
        Vec::new()
    } else {
        negative
    };
    let forces = match chosen {
        Some(d) => d.forces,
        None if negative.is_empty() || m.nrows() == 0 => free_forces.clone(),
        None => unscale(&nnls(&m, &rhs, &signed)),
    };
    // The generalized force the rows carry, in scaled coordinates.
    let mut k = 0;
    let (mut strong, mut weak) = (Vec::new(), Vec::new());
    for (t, cols) in list.iter().zip(&columns) {
        let lambda: Vec<f64> = (0..cols.len()).map(|r| forces[k + r]).collect();
        for (r, c) in cols.iter().enumerate() {
            carried.axpy(lambda[r], c, 1.0);
        }
        if lambda[0] > tau {
            strong.push(t.active);
        } else {
            weak.push(t.active);
        }
        out.complementarity = out.complementarity.max((t.gap * lambda[0]).abs());
        describe(model, state, t, &lambda, tau, &mut out);
        k += cols.len();
    }
    let sticking: Vec<(f64, Option<f64>)> = list
        .iter()
        .filter(|t| matches!(t.active.row, Unilateral::Contact { .. }))
        .zip(&out.contacts)
        .filter(|(t, _)| t.active.anchor.is_some())
        .map(|(t, c)| (c.required_friction, t.mu))
        .collect();
    out.friction = friction::verdict(&sticking, verdict);
    friction::settle_states(&mut out.contacts, out.friction.as_ref());
    if let Some(v) = out.friction.as_ref().filter(|v| v.slipping) {
        out.failures.push(super::friction::slipping(v));
    }
    // Name the rows that would have to pull, for the failure message (only meaningful when
    // the non-negative forces then leave an imbalance: the caller decides).
    let mut k = 0;
    for t in &list {
        if negative.contains(&k) {
            out.failures
                .push(pulling(model, &t.active.row, free_forces[k]));
        }
        k += t.rows.len();
    }
    (out, carried, strong, weak)
}

/// The failure of a stop or contact `u` that would have to pull with `force` to hold the pose.
pub(super) fn pulling(model: &Model, u: &Unilateral, force: f64) -> String {
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

/// Adds the contact or stop `t` with its forces `lambda` to `out`, and a failure for a sticking
/// contact needing more than its friction coefficient.
pub(super) fn describe(
    model: &Model,
    state: &State,
    t: &Touching,
    lambda: &[f64],
    tau: f64,
    out: &mut UnilateralCheck,
) {
    match t.active.row {
        Unilateral::Limit {
            joint,
            bound,
            value,
        } => {
            let effort = match bound {
                unilateral::Bound::Lower => lambda[0],
                unilateral::Bound::Upper => -lambda[0],
            };
            let (effort_limit, exceeds_effort_limit) = friction::effort_check(model, joint, effort);
            out.active_limits.push(ActiveLimit {
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
            let mut ft = Vector3::zeros();
            if t.active.anchor.is_some() {
                let [t1, t2] = unilateral::tangents(&normal);
                ft = t1 * lambda[1] + t2 * lambda[2];
            }
            let fnorm = lambda[0];
            let tiny = 1e-12 * friction::force_scale(model);
            let required =
                friction::needs_mu(fnorm, if ft.norm() <= tiny { 0.0 } else { ft.norm() });
            let _ = tau;
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
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// NNLS against a case solved by hand: `b = (1, −1)` with `M = I` and `x ≥ 0` gives
    /// `x = (1, 0)`; the free variable takes its unconstrained value.
    #[test]
    fn nnls_clamps_only_the_signed_variables() {
        let m = DMatrix::identity(2, 2);
        let b = DVector::from_vec(vec![1.0, -1.0]);
        let x = nnls(&m, &b, &[true, true]);
        assert!((x[0] - 1.0).abs() < 1e-14 && x[1] == 0.0, "{x}");
        let x = nnls(&m, &b, &[true, false]);
        assert!(
            (x[0] - 1.0).abs() < 1e-14 && (x[1] + 1.0).abs() < 1e-14,
            "{x}"
        );
        // Two columns pulling the same way: the non-negative fit uses the one that helps.
        let m = DMatrix::from_row_slice(2, 2, &[1.0, 0.6, 0.0, 0.8]);
        let b = DVector::from_vec(vec![1.0, -2.0]);
        let x = nnls(&m, &b, &[true, true]);
        assert!((x[0] - 1.0).abs() < 1e-12 && x[1] == 0.0, "{x}");
    }
}
