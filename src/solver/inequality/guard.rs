//! The guard of the inactive inequalities during one round of the active-set iteration
//! (module `active_set`): the lowest dimensionless gap `min_k g_k(q)` over the inactive stops
//! and contacts (and the sticking spheres' roll limits), and the point where a step first
//! reaches a boundary: `α*` with `|g(correct(q + α* dq))| ≤ tol`, found by bisection or
//! regula falsi on `α` through the corrector.
//!
//! ## References
//! - J. Nocedal, S. J. Wright, *Numerical Optimization*, 2nd ed., Springer (2006), §16.5.
//! - M. Dowell, P. Jarratt, "A modified regula falsi method for computing the root of an
//!   equation", *BIT* 11 (1971) 168–174 (the Illinois method).

use super::active_set::dimensionless;
use crate::constraints::unilateral::{self, Active, Unilateral};
use crate::kinematics::Branches;
use crate::model::JointId;
use crate::model::Model;
use crate::solver::options::Options;
use crate::solver::partition::Partition;
use crate::solver::system::{Eval, System};
use nalgebra::{DVector, Vector3};

/// The inactive inequalities that a step must not violate.
pub(crate) struct Guard<'m> {
    pub(super) model: &'m Model,
    pub(crate) inactive: Vec<Unilateral>,
    pub(super) tol: f64,
    /// For contacts with an obstacle: its tangent plane `(o, n)` at the round's start. A step
    /// is guarded against that plane (a finite obstacle could otherwise be stepped through).
    planes: Vec<Option<(Vector3<f64>, Vector3<f64>)>>,
    /// The sticking spheres' roll limits, after the inequalities (module `rolling`).
    rolls: Vec<super::rolling::RollLimit>,
    /// Whether the boundary may be searched by regula falsi: no guarded inequality is a
    /// sticking contact (anchored where it lands) and there is no roll limit.
    falsi: bool,
    /// The round's active rows and locks, where frictionless contacts are held on their
    /// grounds along a step (module `hold`).
    pub(super) held: Option<super::hold::Held>,
    /// The round follows a release of several stops decided by the step: the stops fall from
    /// them (module `release_trial`).
    pub(crate) falling: bool,
    /// Per inactive inequality: a contact on the patch of a sticking pivot (module `together`).
    pub(super) on_patch: Vec<bool>,
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
            Unilateral::Contact { point, .. } => options
                .contact()
                .sticks(&model.contact_points[point].settings),
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
            held: None,
            falling: false,
            on_patch: Vec::new(),
        }
    }

    /// With the projected search (`StopSearch::Projected`), the guard that holds frictionless
    /// contacts on their grounds along a step (module `hold`), projecting with the round's
    /// `active` rows and `locks`; unchanged where a guarded inequality is a sticking contact
    /// or a roll limit.
    pub(crate) fn holding(
        mut self,
        active: &[Active],
        locks: &[(JointId, usize, f64)],
        options: &Options,
    ) -> Self {
        if self.falsi && options.stop_search == crate::solver::options::StopSearch::Projected {
            self.held = Some(super::hold::Held {
                active: active.to_vec(),
                locks: locks.to_vec(),
            });
        }
        self
    }

    /// The guard with the contacts `rows` that let go of a floating body (module `let_go`)
    /// guarded by their true gap instead of the obstacle's tangent plane: at an edge of the
    /// obstacle that plane is one of two faces, and the motion that opens the gap may cross
    /// it. Along such a motion the signed distance to the convex obstacle grows from the
    /// start, so it cannot be stepped through.
    pub(crate) fn with_true_gaps(mut self, rows: &[Unilateral]) -> Self {
        for (k, u) in self.inactive.iter().enumerate() {
            if rows.contains(u) {
                self.planes[k] = None;
            }
        }
        self
    }

    /// Number of guarded inequalities: the inactive ones, then the roll limits.
    pub(super) fn len(&self) -> usize {
        self.inactive.len() + self.rolls.len()
    }

    /// Whether guarded inequality `k` is a roll limit (not an inequality to activate).
    pub(crate) fn is_roll_limit(&self, k: usize) -> bool {
        k >= self.inactive.len()
    }

    /// Dimensionless gap of inequality `k` (against an obstacle: to its plane of `planes`; a
    /// roll limit's margin after the inactive ones).
    pub(super) fn gap(&self, k: usize, q: &DVector<f64>, branches: &Branches) -> f64 {
        self.gap_sharing(k, q, branches, &mut None)
    }

    /// [`Guard::gap`], with the joint angle of the last stop evaluated in `last` (a joint's
    /// lower and upper stops are consecutive and read the same angle: computed once).
    fn gap_sharing(
        &self,
        k: usize,
        q: &DVector<f64>,
        branches: &Branches,
        last: &mut Option<(JointId, f64)>,
    ) -> f64 {
        let Some(u) = self.inactive.get(k) else {
            return self.rolls[k - self.inactive.len()].margin(self.model, q);
        };
        let g = match (self.planes[k], u) {
            (Some((o, n)), Unilateral::Contact { point, .. }) => {
                n.dot(&(unilateral::point_world(self.model, *point, q) - o))
                    - self.model.contact_points[*point].radius
            }
            (
                _,
                Unilateral::Limit {
                    joint,
                    bound,
                    value,
                },
            ) => {
                let theta = match *last {
                    Some((j, theta)) if j == *joint => Some(theta),
                    _ => unilateral::limit_angle(self.model, *joint, q, branches),
                };
                *last = theta.map(|t| (*joint, t));
                theta.map_or(f64::INFINITY, |t| unilateral::limit_gap(t, *bound, *value))
            }
            _ => unilateral::gap(self.model, u, q, branches).unwrap_or(f64::INFINITY),
        };
        dimensionless(self.model, u, g)
    }

    /// The lowest dimensionless gap and its inequality.
    fn lowest(&self, q: &DVector<f64>, branches: &Branches) -> Option<(usize, f64)> {
        self.lowest_closing(q, branches, None)
    }

    /// [`Guard::lowest`] over the inequalities that can stop a step from a point where their
    /// gaps are `start`: an inequality at its boundary there (within `tol`, a row just
    /// released) whose gap has not decreased is moving away from it and does not count.
    fn lowest_closing(
        &self,
        q: &DVector<f64>,
        branches: &Branches,
        start: Option<&[f64]>,
    ) -> Option<(usize, f64)> {
        let mut last = None;
        (0..self.len())
            .map(|k| (k, self.gap_sharing(k, q, branches, &mut last)))
            .filter(|&(k, g)| start.is_none_or(|s| self.closing(s[k], g)))
            .min_by(|a, b| a.1.total_cmp(&b.1))
    }

    /// Whether an inequality whose gap went from `start` to `g` can stop the step: all but one
    /// at its boundary at the start (within `tol`) whose gap has not decreased since.
    fn closing(&self, start: f64, g: f64) -> bool {
        start.abs() > self.tol || g < start
    }

    /// Whether the step from `from` to `to` brings one of the inequalities closer to its
    /// boundary (a linear descent may then end on it, and is not unbounded).
    pub(crate) fn approaching(&self, sys: &System, from: &DVector<f64>, to: &DVector<f64>) -> bool {
        let b = &sys.problem.cons.branches;
        let (mut at_to, mut at_from) = (None, None);
        (0..self.len()).any(|k| {
            self.gap_sharing(k, to, b, &mut at_to)
                < self.gap_sharing(k, from, b, &mut at_from) - self.tol
        })
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
        // The gaps at the start: an inequality touching there (a row released at the end of
        // the last round, whose step lifts it by less than `tol` at first) stops the step only
        // if it closes (`closing`); else the bracket would stop at once on it.
        let start: Vec<f64> = {
            let b = &sys.problem.cons.branches;
            let mut last = None;
            (0..self.len())
                .map(|k| self.gap_sharing(k, q, b, &mut last))
                .collect()
        };
        if self.falsi {
            let b = &sys.problem.cons.branches;
            g_lo = self.lowest_closing(q, b, Some(&start)).map(|x| x.1);
            g_hi = q_alpha
                .and_then(|qa| self.lowest_closing(qa, b, Some(&start)))
                .map(|x| x.1);
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
            let Some((_, g)) = self.lowest_closing(&qm, &sys.problem.cons.branches, Some(&start))
            else {
                lo = mid;
                q_lo = qm;
                continue;
            };
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
            .filter(|&k| {
                let g = self.gap(k, &q_lo, branches);
                g <= self.tol && self.closing(start[k], g)
            })
            .collect();
        if touching.is_empty() {
            return None;
        }
        Some((q_lo, touching))
    }
}

