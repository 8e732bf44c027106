//! Joint stops and ground contact: minimize `V(q)` subject to `Φ(q) = 0` and `g(q) ≥ 0` by an
//! active-set extension of coordinate partitioning.
//!
//! The active inequalities `A` join `Φ` as rows `g_k(q) = 0`, and the equality-constrained
//! problem is solved as any other (partition, reduced Newton, corrector). Then:
//! - a step that would make an inactive `g_k` negative is cut by bisection on the step length
//!   (through the corrector) where the first one reaches `|g_k| ≤ tol`; every inequality within
//!   `tol` of its boundary there joins `A`, and the partition is recomputed;
//! - at a stationary point, the multipliers `λ_k` of the active rows (`V_qᵀ = Φ_qᵀ μ`) are the
//!   stops' efforts and the contacts' normal forces; the one most negative below
//!   `−force_tolerance · F` (`F` the weight and loads of the mechanism) leaves `A`;
//! - it stops when every `λ_k ≥ −force_tolerance · F` and every `g_k ≥ −tol`
//!   (complementarity `g_k λ_k = 0` holds by construction: active rows have `g = 0`, inactive
//!   ones `λ = 0`), or after `max_iterations` changes of `A` after the start (reported as
//!   cycling).
//!
//! - a sticking sphere that has rolled at a stationary point is re-anchored where it touches
//!   and the round solved again (module `rolling`); where no rest exists this way (a ball on a
//!   sloping plane rolls down) it gives up after `MAX_ROLLS` re-anchorings (`unbounded`).
//!
//! Gaps are compared dimensionless: lengths divided by the characteristic length `L`, angles
//! as they are; `tol = gap_tolerance`. Redundant active rows (a box flat on the ground has four
//! supporting vertices for three degrees of freedom) are handled by the partition, which gives
//! them no multiplier; the force distribution reported is then the least-norm one over the
//! stops and contacts (module `distribution`: a box flat on four vertices gets `m g / 4` on
//! each). Stability is judged on the tangent space of the active rows that carry a force and the
//! critical cone of those that do not (module `cone`).
//!
//! ## References
//! - J. Nocedal, S. J. Wright, *Numerical Optimization*, 2nd ed., Springer (2006), §16.5
//!   (active-set methods), §15.4 (handling inequalities in reduced-gradient methods).

use super::options::{Limits, Options};
use super::partition::Partition;
use super::system::{Eval, System};
use crate::constraints::unilateral::{self, Active, Unilateral};
use crate::kinematics::Branches;
use crate::model::{Friction, Model};
use nalgebra::{DVector, Vector3};

/// The inactive inequalities that a step must not violate.
pub(crate) struct Guard<'m> {
    model: &'m Model,
    pub(crate) inactive: Vec<Unilateral>,
    tol: f64,
    /// For contacts with an obstacle: its tangent plane `(o, n)` at the round's start. A step
    /// is guarded against that plane (a finite obstacle could otherwise be stepped through).
    planes: Vec<Option<(Vector3<f64>, Vector3<f64>)>>,
    /// The sticking spheres' roll limits, after the inequalities (module `rolling`).
    rolls: Vec<super::rolling::RollLimit>,
    /// Whether the boundary may be searched by regula falsi: no guarded inequality is a
    /// sticking contact (anchored where it lands) and there is no roll limit.
    falsi: bool,
}

impl<'m> Guard<'m> {
    /// The guard of the inequalities `inactive` from the configuration `q`, and of the roll
    /// limits of the sticking spheres among `active`.
    pub(crate) fn new(
        model: &'m Model,
        options: &Options,
        inactive: Vec<Unilateral>,
        active: &[Active],
        tol: f64,
        q: &DVector<f64>,
    ) -> Self {
        let sticking = inactive.iter().any(|u| match *u {
            Unilateral::Contact { point, .. } => {
                model.contact_points[point]
                    .settings
                    .friction
                    .unwrap_or(options.friction)
                    == Friction::Stick
            }
            Unilateral::Limit { .. } => false,
        });
        let rolls = super::rolling::limits(model, active);
        let planes = inactive
            .iter()
            .map(|u| match *u {
                Unilateral::Contact { point, ground } if ground >= model.grounds.len() => Some(
                    unilateral::surface(model, ground, &unilateral::point_world(model, point, q)),
                ),
                _ => None,
            })
            .collect();
        Guard {
            model,
            inactive,
            tol,
            planes,
            falsi: !sticking && rolls.is_empty(),
            rolls,
        }
    }

