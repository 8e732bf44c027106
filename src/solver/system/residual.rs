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
//! **Rounding floor.** `Φ` is evaluated in floating point from coordinates as large as the
//! mechanism's extent `m = max(1, max_b ‖x_b‖∞ / L)` (in characteristic lengths): a row in
//! m^k carries a rounding error of a few units in the last place of `m^k` (in `L^k`), a
//! dimensionless row of a few `ε`. Below [`ROUNDING_ULPS`]` · ε · m^k` on every row
//! ([`Scaling::at_rounding_floor`]) no step of the corrector can be resolved from rounding: a
//! chain of 1,000 links hanging 200 m deep evaluates `‖D Φ‖∞` at `1.4 – 4.3 · 10⁻¹³`
//! whatever the step, above the chord steps' target `10⁻³` of the tolerance.
//!
//! What is *reported* as `constraint_residual` (the analysis's diagnostics, `verify`) is the
//! raw `‖Φ‖∞` in m or rad, a JSON field kept as it was; `verify` reports `‖D Φ‖∞` beside it
//! as `scaled_constraint_residual`.

use super::problem::Scaling;
use crate::constraints::Constraints;
use nalgebra::DVector;

/// Default tolerance on `‖D Φ‖∞` of the solver (`Options::constraint_tolerance`).
pub(crate) const TOLERANCE: f64 = 1e-10;

/// The redundant rows are satisfied only to rounding after the independent ones converge:
/// all rows are accepted at `max(tolerance, REDUNDANT_FLOOR)` (dimensionless).
pub(crate) const REDUNDANT_FLOOR: f64 = 1e-8;

/// The rounding floor of a row in m^k, in units in the last place of `m^k` (module docs).
pub(crate) const ROUNDING_ULPS: f64 = 8.0;

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

    /// The extent `m = max(1, max_b ‖x_b‖∞ / L)` of the configuration `q` in characteristic
    /// lengths (the position columns are those scaled by `L`, module `problem`).
    pub(crate) fn extent(&self, q: &DVector<f64>) -> f64 {
        q.as_slice()
            .chunks_exact(7)
            .zip(self.columns.chunks_exact(7))
            .flat_map(|(x, s)| (0..3).map(move |k| x[k].abs() / s[k]))
            .fold(1.0, f64::max)
    }

    /// Whether every row of `rows` is within its rounding floor at a configuration of extent
    /// `m`: `|D_i Φ_i| ≤ ROUNDING_ULPS · ε · m^{k_i}` (module docs).
    pub(crate) fn at_rounding_floor(
        &self,
        cons: &Constraints,
        phi: &DVector<f64>,
        rows: &[usize],
        m: f64,
    ) -> bool {
        let ulp = ROUNDING_ULPS * f64::EPSILON;
        let floor = [ulp, ulp * m, ulp * m * m];
        rows.iter().all(|&i| {
            let k = cons.length_power(i);
            let f = usize::try_from(k)
                .ok()
                .and_then(|k| floor.get(k).copied())
                .unwrap_or_else(|| ulp * m.powi(k));
            self.row_residual(phi, i) <= f
        })
    }
}
