//! The large-scale path: sparse partition, sparse LU of `Φ_u`, block-sparse Lagrangian Hessian
//! and the Newton step from the sparse KKT system.
//!
//! Cartesian coordinates make `Φ_q` very sparse: each joint row touches the 14 coordinates of
//! two bodies, each normalization row four. Every step of an iteration here costs `O(N)` in the
//! number of bodies `N` for chains, trees and ladders:
//! - partition (module `partition`): elimination body by body with threshold pivoting, instead
//!   of dense full pivoting (`O(N³)`); the same pivots on dense copies of each body's rows
//!   (module `fill_free`, with `rows` and `block`) wherever the fill stays between a few
//!   bodies (trees, ladders), the sparse elimination otherwise;
//! - `Φ_u δu = −Φ`, `Φ_uᵀ μ = V_uᵀ` (module `factor`): faer's sparse LU, symbolic analysis
//!   once per partition, numeric factorization per evaluation;
//! - the Newton step (module `kkt`): the sparse KKT system instead of the dense reduced Hessian
//!   `Zᵀ W Z`, which is dense for a chain;
//! - the stability verdict (`solver::stability::spectrum`): Lanczos on `(Zᵀ W Z)⁻¹` through the KKT
//!   factors when the degrees of freedom are many.

pub(crate) mod block;
pub(crate) mod factor;
pub(crate) mod fill_free;
pub(crate) mod hessian;
pub(crate) mod kkt;
pub(crate) mod partition;
#[cfg(test)]
mod partition_tests;
pub(crate) mod pattern;
pub(crate) mod rows;
pub(crate) mod shifts;
