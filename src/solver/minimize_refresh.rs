//! Stage 7 of the minimizer (module `solver::minimize`): the partition refreshed after an
//! accepted step, or made anew where the line search failed (paper step (b); docs/method.md,
//! "Re-partition"). A fresh partition resets the quasi-Newton matrix.

use super::{Search, PIVOT_DRIFT};
use crate::solver::partition::Partition;
use crate::solver::step::quasi_newton::QuasiNewton;
use crate::solver::system::{Backend, System};

/// Stage 7: re-partitions when `Φ_u` is ill-conditioned, or (dense, tree) when its pivots drifted
/// and a fresh full pivoting differs, or (sparse, second-pass choices) when the partition at `q`
/// makes other ones, or (sparse or tree factors) when a fresh one differs after a step that
/// needed a failed correction (a folded chart: docs/method.md, "Re-partition"). Not on any
/// change (nearly equal levers would flip from step to step). `None` if evaluating `q` fails.
pub(super) fn refresh_partition(
    sys: &mut System,
    s: &mut Search,
    corrector_failed: bool,
) -> Option<()> {
    let drifted = match (s.eval.factors.pivot_ratio(), s.pivot_reference) {
        (Some(now), Some(reference)) => now < PIVOT_DRIFT * reference,
        _ => false,
    };
    if s.eval.factors.ill_conditioned() {
        repartition(sys, s)?;
    } else if drifted {
        // The dependent coordinates chosen at the start of this partition are losing their
        // hold: a fresh full pivoting at `q`, adopted if it differs.
        let fresh = sys.partition(&s.q);
        if !fresh.same_split(&s.part) {
            adopt(sys, s, fresh)?;
        }
        s.pivot_reference = s.eval.factors.pivot_ratio();
    } else if !s.part.second_pass.is_empty() || (corrector_failed && sys.backend != Backend::Dense)
    {
        let fresh = sys.partition(&s.q);
        if fresh.second_pass != s.part.second_pass
            || (s.part.second_pass.is_empty() && !fresh.same_split(&s.part))
        {
            adopt(sys, s, fresh)?;
        }
    }
    Some(())
}

/// A fresh partition at `q` (paper step (b)), evaluated, with a reset quasi-Newton matrix.
pub(super) fn repartition(sys: &mut System, s: &mut Search) -> Option<()> {
    let part = sys.partition(&s.q);
    s.diag.repartitions += 1;
    s.eval = sys.evaluate(&s.q, &part)?;
    s.qn = QuasiNewton::new(part.independent.len(), s.method);
    s.part = part;
    s.pivot_reference = s.eval.factors.pivot_ratio();
    Some(())
}

/// Replaces the partition by `fresh`, evaluated at `q`, with a reset quasi-Newton matrix.
fn adopt(sys: &mut System, s: &mut Search, fresh: Partition) -> Option<()> {
    s.diag.repartitions += 1;
    s.eval = sys.evaluate(&s.q, &fresh)?;
    s.part = fresh;
    s.qn = QuasiNewton::new(s.part.independent.len(), s.method);
    Some(())
}
