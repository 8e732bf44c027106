//! The friction verdict: is there a distribution of the stop and contact forces, each contact
//! inside its friction cone and each stop within its joint's `effort`, that balances the
//! mechanism at this pose? And how much friction does it need at least?
//!
//! Where the supports are statically indeterminate every balancing distribution is
//! `λ(z) = λ₀ + N z` (`λ₀` one of them, `N` a basis of the self-equilibrated combinations of
//! the stop and contact rows; analyze and verify each build theirs, module `distribution` and
//! `verify::unilateral`). A contact `i` pushes with `n_i = λ_{i,0} ≥ 0` and, when it sticks,
//! carries the friction force `t_i = (λ_{i,1}, λ_{i,2})`. The friction the mechanism needs is
//!
//! ```text
//! required_mu = min_z max_i ‖t_i(z)‖ / n_i(z)     over the sticking contacts,
//! ```
//!
//! subject to `n_i ≥ 0` and `0 ≤ λ_stop ≤ limit`: a generalized fractional program
//! (quasi-convex: for a fixed `s` the set `‖t_i‖ ≤ s n_i` is a second-order cone). It is
//! solved by the Dinkelbach-type iteration of Crouzeix, Ferland and Schaible: from a
//! distribution `z_k` needing `s_k = max_i ‖t_i‖/n_i`, the second-order cone program
//!
//! ```text
//! θ_k = min_{z,θ} θ   s.t.  ‖t_i(z)‖ ≤ s_k n_i(z) + θ n_i(z_k)
//! ```
//!
//! gives `z_{k+1}` with `s_{k+1} ≤ s_k + θ_k`; it stops when `θ_k ≥ −10⁻¹¹` (superlinear
//! convergence; the start `z_0` minimizes the largest friction force, which is zero on a
//! level floor). Every `s_k` is the need of a concrete distribution, so the answer is an upper
//! bound reached to the solver's accuracy (`10⁻¹²`). The forces reported are then the
//! least-norm ones (`½ ‖D λ‖²`, stop efforts divided by the characteristic length) among those
//! needing at most `required_mu (1 + 10⁻¹⁰)`: a level box gets no friction and `m g / 4` per
//! corner, a crate on a slope `tan α` at every loaded corner.
//!
//! A pose slips only when no distribution within the given coefficients exists: with one
//! coefficient `μ` for every sticking contact, when `required_mu > μ + 10⁻⁹ max(1, μ)`; with
//! different ones, when `min_z max_i ‖t_i‖ / (μ_i n_i) > 1 + 10⁻⁹` (contacts without a
//! coefficient unbounded), whose distribution is then reported.
//!
//! ## References
//! - J.-P. Crouzeix, J. A. Ferland, S. Schaible, An algorithm for generalized fractional
//!   programs, *J. Optim. Theory Appl.* 47 (1985) 35–49.
//! - J. C. Trinkle, J.-S. Pang, S. Sudarsky, G. Lo, On dynamic multi-rigid-body contact
//!   problems with Coulomb friction, *ZAMM* 77 (1997) 267–279 (the friction cones).

pub(crate) use super::conic::Holder;
use super::conic::{self, Affine, Goal};
use super::shortcut;
pub(crate) use super::support::{effort_limit, holders_of, Support};
use crate::model::{JointId, Model};
pub(crate) use crate::solver::active_set::force_scale;
use crate::solver::report::{Contact, ContactState, FrictionVerdict};
use nalgebra::DVector;

/// Relative tolerance of the verdict: a contact slips when it needs more than
/// `μ + MU_TOLERANCE · max(1, μ)`.
pub(crate) const MU_TOLERANCE: f64 = 1e-9;

/// Relative slack of the friction bound in the least-norm choice: where the distributions
/// needing exactly `required_mu` form a set without interior (a crate on a slope: every
/// corner's force parallel to gravity), the interior-point solver needs some room.
const TIE_SLACK: f64 = 1e-6;

/// Iterations of the Dinkelbach-type loop at most.
const MAX_ROUNDS: usize = 30;

/// The distribution chosen and the verdict.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Distribution {
    /// Multipliers of every row of every holder.
    pub(crate) forces: DVector<f64>,
    /// The smallest common coefficient for which balancing forces exist (`None` without a
    /// sticking contact).
    pub(crate) required_mu: Option<f64>,
    /// Whether no distribution holds within the given coefficients.
    pub(crate) slipping: bool,
}

