//! Two rolling hulls meeting their next vertices together. A step cut where a first sticking
//! contact touches (module `guard`, at `α₁`) goes on to where a second one, closing as well,
//! touches just after it, at `α₂ ≤ (1 + NEAR) α₁`, and both join the active set at that point;
//! only where both are the next vertices of rolling hulls (each on the patch of a sticking
//! pivot of its own link, module `patch`), on different links, one per link.
//!
//! Along the cut step the gaps are closing at rates `ġ_k ≈ (g_k(α₁) − g_k(0)) / α₁ < 0`, so a
//! contact still open at the cut touches at about `α_k = α₁ + g_k(α₁) / |ġ_k|`; the root of the
//! last of them is then found by the secant method on `g_k(correct(q + α dq))` alone. At `α₂`
//! the contacts touching at `α₁` have sunk by about `|ġ| (α₂ − α₁)`; each is anchored at its
//! projection on the ground (`active_set::activate`), never above it, and the next round's
//! projection lifts it back onto it. The point is taken if it violates no other inequality and
//! does not raise the merit beyond rounding, as the cut.
//!
//! Bolt falling over on its mesh feet and thighs (`robots/bolt`, servos of 1000 N m/rad about
//! its SRDF `standing` state, sticking) rolls both legs at once: 5 of its cuts met the other
//! leg's next vertex within 5 % of the same step, each of which took a round and a Newton step
//! cut at once (below 1 % of its length); met together, 54 iterations in 66 rounds become 49
//! in 60 (V 0.931723 → 0.931725 J). Accepting any second sticking contact (not only a hull's
//! next vertex) also moved Go2's and Romeo's standing rests (by 9·10⁻⁸ and 2·10⁻¹⁰ J).

use super::active_set::Guard;
use crate::constraints::unilateral::{Active, Unilateral};
use crate::solver::options::Options;
use crate::solver::partition::Partition;
use crate::solver::system::{Eval, System};
use nalgebra::DVector;

/// The largest further fraction `(α₂ − α₁) / α₁` of a cut step within which a second
/// sticking contact is met together with the first.
pub(crate) const NEAR: f64 = 0.05;

/// Secant steps on the second contact's gap.
const SECANT_STEPS: usize = 8;