    /// Number of guarded inequalities: the inactive ones, then the roll limits.
    fn len(&self) -> usize {
        self.inactive.len() + self.rolls.len()
    }

    /// Whether guarded inequality `k` is a roll limit (not an inequality to activate).
    pub(crate) fn is_roll_limit(&self, k: usize) -> bool {
        k >= self.inactive.len()
    }

    /// Dimensionless gap of inequality `k` (against an obstacle: to its plane of `planes`; a
    /// roll limit's margin after the inactive ones).
    fn gap(&self, k: usize, q: &DVector<f64>, branches: &Branches) -> f64 {
        let Some(u) = self.inactive.get(k) else {
            return self.rolls[k - self.inactive.len()].margin(self.model, q);
        };
        let g = match (self.planes[k], u) {
            (Some((o, n)), Unilateral::Contact { point, .. }) => {
                n.dot(&(unilateral::point_world(self.model, *point, q) - o))
                    - self.model.contact_points[*point].radius
            }
            _ => unilateral::gap(self.model, u, q, branches).unwrap_or(f64::INFINITY),
        };
        dimensionless(self.model, u, g)
    }

    /// The lowest dimensionless gap and its inequality.
    fn lowest(&self, q: &DVector<f64>, branches: &Branches) -> Option<(usize, f64)> {
        (0..self.len())
            .map(|k| (k, self.gap(k, q, branches)))
            .min_by(|a, b| a.1.total_cmp(&b.1))
    }

    /// Whether the step from `from` to `to` brings one of the inequalities closer to its
    /// boundary (a linear descent may then end on it, and is not unbounded).
    pub(crate) fn approaching(&self, sys: &System, from: &DVector<f64>, to: &DVector<f64>) -> bool {
        let b = &sys.problem.cons.branches;
        (0..self.len()).any(|k| self.gap(k, to, b) < self.gap(k, from, b) - self.tol)
    }

    /// Whether `q` violates one of the inequalities by more than the tolerance.
    pub(crate) fn violated(&self, sys: &System, q: &DVector<f64>) -> bool {
        self.lowest(q, &sys.problem.cons.branches)
            .is_some_and(|(_, g)| g < -self.tol)
    }

    /// The corrected point `q(α) = correct(q + α dq)` on the boundary of the first inequality
    /// met along `α ∈ [0, alpha]`, and the inequalities within the tolerance of their boundary
    /// there. `q_alpha` is the corrected point at `alpha`, if known.
    ///
    /// The bracket `[lo, hi]` (`lo` within or above every boundary, `hi` beyond one or where
    /// the corrector fails) shrinks by bisection, or, when the guard allows it (no sticking
    /// contact, which would be anchored where it lands, and no roll limit), by regula falsi
    /// (Illinois) on the lowest gap `g(α)` where both ends have one, clamped to the inner
    /// `1 − 2·10⁻³` of the bracket. Either ends at the first point with `|g| ≤ tol`.
    ///
    /// The corrector at each trial point starts from the chord between the corrected ends of
    /// the bracket (from `q_lo + (α − lo) dq` while the upper end has none): its distance to the
    /// manifold is second order in the bracket's width, not in `α`, so fewer corrector steps
    /// reach the same point. The independent coordinates are `q + α dq`.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn boundary(
        &self,
        sys: &mut System,
        q: &DVector<f64>,
        dq: &DVector<f64>,
        alpha: f64,
        q_alpha: Option<&DVector<f64>>,
        part: &Partition,
        options: &Options,
        eval: &Eval,
    ) -> Option<(DVector<f64>, Vec<usize>)> {
        let (mut lo, mut hi) = (0.0, alpha);
        let mut q_lo = q.clone();
        let mut q_hi = q_alpha.cloned();
        // The lowest gap at each end (`None` at an end where the corrector failed), and the
        // end that moved last (Illinois: the other end's gap is halved when it stays twice).
        let (mut g_lo, mut g_hi) = (None, None);
        if self.falsi {
            let b = &sys.problem.cons.branches;
            g_lo = self.lowest(q, b).map(|x| x.1);
            g_hi = q_alpha.and_then(|qa| self.lowest(qa, b)).map(|x| x.1);
        }
        let mut last_moved_hi = None;
        for _ in 0..80 {
            let w = hi - lo;
            let mid = match (g_lo, g_hi) {
                (Some(a), Some(b)) if a > b => {
                    (lo + w * a / (a - b)).clamp(lo + 1e-3 * w, hi - 1e-3 * w)
                }
                _ => 0.5 * (lo + hi),
            };
            let mut qm = match &q_hi {
                Some(qh) => &q_lo + (qh - &q_lo) * ((mid - lo) / w),
                None => &q_lo + dq * (mid - lo),
            };
            for &c in &part.independent {
                qm[c] = q[c] + dq[c] * mid;
            }
            let corrected = sys.correct_from(
                &mut qm,
                part,
                options.constraint_tolerance,
                options.max_corrector_iterations,
                Some(&eval.factors),
            );
            if corrected.is_err() {
                hi = mid;
                (q_hi, g_hi) = (None, None);
                continue;
            }
            let (_, g) = self.lowest(&qm, &sys.problem.cons.branches)?;
            if g < -self.tol {
                hi = mid;
                q_hi = Some(qm);
                g_hi = self.falsi.then_some(g);
                if last_moved_hi == Some(true) {
                    g_lo = g_lo.map(|x| 0.5 * x);
                }
                last_moved_hi = Some(true);
            } else {
                lo = mid;
                q_lo = qm;
                if g <= self.tol {
                    break;
                }
                g_lo = self.falsi.then_some(g);
                if last_moved_hi == Some(false) {
                    g_hi = g_hi.map(|x| 0.5 * x);
                }
                last_moved_hi = Some(false);
            }
        }
        let branches = &sys.problem.cons.branches;
        let touching: Vec<usize> = (0..self.len())
            .filter(|&k| self.gap(k, &q_lo, branches) <= self.tol)
            .collect();
        if touching.is_empty() {
            return None;
        }
        Some((q_lo, touching))
    }
}

