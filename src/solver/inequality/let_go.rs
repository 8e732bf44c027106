//! Contacts that no longer hold a floating body: the rows released when a round stalls.
//!
//! A round can end with its line search failed and no active row pulling: a box that slid over
//! the edge of a finite obstacle hangs on contact points at the edge, where the gap
//! `g(x) = dist(x, obstacle)` has a kink (the nearest face changes) and the step the row's
//! gradient allows goes nowhere. Such rows do not hold the body: translating the body's group
//! (the bodies joined by joints and springs, module `unbounded`) by `δ = ε F̂` along its net
//! constant pull `F = Σ m_b g + Σ f_load` opens every one of them,
//!
//! `g_k(q ⊕ ε F̂) − g_k(q) > OPENING · ε` for every active contact `k` of the group,
//!
//! while a contact resting on a face that carries the body (`n · F̂ < 0`) closes. Those rows
//! leave the active set as pulling rows do (module `release`), and the next round lets the
//! group fall: onto whatever the guard meets on the way, or without bound, which the
//! minimizer's constant-rate test reports as `unbounded` with the free direction.

use crate::constraints::unilateral::{self, Active, Unilateral};
use crate::model::Model;
use crate::State;

/// The translation `ε` tried, in units of the characteristic length.
const STEP: f64 = 1e-6;

/// The least opening, as a fraction of `ε`, that counts (a face at right angles to the pull
/// leaves the gap unchanged to first order: it neither holds nor lets go).
const OPENING: f64 = 1e-2;

/// The active contact rows (indices into `active`) of every floating group that a
/// translation along its pull opens, all of them at once (module docs); empty if every group
/// with active contacts is held by at least one of them.
pub(crate) fn opened(model: &Model, active: &[Active], state: &State) -> Vec<usize> {
    let (root, world) = crate::solver::unbounded::groups(model);
    let scale = super::active_set::force_scale(model);
    let n = model.bodies.len();
    let mut force = vec![nalgebra::Vector3::zeros(); n + 1];
    for (b, body) in model.bodies.iter().enumerate() {
        force[root[b]] += model.gravity * body.gravity_mass;
    }
    for l in &model.loads {
        force[root[l.body.0]] += l.force;
    }
    let eps = STEP * model.length_scale;
    let mut out = Vec::new();
    for r in 0..n {
        let f = force[r];
        if r == world || f.norm() <= 1e-9 * scale {
            continue;
        }
        let rows: Vec<usize> = active
            .iter()
            .enumerate()
            .filter(|(_, a)| match a.row {
                Unilateral::Contact { point, .. } => root[model.contact_points[point].body.0] == r,
                Unilateral::Limit { .. } => false,
            })
            .map(|(i, _)| i)
            .collect();
        if rows.is_empty() {
            continue;
        }
        let mut moved = state.q.clone();
        let d = f * (eps / f.norm());
        for b in (0..n).filter(|&b| root[b] == r) {
            for k in 0..3 {
                moved[7 * b + k] += d[k];
            }
        }
        let opens = |i: &usize| {
            let u = &active[*i].row;
            let before = unilateral::gap(model, u, &state.q, &state.branches);
            let after = unilateral::gap(model, u, &moved, &state.branches);
            matches!((before, after), (Some(g0), Some(g1)) if g1 - g0 > OPENING * eps)
        };
        if rows.iter().all(opens) {
            out.extend(rows);
        }
    }
    out
}