/// Projects `q` onto the joints and the `active` rows (`assemble::project`). A step is guarded
/// against an obstacle's tangent plane at the round's start, which extends past the
/// obstacle's edges: a box tipping over the edge of a finite ramp meets the plane of the top
/// face beyond the edge, 0.089 m from the ramp. If the projection fails, the rows of `hits`
/// (just added where a step met its plane) whose true gap is open beyond `tol` leave `active`
/// again and the projection is retried; the next round guards them against the tangent plane
/// at the new point.
///
/// # Errors
/// As `assemble::project`, when the retry fails too or no such row was added.
#[allow(clippy::too_many_arguments)]
pub(crate) fn project_past_false_hits(
    model: &Model,
    q: DVector<f64>,
    branches: &mut Branches,
    locks: &[(JointId, usize, f64)],
    active: &mut Vec<Active>,
    hits: &[Unilateral],
    options: &Options,
    tol: f64,
) -> crate::Result<DVector<f64>> {
    let start = (!hits.is_empty()).then(|| (q.clone(), branches.clone()));
    let first = crate::solver::assemble::project(model, q, branches, locks, active, options);
    let (Err(_), Some((q, from))) = (&first, start) else {
        return first;
    };
    let before = active.len();
    active.retain(|a| {
        !hits.contains(&a.row)
            || unilateral::gap(model, &a.row, &q, &from)
                .is_none_or(|g| dimensionless(model, &a.row, g) <= tol)
    });
    if active.len() == before {
        return first;
    }
    *branches = from;
    crate::solver::assemble::project(model, q, branches, locks, active, options)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::constraints::Constraints;
    use crate::model::Friction;
    use crate::solver::inequality::active_set::{activate, inequalities};
    use crate::solver::system::Backend;
    use crate::urdf::{load_str, ImportOptions};

    /// A link on a hinge 0.04 m above the ground, from the horizontal, turned toward the
    /// ground (the direction that closes its sphere's gap fastest): regula falsi and bisection
    /// find the touchdown at the same boundary (the gap within `tol`, the contact touching,
    /// the joint satisfied, the two points within `10 tol L` of each other); the guard of a
    /// sticking contact keeps the bisection.
    #[test]
    fn regula_falsi_and_bisection_land_on_the_same_boundary() {
        let text = r#"<robot name="tip" xmlns:mech="urn:urdf-mech:1">
  <link name="world"/>
  <link name="link0"><inertial><origin xyz="0.025 0 0"/><mass value="0.05"/><inertia ixx="1e-6" ixy="0" ixz="0" iyy="1.1e-5" iyz="0" izz="1.1e-5"/></inertial><collision><origin xyz="0.05 0 0"/><geometry><sphere radius="0.01"/></geometry></collision></link>
  <joint name="joint0" type="continuous"><parent link="world"/><child link="link0"/><origin xyz="0 0 0.04"/><axis xyz="0 1 0"/></joint>
  <mech:ground/>
</robot>"#;
        let model = load_str(text, "tip.urdf", &ImportOptions::default())
            .unwrap()
            .model;
        let options = Options::default();
        let tol = options.gap_tolerance;
        let start = crate::State::initial(&model);
        let mut branches = start.branches.clone();
        let q = crate::solver::assemble::assemble(&model, start.q, &mut branches, &[], &options)
            .unwrap();
        let all = inequalities(&model, &options);
        let touches = |u: &Unilateral| {
            unilateral::gap(&model, u, &q, &branches)
                .is_some_and(|g| dimensionless(&model, u, g) <= tol)
        };
        let active: Vec<Active> = all
            .iter()
            .filter(|u| touches(u))
            .map(|&u| activate(&model, &options, u, &q))
            .collect();
        let inactive: Vec<Unilateral> = all.iter().filter(|u| !touches(u)).copied().collect();
        assert!(active.is_empty() && inactive.len() == 1);
        let q = crate::solver::assemble::project(&model, q, &mut branches, &[], &active, &options)
            .unwrap();
        let mut guard = Guard::new(&model, &options, inactive, &active, tol, &q);
        assert!(guard.falsi);
        let cons = Constraints::new(&model, &[])
            .with_active(&model, &active)
            .on_branches(branches);
        let mut sys = System::new(&model, cons, Backend::of(&model, &options));
        let part = sys.partition(&q);
        let eval = sys.evaluate(&q, &part).unwrap();
        // The direction of the independent coordinates that closes the lowest gap fastest
        // (its gradient by forward differences through the corrector).
        let tolerance = options.constraint_tolerance;
        let (k, g0) = guard.lowest(&q, &sys.problem.cons.branches).unwrap();
        let mut dq = DVector::zeros(q.len());
        for &c in &part.independent {
            let mut qt = q.clone();
            qt[c] += 1e-6;
            sys.correct_from(&mut qt, &part, tolerance, 25, None)
                .unwrap();
            dq[c] = -(guard.gap(k, &qt, &sys.problem.cons.branches) - g0) / 1e-6;
        }
        dq *= 0.05 / dq.amax();
        // The shortest step (doubling) that the corrector manages and that violates a gap.
        let mut alpha = 0.125;
        let q_alpha = loop {
            let mut qt = &q + &dq * alpha;
            let ok = sys.correct_from(&mut qt, &part, tolerance, 25, Some(&eval.factors));
            if ok.is_ok() && guard.violated(&sys, &qt) {
                break qt;
            }
            alpha *= 2.0;
            assert!(alpha < 1e3, "no gap is reached along the descent");
        };
        let (qf, touching_f) = guard
            .boundary(
                &mut sys,
                &q,
                &dq,
                alpha,
                Some(&q_alpha),
                &part,
                &options,
                &eval,
            )
            .unwrap();
        guard.falsi = false;
        let (qb, touching_b) = guard
            .boundary(
                &mut sys,
                &q,
                &dq,
                alpha,
                Some(&q_alpha),
                &part,
                &options,
                &eval,
            )
            .unwrap();
        assert_eq!(touching_f, vec![0]);
        assert_eq!(touching_b, vec![0]);
        let apart = (&qf - &qb).amax() / model.length_scale;
        assert!(apart <= 10.0 * tol, "{apart}");
        for qx in [&qf, &qb] {
            let (_, lowest) = guard.lowest(qx, &sys.problem.cons.branches).unwrap();
            assert!(lowest.abs() <= tol, "lowest gap {lowest}");
            sys.residual(qx);
            assert!(sys.dimensionless_residual() <= 1e-8);
        }
        let sticking = Options {
            friction: Friction::Stick,
            ..options
        };
        let g = Guard::new(&model, &sticking, guard.inactive.clone(), &active, tol, &q);
        assert!(!g.falsi);
    }
}