impl Guard<'_> {
    /// The guard knowing which inactive contacts lie on the patch of a sticking pivot among
    /// `active` (module `patch`): the next vertices of rolling hulls.
    pub(crate) fn rolling_on(mut self, active: &[Active]) -> Self {
        self.on_patch = self
            .inactive
            .iter()
            .map(|u| match *u {
                Unilateral::Contact { point, ground } => {
                    super::patch::near_pivot(self.model, active, point, ground)
                }
                Unilateral::Limit { .. } => false,
            })
            .collect();
        self
    }

    /// Whether inactive inequality `k` lies on the patch of a sticking pivot.
    pub(crate) fn rolls(&self, k: usize) -> bool {
        self.on_patch.get(k).copied().unwrap_or(false)
    }

    /// Whether guarded inequality `k` is a contact that sticks (anchored where it lands).
    fn sticking(&self, k: usize, options: &Options) -> bool {
        match self.inactive.get(k) {
            Some(Unilateral::Contact { point, .. }) => options
                .contact()
                .sticks(&self.model.contact_points[*point].settings),
            _ => false,
        }
    }

    /// From the cut `(q_cut, touching)` of the step `dq` at `q` (module `guard`), the point
    /// `α₂` further where the sticking contacts closing within [`NEAR`] of the cut touch too,
    /// and every contact touching there (module docs); `None` where there is none, the secant
    /// misses it, or the point violates another inequality.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn together(
        &self,
        sys: &mut System,
        q: &DVector<f64>,
        dq: &DVector<f64>,
        cut: (&DVector<f64>, &[usize]),
        alpha: f64,
        part: &Partition,
        options: &Options,
        eval: &Eval,
    ) -> Option<(DVector<f64>, Vec<usize>)> {
        let (q_cut, touching) = cut;
        // Only two hulls rolling at once: the cut met a pivot's next vertex (and the second
        // is another pivot's next vertex, below).
        if !touching.iter().all(|&k| self.sticking(k, options))
            || !touching.iter().any(|&k| self.rolls(k))
        {
            return None;
        }
        // The cut's step length, from the independent coordinates (`q + α₁ dq` there).
        let c = *part
            .independent
            .iter()
            .max_by(|&&a, &&b| dq[a].abs().total_cmp(&dq[b].abs()))?;
        if dq[c] == 0.0 {
            return None;
        }
        let a1 = (q_cut[c] - q[c]) / dq[c];
        if a1.is_nan() || a1 <= 0.0 {
            return None;
        }
        let branches = sys.problem.cons.branches.clone();
        let near: Vec<(usize, f64)> = (0..self.inactive.len())
            .filter(|k| !touching.contains(k) && self.sticking(*k, options))
            .filter_map(|k| {
                let (g0, g1) = (self.gap(k, q, &branches), self.gap(k, q_cut, &branches));
                let rate = (g1 - g0) / a1;
                (rate < 0.0 && g1 > self.tol).then(|| (k, a1 + g1 / -rate))
            })
            .filter(|&(_, ak)| ak <= a1 * (1.0 + NEAR) && ak <= alpha)
            .collect();
        // One per link, the first to touch, on links other than those of the cut (a link's
        // next vertex is its roll, not a touch of its own).
        let body = |k: usize| match self.inactive[k] {
            Unilateral::Contact { point, .. } => Some(self.model.contact_points[point].body),
            Unilateral::Limit { .. } => None,
        };
        let mut near: Vec<(usize, f64)> = near
            .iter()
            .copied()
            .filter(|&(k, ak)| {
                !touching.iter().any(|&t| body(t) == body(k))
                    && !near
                        .iter()
                        .any(|&(j, aj)| body(j) == body(k) && (aj, j) < (ak, k))
            })
            .collect();
        near.sort_by(|a, b| a.1.total_cmp(&b.1));
        let near: Vec<(usize, f64)> = near.into_iter().filter(|&(k, _)| self.rolls(k)).collect();
        let &(last, a_last) = near.iter().max_by(|a, b| a.1.total_cmp(&b.1))?;
        // The secant on the last one's gap, from the cut.
        let point = |sys: &mut System, a: f64| -> Option<DVector<f64>> {
            let mut qm = q_cut + dq * (a - a1);
            for &c in &part.independent {
                qm[c] = q[c] + dq[c] * a;
            }
            sys.correct_from(
                &mut qm,
                part,
                options.constraint_tolerance,
                options.max_corrector_iterations,
                Some(&eval.factors),
            )
            .ok()?;
            Some(qm)
        };
        let (mut a_prev, mut g_prev) = (a1, self.gap(last, q_cut, &branches));
        let mut a = a_last;
        let mut found = None;
        for _ in 0..SECANT_STEPS {
            let qm = point(sys, a)?;
            let g = self.gap(last, &qm, &sys.problem.cons.branches);
            if g.abs() <= self.tol {
                found = Some(qm);
                break;
            }
            if g == g_prev {
                return None;
            }
            let next = a - g * (a - a_prev) / (g - g_prev);
            (a_prev, g_prev) = (a, g);
            a = next;
            if a.is_nan() || a <= a1 || a > a1 * (1.0 + 2.0 * NEAR) || a > alpha {
                return None;
            }
        }
        let q2 = found?;
        let b = &sys.problem.cons.branches;
        let mut met: Vec<usize> = touching.to_vec();
        for k in 0..self.len() {
            if met.contains(&k) {
                continue;
            }
            let g = self.gap(k, &q2, b);
            let with = near.iter().any(|&(j, _)| j == k);
            if with && g <= self.tol {
                met.push(k);
            } else if g < -self.tol {
                return None;
            }
        }
        (met.len() > touching.len()).then_some((q2, met))
    }
}