/// `g` divided by the characteristic length for a gap in m.
fn dimensionless(model: &Model, u: &Unilateral, g: f64) -> f64 {
    if unilateral::length_power(model, u) == 1 {
        g / model.length_scale
    } else {
        g
    }
}

/// Every inequality of the model under `options`.
pub(crate) fn inequalities(model: &Model, options: &Options) -> Vec<Unilateral> {
    unilateral::inequalities(model, options.limits == Limits::Enforce)
}

/// `u` made active at `q`: a sticking contact is anchored at the point's projection on the
/// ground.
pub(crate) fn activate(
    model: &Model,
    options: &Options,
    u: Unilateral,
    q: &DVector<f64>,
) -> Active {
    let anchor = match u {
        Unilateral::Contact { point, ground } => {
            let c = &model.contact_points[point];
            let friction = c.settings.friction.unwrap_or(options.friction);
            (friction == Friction::Stick).then(|| {
                let x = unilateral::point_world(model, point, q);
                let (_, normal) = unilateral::surface(model, ground, &x);
                let g = unilateral::gap(model, &u, q, &Branches::default()).unwrap_or(0.0);
                let i = 7 * c.body.0;
                let p = nalgebra::Vector4::new(q[i + 3], q[i + 4], q[i + 5], q[i + 6]);
                let a = crate::math::rotation(&p);
                unilateral::Anchor {
                    world: x - normal * (g + c.radius),
                    body: c.point - a.transpose() * normal * c.radius,
                }
            })
        }
        Unilateral::Limit { .. } => None,
    };
    Active { row: u, anchor }
}

/// Force scale `F` of the mechanism \[N\]: its weight plus the dead loads, and the joint
/// efforts divided by the characteristic length (at least 1e-12).
pub(crate) fn force_scale(model: &Model) -> f64 {
    let weight: f64 =
        model.bodies.iter().map(|b| b.gravity_mass).sum::<f64>() * model.gravity.norm();
    let loads: f64 = model.loads.iter().map(|l| l.force.norm()).sum();
    let efforts: f64 =
        model.efforts.iter().map(|e| e.value.abs()).sum::<f64>() / model.length_scale;
    (weight + loads + efforts).max(1e-12)
}