/// `required_mu` and whether the pose slips, as [`distribute`] chose.
pub(crate) type Chosen = Option<(Option<f64>, bool)>;

/// The verdict from the sticking contacts of the distribution reported, each with the
/// coefficient it needs and the one it has, and `chosen` (`required_mu`, slipping) where
/// [`distribute`] chose the distribution (else from the needs: it is the only one).
pub(crate) fn verdict(
    sticking: &[(f64, Option<f64>)],
    chosen: Option<(Option<f64>, bool)>,
) -> Option<FrictionVerdict> {
    let required = chosen.and_then(|c| c.0);
    let first = sticking.first()?.1;
    let required_mu = required.unwrap_or_else(|| sticking.iter().map(|s| s.0).fold(0.0, f64::max));
    let mu = if sticking.iter().all(|s| s.1 == first) {
        first
    } else {
        None
    };
    Some(FrictionVerdict {
        required_mu,
        mu,
        margin: mu.map(|m| m - required_mu),
        slipping: match chosen {
            Some((_, slipping)) => slipping,
            None => sticking
                .iter()
                .any(|&(n, m)| m.is_some_and(|m| slips(n, m))),
        },
    })
}

/// Contacts marked slipping only where the verdict is (with the least-norm choice's slack a
/// contact may need `10⁻⁶` more than `required_mu` while the mechanism holds).
pub(crate) fn settle_states(contacts: &mut [Contact], verdict: Option<&FrictionVerdict>) {
    if verdict.is_some_and(|v| !v.slipping) {
        for c in contacts
            .iter_mut()
            .filter(|c| c.state == ContactState::Slipping)
        {
            c.state = ContactState::Sticking;
        }
    }
}

/// A stop's effort limit and whether `effort` exceeds it (beyond `10⁻⁹` of it).
pub(crate) fn effort_check(model: &Model, joint: JointId, effort: f64) -> (Option<f64>, bool) {
    let limit = effort_limit(model, joint);
    (
        limit,
        limit.is_some_and(|l| effort.abs() > l * (1.0 + 1e-9)),
    )
}

/// The friction coefficient a contact with normal force `n` and friction force of magnitude
/// `t` needs: `t / n`, 0 without friction force, `f64::MAX` with friction and no push.
pub(crate) fn needs_mu(n: f64, t: f64) -> f64 {
    if t == 0.0 {
        0.0
    } else if n > 0.0 {
        t / n
    } else {
        f64::MAX
    }
}

/// Whether needing `needs` exceeds the coefficient `mu` beyond the verdict's tolerance.
pub(crate) fn slips(needs: f64, mu: f64) -> bool {
    needs > mu + MU_TOLERANCE * mu.max(1.0)
}

/// The largest need `max_i ‖t_i‖ / (c_i n_i)` of `forces` over the sticking contacts with a
/// weight `c_i` (`μ_i` or 1), relative to the force scale `eps` below which a friction
/// force counts as none.
fn largest_need(support: &Support, c: &[Option<f64>], forces: &DVector<f64>, eps: f64) -> f64 {
    let mut worst: f64 = 0.0;
    let mut i = 0;
    for &(first, h) in &support.holders {
        if let Holder::Stick { .. } = h {
            if let Some(ci) = c[i] {
                let t = forces[first + 1].hypot(forces[first + 2]);
                let t = if t <= eps { 0.0 } else { t };
                worst = worst.max(needs_mu(forces[first].max(0.0), t) / ci);
            }
            i += 1;
        }
    }
    worst
}

/// `λ(z)`.
fn at(support: &Support, z: &DVector<f64>) -> DVector<f64> {
    &support.base + &support.null * z
}

/// The support with its friction weights `c` (one per sticking contact).
fn holders(support: &Support, c: &[Option<f64>]) -> Vec<(usize, Holder)> {
    let mut i = 0;
    support
        .holders
        .iter()
        .map(|&(first, h)| match h {
            Holder::Stick { .. } => {
                i += 1;
                (first, Holder::Stick { c: c[i - 1] })
            }
            other => (first, other),
        })
        .collect()
}

