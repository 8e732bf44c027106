//! Evaluation of the partitioned problem at a configuration: the corrector, the reduced
//! gradient and the reduced Hessian.
//!
//! With `q = [u; v]`, `Φ_q = [Φ_u Φ_v]` (independent rows only) and `H = −Φ_u⁻¹ Φ_v`:
//! - corrector: Newton on `Φ(u; v) = 0` for fixed `v`: `Φ_u δu = −Φ` (module `corrector`);
//! - multipliers: `Φ_uᵀ μ = V_uᵀ`, so that `V_qᵀ = Φ_qᵀ μ` at equilibrium;
//! - reduced gradient (eq. 37): `∂V/∂v = V_v + V_u H = V_v − Φ_vᵀ μ` (module `reduced`);
//! - reduced Hessian: `Zᵀ (V_qq − Σ_k μ_k Φ_k,qq) Z`, `Z = [H; I]`, exact at feasible points
//!   (module `reduced`; on the sparse path Newton steps come from the KKT system, module
//!   `kkt`).
//!
//! Independent coordinates are scaled, `v = S v̂` (positions by the characteristic length), and
//! gradients and Hessians are reported in the scaled coordinates `v̂`.
//!
//! A [`System`] is a [`Problem`] (model, constraint rows, scaling: built once), a
//! [`Workspace`] (scratch, reused) and a [`Backend`] (dense or sparse, chosen once). The
//! factors of `Φ_u` are module `factors` (dense: module `dense_lu`).

mod augment;
mod backend;
mod base;
mod basis_products;
mod corrector;
mod dense_lu;
mod dense_memo;
mod factors;
mod kkt;
mod kkt_matrix;
mod problem;
mod reduced;
pub(crate) mod residual;
#[cfg(test)]
mod tests;
mod workspace;
#[cfg(test)]
mod zero_weight_tests;

pub(crate) use backend::{is_small_tree, Backend};
pub(crate) use base::System;
pub(crate) use factors::Factors;
#[cfg(test)]
pub(crate) use kkt_matrix::KktMatrix;
pub(crate) use problem::{coordinate_scale, Problem, Scaling};
pub(crate) use reduced::{symmetric_part, Eval};
pub(crate) use workspace::Workspace;