/// Multipliers of the rows of each active inequality (`g` first, then the tangential rows),
/// from the multipliers `full` of every row of `cons`.
pub(crate) fn active_multipliers(
    cons: &crate::constraints::Constraints,
    full: &DVector<f64>,
) -> Vec<(Active, Vec<f64>)> {
    cons.blocks
        .iter()
        .filter_map(|b| match &b.kind {
            crate::constraints::BlockKind::Unilateral(a) => {
                Some((*a, (0..a.row_count()).map(|k| full[b.first + k]).collect()))
            }
            _ => None,
        })
        .collect()
}

/// The inequality whose multiplier is most negative relative to `scale` (a stop's effort in
/// N m divided by the characteristic length), if below `−threshold`.
pub(crate) fn to_release(
    model: &Model,
    multipliers: &[(Active, Vec<f64>)],
    threshold: f64,
) -> Option<usize> {
    multipliers
        .iter()
        .enumerate()
        .map(|(i, (a, m))| (i, scaled_force(model, a, m)))
        .filter(|&(_, l)| l < -threshold)
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(i, _)| i)
}

/// The multiplier of an active row's inequality, a stop's torque divided by the
/// characteristic length so that it compares with forces.
fn scaled_force(model: &Model, a: &Active, m: &[f64]) -> f64 {
    match a.row {
        Unilateral::Limit { joint, .. } if model.joints[joint.0].kind.is_angle(0) => {
            m[0] / model.length_scale
        }
        _ => m[0],
    }
}

/// The active rows that carry a force above `threshold` (strongly active) and those that do
/// not (weakly active), with the multipliers' scaling of [`to_release`].
pub(crate) fn split(
    model: &Model,
    multipliers: &[(Active, Vec<f64>)],
    threshold: f64,
) -> (Vec<Active>, Vec<Active>) {
    let mut strong = Vec::new();
    let mut weak = Vec::new();
    for (a, m) in multipliers {
        if scaled_force(model, a, m) > threshold {
            strong.push(*a);
        } else {
            weak.push(*a);
        }
    }
    (strong, weak)
}

/// The world point where a contact touches: the point minus its radius along the normal.
pub(crate) fn touch_point(model: &Model, a: &Active, q: &DVector<f64>) -> Option<Vector3<f64>> {
    match a.row {
        Unilateral::Contact { point, ground } => {
            let x = unilateral::point_world(model, point, q);
            let (_, normal) = unilateral::surface(model, ground, &x);
            Some(x - normal * model.contact_points[point].radius)
        }
        Unilateral::Limit { .. } => None,
    }
}

