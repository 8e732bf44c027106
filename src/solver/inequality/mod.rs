//! Inequalities: joint stops and contacts `g(q) ≥ 0`, by an active-set iteration around the
//! equality-constrained solve (the active `g_k` join `Φ` as rows `g_k(q) = 0`).
//!
//! - `active_set`: the iteration (which inequality joins, which leaves, when it stops).
//! - `guard`: where a step first reaches an inactive inequality's boundary.
//! - `bend`: the search path projected onto the joint stops (several reached at once).
//! - `hold`: frictionless contacts held on their grounds along a step (several met at once).
//! - `release`: when active rows leave (early, before a round is stationary; several at once).
//! - `release_trial`: several stops leave together only if the step moves off them.
//! - `let_go`: contacts that no longer hold a floating body when a round stalls.
//! - `patch`: rounded hulls (mesh feet) rolling on one sticking pivot.
//! - `stall`: a round whose steps shrink towards an obstacle's edge ends.
//! - `rolling`: sticking spheres re-anchored where they touch after rolling.
//! - `together`: two rolling hulls meeting their next vertices in the same step.
//! - `roll_on`: a step cut at a rolling hull's next vertex goes on after the hand-over.
//! - `describe`: the report's stops and contacts from the active rows' multipliers.
//! - `distribution`: the least-norm force distribution of a statically indeterminate support.

pub(crate) mod active_set;
pub(crate) mod bend;
pub(crate) mod describe;
pub(crate) mod distribution;
pub(crate) mod guard;
pub(crate) mod hold;
pub(crate) mod let_go;
pub(crate) mod patch;
pub(crate) mod release;
pub(crate) mod release_trial;
pub(crate) mod roll_on;
pub(crate) mod rolling;
pub(crate) mod slide;
pub(crate) mod stall;
pub(crate) mod together;
#[cfg(test)]
mod values_tests;
