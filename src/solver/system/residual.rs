//! The constraint residual: one measure, `‖D Φ‖∞`, documented here once.
//!
//! `Φ(q)` has rows in different units: positions in m (a joint's origin coincidence, a
//! contact gap), products of lengths in m² (a distance constraint), and dimensionless rows
//! (rotations, Euler-parameter normalization). Each row in m^k is divided by `L^k`, `L` the
//! mechanism's characteristic length (`Model::length_scale`), so that
//!
//! `r(q) = ‖D Φ(q)‖∞ = max_i |Φ_i(q)| / L^{k_i}`
//!
//! means the same in any length unit. This is the residual every tolerance of the solver
//! applies to (`Options::constraint_tolerance`, default [`TOLERANCE`]): the assembly, the
//! corrector (over the partition's independent rows, [`Scaling::residual_over`], then over
//! every row with the floor [`REDUNDANT_FLOOR`]), and the gaps of the stops and contacts (a
//! gap in m divided by `L`, as its row). `verify`'s tolerance (`Tolerances::constraint`, the
//! same default) bounds the same `‖D Φ‖∞` of a given pose over every row, and the gaps of its
//! stops and contacts in the same scaling, so `analyze --constraint-tolerance` and
//! `verify --constraint-tolerance` mean one thing.
//!
//! What is *reported* as `constraint_residual` (the analysis's diagnostics, `verify`) is the
//! raw `‖Φ‖∞` in m or rad, a JSON field kept as it was; `verify` reports `‖D Φ‖∞` beside it
//! as `scaled_constraint_residual`.

use super::problem::Scaling;
use nalgebra::DVector;

/// Default tolerance on `‖D Φ‖∞` of the solver (`Options::constraint_tolerance`).
pub(crate) const TOLERANCE: f64 = 1e-10;

/// The redundant rows are satisfied only to rounding after the independent ones converge:
/// all rows are accepted at `max(tolerance, REDUNDANT_FLOOR)` (dimensionless).
pub(crate) const REDUNDANT_FLOOR: f64 = 1e-8;

impl Scaling {
    /// `‖D Φ‖∞` over every row.
    pub(crate) fn residual(&self, phi: &DVector<f64>) -> f64 {
        phi.iter()
            .zip(&self.rows)
            .map(|(p, s)| (p * s).abs())
            .fold(0.0, f64::max)
    }

    /// `‖D Φ‖∞` over the rows `rows` (the partition's independent rows).
    pub(crate) fn residual_over(&self, phi: &DVector<f64>, rows: &[usize]) -> f64 {
        rows.iter()
            .map(|&i| (phi[i] * self.rows[i]).abs())
            .fold(0.0, f64::max)
    }

    /// `|D_i Φ_i|`: the dimensionless residual of row `i`.
    pub(crate) fn row_residual(&self, phi: &DVector<f64>, i: usize) -> f64 {
        (phi[i] * self.rows[i]).abs()
    }
}