/// The active-set iteration from an assembled state (module docs).
///
/// # Errors
/// As [`crate::solve`]; [`crate::Error::Assembly`] if the initially violated inequalities
/// cannot be met together with the joints.
pub(crate) fn solve(
    model: &Model,
    start: crate::State,
    locks: &[(crate::model::JointId, usize, f64)],
    options: &Options,
) -> crate::Result<(crate::State, super::Report)> {
    let all = inequalities(model, options);
    let tol = options.gap_tolerance;
    let threshold = options.force_tolerance * force_scale(model);
    let mut state = start;
    // Inequalities violated or touching at the start are active from the start (a sticking
    // contact that touches at the start is held where it is).
    let mut active: Vec<Active> = all
        .iter()
        .filter(|u| {
            unilateral::gap(model, u, &state.q, &state.branches)
                .is_some_and(|g| dimensionless(model, u, g) <= tol)
        })
        .map(|&u| activate(model, options, u, &state.q))
        .collect();
    // The inequalities active from the start count as changes in the report, not towards the
    // cycling guard (a rope lying on the ground starts with hundreds).
    let mut changes = active.len();
    let initial = changes;
    let mut rolls = 0;
    let mut touched = Vec::new();
    super::rolling::record_touches(model, &active, &state.q, &mut touched);
    let mut iterations = 0;
    let mut counters = super::Diagnostics::default();
    loop {
        let mut branches = state.branches.clone();
        let q = super::assemble::project(model, state.q, &mut branches, locks, &active, options)?;
        let inactive: Vec<Unilateral> = all
            .iter()
            .filter(|u| !active.iter().any(|a| a.row == **u))
            .copied()
            .collect();
        let guard = Guard::new(model, options, inactive, &active, tol, &q);
        let round = super::solve_round(
            model,
            crate::State { q, branches },
            locks,
            &active,
            Some(&guard),
            options,
        )?;
        iterations += round.report.iterations;
        counters.add_counts(&round.report.diagnostics);
        state = round.state;
        let mut report = round.report;
        let cycling = changes - initial >= options.max_iterations;
        let mut rolled_too_far = false;
        if let (Some(hit), false) = (&round.blocked, cycling) {
            // A sphere that reached its roll limit is re-anchored where it touches now.
            if hit.iter().any(|&k| guard.is_roll_limit(k)) {
                super::rolling::reanchor(model, options, &mut active, &touched, &state.q);
                rolls += 1;
            }
            for &k in hit.iter().filter(|&&k| !guard.is_roll_limit(k)) {
                active.push(activate(model, options, guard.inactive[k], &state.q));
                changes += 1;
            }
            super::rolling::record_touches(model, &active, &state.q, &mut touched);
            if rolls <= super::rolling::MAX_ROLLS {
                continue;
            }
            report.termination = super::Termination::Unbounded;
            rolled_too_far = true;
        }
        if report.converged() && !cycling && !rolled_too_far {
            if let Some(i) = to_release(model, &round.multipliers, threshold) {
                active.remove(i);
                super::rolling::record_touches(model, &active, &state.q, &mut touched);
                changes += 1;
                continue;
            }
            if super::rolling::reanchor(model, options, &mut active, &touched, &state.q) {
                rolls += 1;
                if rolls <= super::rolling::MAX_ROLLS {
                    continue;
                }
                report.termination = super::Termination::Unbounded;
            }
        }
        if cycling {
            report.termination = super::Termination::ActiveSetCycling;
        }
        // A round stopped at an inequality or a roll limit has no verdict of its own.
        if (cycling || rolled_too_far) && round.blocked.is_some() {
            report.stability = super::stability_on(model, &state, &active, true);
        }
        report.iterations = iterations;
        let own = report.diagnostics.clone();
        report.diagnostics = counters;
        report.diagnostics.gradient_norm = own.gradient_norm;
        report.diagnostics.gradient_tolerance = own.gradient_tolerance;
        report.diagnostics.constraint_residual = own.constraint_residual;
        report.diagnostics.linear_algebra = own.linear_algebra;
        report.diagnostics.eigenvalues_by = own.eigenvalues_by;
        report.diagnostics.free_directions = own.free_directions;
        report.diagnostics.load_steps = 1;
        report.active_set_changes = changes;
        describe(model, options, &state, &round.multipliers, &mut report);
        // Judged with every active row held; where some touch without a force, on the
        // critical cone instead (module `cone`).
        let (strong, weak) = split(model, &round.multipliers, threshold);
        if report.converged() && !weak.is_empty() {
            report.stability = super::cone::stability_touching(model, &state, &strong, &weak, true);
        }
        return Ok((state, report));
    }
}

/// Fills the report's `contacts` and `active_limits` from the multipliers of the active rows.
fn describe(
    model: &Model,
    options: &Options,
    state: &crate::State,
    multipliers: &[(Active, Vec<f64>)],
    report: &mut super::Report,
) {
    use super::report::{ActiveLimit, Contact, ContactState};
    for (a, m) in multipliers {
        match a.row {
            Unilateral::Limit {
                joint,
                bound,
                value,
            } => report.active_limits.push(ActiveLimit {
                joint: model.joints[joint.0].name.clone(),
                bound: bound.name().into(),
                value,
                effort: match bound {
                    unilateral::Bound::Lower => m[0],
                    unilateral::Bound::Upper => -m[0],
                },
            }),
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
                let required = if ft.norm() == 0.0 {
                    0.0
                } else if fnorm > 0.0 {
                    ft.norm() / fnorm
                } else {
                    f64::INFINITY
                };
                let mu = c.settings.mu.or(options.mu);
                let contact_state = match (a.anchor, mu) {
                    (None, _) => ContactState::Touching,
                    (Some(_), Some(mu)) if required > mu => ContactState::Slipping,
                    (Some(_), _) => ContactState::Sticking,
                };
                let p = touch_point(model, a, &state.q).unwrap_or_default();
                report.contacts.push(Contact {
                    link: c.link.clone(),
                    ground: unilateral::surface_name(model, ground).to_string(),
                    point_world: p.into(),
                    normal_world: normal.into(),
                    gap,
                    normal_force: fnorm,
                    tangential_force: ft.into(),
                    required_friction: if required.is_finite() {
                        required
                    } else {
                        f64::MAX
                    },
                    state: contact_state,
                });
            }
        }
    }
}