/// `min_z max_i ‖t_i‖ / (c_i n_i)` (module docs) and a distribution reaching it; `None` when
/// no distribution keeps every contact pushing and every stop within its limit.
fn least_need(support: &Support, c: &[Option<f64>], scale: f64) -> Option<(f64, DVector<f64>)> {
    let hs = holders(support, c);
    let f = Affine {
        base: &support.base,
        null: &support.null,
        holders: &hs,
    };
    let eps = 1e-12 * scale;
    let sticks = c.iter().filter(|x| x.is_some()).count();
    let w0 = vec![scale; sticks];
    // A distribution within the lower bound of module `friction::shortcut` needs exactly it.
    let bound = c
        .iter()
        .all(|x| *x == Some(1.0))
        .then(|| shortcut::lower_bound(support))
        .flatten();
    if let Some((b, _)) = bound {
        // (Infeasible for one bound, `level` is infeasible for every bound: no distribution
        // keeps the contacts pushing.)
        let (z, _) = conic::solve(&f, &Goal::Level { s: b, w: &w0 })?;
        let s = largest_need(support, c, &at(support, &z), eps);
        if s <= b + 1e-11 * b.max(1.0) {
            return Some((s, z));
        }
    }
    // z₀: the least largest friction force (bound s = 0, weights the force scale).
    let (mut z, _) = conic::solve(&f, &Goal::Level { s: 0.0, w: &w0 })?;
    let mut s = largest_need(support, c, &at(support, &z), eps);
    if !s.is_finite() || s >= f64::MAX {
        s = 1e3;
    }
    for _ in 0..MAX_ROUNDS {
        if s == 0.0 {
            break;
        }
        let lam = at(support, &z);
        let mut w = Vec::with_capacity(sticks);
        let mut i = 0;
        for &(first, h) in &support.holders {
            if let Holder::Stick { .. } = h {
                if c[i].is_some() {
                    w.push(lam[first].max(1e-6 * scale));
                }
                i += 1;
            }
        }
        let Some((zn, theta)) = conic::solve(&f, &Goal::Level { s, w: &w }) else {
            break;
        };
        let sn = largest_need(support, c, &at(support, &zn), eps);
        let improved = sn < s * (1.0 - 1e-14);
        if improved {
            s = sn;
            z = zn;
        }
        if theta >= -1e-11 || !improved {
            break;
        }
    }
    Some((s, z))
}

/// The least-norm distribution among those needing at most `s` (weights `c`), or `fallback`
/// if that program fails or does worse than `s` allows.
fn least_norm(
    support: &Support,
    c: &[Option<f64>],
    s: f64,
    fallback: &DVector<f64>,
    scale: f64,
) -> DVector<f64> {
    let hs = holders(support, c);
    let f = Affine {
        base: &support.base,
        null: &support.null,
        holders: &hs,
    };
    let bound = if s <= 1e-12 {
        0.0
    } else {
        s * (1.0 + TIE_SLACK)
    };
    let Some((z, _)) = conic::solve(
        &f,
        &Goal::Least {
            s: bound,
            d: &support.weight,
        },
    ) else {
        return fallback.clone();
    };
    let lam = at(support, &z);
    let worst = largest_need(support, c, &lam, 1e-12 * scale);
    if worst > s * (1.0 + 2.0 * TIE_SLACK) + 1e-12 {
        return fallback.clone();
    }
    lam
}

/// The distribution and verdict of module docs; `None` when no distribution keeps every
/// contact pushing and every stop within its limit. `scale` is the mechanism's force scale
/// \[N\].
pub(crate) fn distribute(support: &Support, scale: f64) -> Option<Distribution> {
    distribute_within(support, scale).or_else(|| {
        // No distribution within the effort limits: the one without them (the stops that
        // then exceed their limits are flagged by the caller).
        let limited = support
            .holders
            .iter()
            .any(|(_, h)| matches!(h, Holder::Stop { limit: Some(_) }));
        limited.then_some(())?;
        let free = Support {
            base: support.base.clone(),
            null: support.null.clone(),
            holders: support
                .holders
                .iter()
                .map(|&(f, h)| match h {
                    Holder::Stop { .. } => (f, Holder::Stop { limit: None }),
                    other => (f, other),
                })
                .collect(),
            mu: support.mu.clone(),
            weight: support.weight.clone(),
            plane: support.plane.clone(),
        };
        distribute_within(&free, scale)
    })
}

