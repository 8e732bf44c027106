//! The friction verdict: does a distribution of the stop and contact forces
//! `λ(z) = λ₀ + N z` balance the pose with each contact inside its friction cone
//! (`‖t_i‖ ≤ μ n_i`) and each stop within its joint's `effort`, and how much friction does it
//! need at least (`required_mu = min_z max_i ‖t_i(z)‖ / n_i(z)`)?
//!
//! - `verdict`: the verdict, the Dinkelbach-type iteration for `required_mu` and the
//!   least-norm distribution (the entry points).
//! - `support`: the stops and contacts of a pose with their rows, `λ(z) = λ₀ + N z`.
//! - `shortcut`: what is decided without cone programs (a lower bound from one plane ground).
//! - `conic`: the second-order cone programs, solved by Clarabel.

mod conic;
mod shortcut;
mod support;
mod verdict;

pub(crate) use verdict::{
    distribute, effort_check, force_scale, holders_of, needs_mu, settle_states, slips, verdict,
    Chosen, Distribution,
};