/// [`distribute`] with the effort limits as given.
fn distribute_within(support: &Support, scale: f64) -> Option<Distribution> {
    let sticks: Vec<Option<f64>> = support
        .holders
        .iter()
        .zip(&support.mu)
        .filter(|((_, h), _)| matches!(h, Holder::Stick { .. }))
        .map(|(_, m)| *m)
        .collect();
    let ones = vec![Some(1.0); sticks.len()];
    let scale = scale.max(1e-300);
    if support.null.ncols() == 0 {
        // Determinate: the one distribution.
        let f = &support.base;
        if !pushes(support, f, scale) {
            return None;
        }
        let required = (!sticks.is_empty()).then(|| largest_need(support, &ones, f, 1e-12 * scale));
        let slipping = slipping_with(support, &sticks, f, scale);
        return Some(Distribution {
            forces: f.clone(),
            required_mu: required,
            slipping,
        });
    }
    if shortcut::nothing_pushes_on_a_line(support, scale) {
        return None;
    }
    // The lower bound (0 without one), reached in closed form where it can be.
    let bound = shortcut::lower_bound(support);
    let (b, group) = bound.as_ref().map_or((0.0, &[][..]), |(b, g)| (*b, &g[..]));
    let eps = 1e-12 * scale;
    if let Some(forces) = shortcut::at_bound(
        support,
        (b, group),
        scale,
        |f| pushes(support, f, scale),
        |f| largest_need(support, &ones, f, eps),
    ) {
        let need = largest_need(support, &ones, &forces, eps);
        let slipping = match common_mu(&sticks) {
            Some(Some(mu)) => slips(need, mu),
            Some(None) => false,
            None => slipping_with(support, &sticks, &forces, scale),
        };
        // (Different coefficients and a contact beyond its own: the cone programs weigh them.)
        if !slipping || common_mu(&sticks).is_some() {
            return Some(Distribution {
                forces,
                required_mu: (!sticks.is_empty()).then_some(need),
                slipping,
            });
        }
    }
    let (required, z) = least_need(support, &ones, scale)?;
    let best = at(support, &z);
    let forces = least_norm(support, &ones, required, &best, scale);
    let required_mu = (!sticks.is_empty()).then_some(required);
    let common = common_mu(&sticks);
    let mut out = Distribution {
        forces,
        required_mu,
        slipping: false,
    };
    match common {
        Some(Some(mu)) => out.slipping = slips(required_mu.unwrap_or(0.0), mu),
        Some(None) => {}
        None => {
            // Different coefficients: the best use of each contact's own.
            if slipping_with(support, &sticks, &out.forces, scale) {
                let c: Vec<Option<f64>> = sticks.to_vec();
                if let Some((usage, z)) = least_need(support, &c, scale) {
                    if usage <= 1.0 + MU_TOLERANCE {
                        let best = at(support, &z);
                        out.forces = least_norm(support, &c, usage, &best, scale);
                    } else {
                        out.slipping = true;
                    }
                }
            }
        }
    }
    Some(out)
}

/// `Some(mu)` when every sticking contact has the same coefficient (`Some(None)`: none has
/// one), `None` when they differ.
fn common_mu(sticks: &[Option<f64>]) -> Option<Option<f64>> {
    let first = *sticks.first()?;
    sticks.iter().all(|m| *m == first).then_some(first)
}

/// Whether some sticking contact of `forces` needs more than its own coefficient.
fn slipping_with(
    support: &Support,
    sticks: &[Option<f64>],
    forces: &DVector<f64>,
    scale: f64,
) -> bool {
    let mut i = 0;
    let mut any = false;
    for &(first, h) in &support.holders {
        if let Holder::Stick { .. } = h {
            if let Some(mu) = sticks[i] {
                let t = forces[first + 1].hypot(forces[first + 2]);
                let t = if t <= 1e-12 * scale { 0.0 } else { t };
                any |= slips(needs_mu(forces[first].max(0.0), t), mu);
            }
            i += 1;
        }
    }
    any
}

/// Whether every contact of `forces` pushes and every stop holds within its limit (to
/// `10⁻⁹` of the force scale).
fn pushes(support: &Support, forces: &DVector<f64>, scale: f64) -> bool {
    let tol = 1e-9 * scale;
    support.holders.iter().all(|&(first, h)| {
        forces[first] >= -tol
            && match h {
                Holder::Stop { limit: Some(l) } => forces[first] <= l + tol,
                _ => true,
            }
    })
}

#[cfg(test)]
#[path = "tests.rs"]
mod tests;
