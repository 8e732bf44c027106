//! Tree-structured factorizations (`--linear-algebra tree`): the KKT matrix of a Newton step
//! and `Φ_u` factored body by body along the kinematic tree, leaves first, with fixed-size
//! dense blocks and no fill, in `O(N)` for `N` bodies; the few unknowns that do not fit the
//! tree (loop rows, bodies a loop couples) form a border eliminated last through its dense
//! Schur complement.
//!
//! - `dense`: the block kernels (LDLᵀ without pivoting, LU with partial pivoting);
//! - `fixed`: LDLᵀ, LU, the Schur update and the solves' products unrolled for a chain's and a
//!   ladder's block sizes;
//! - `phi_u`: `Φ_u` as a block upper triangular matrix (corrector, multipliers, tangent steps);
//! - `segments`: its off-diagonal entries as dense row × column segments for the solves;
//! - `shape`: the KKT matrix's nodes, parents, border and value slots, once per partition;
//! - `nodes`: its nodes' unknowns, the pairs of nodes coupled by a value, the bordered tree;
//! - `fused`: the Newton step's assembly of `W`, its terms added into the tree's body-pair
//!   blocks and stored into the 13 × 13 blocks in one pass;
//! - `norm`: the row sums of `|K|` for `‖K‖∞`, node by node;
//! - `kkt`: its block LDLᵀ (block LU as the fallback), solves and refinement;
//! - `border`: the dense Schur complement of the border;
//! - `merge`: super-nodes where the border would be too large (a ladder: a loop per rung).
//!
//! The sparse path (module `sparse`) stays the reference and the fallback: where a partition's
//! structure does not fit (a super-node above its limit), the system uses it instead.

mod border;
pub(crate) mod dense;
mod fixed;
pub(crate) mod fused;
mod jac_runs;
pub(crate) mod kkt;
mod merge;
#[cfg(test)]
mod merge_tests;
mod nodes;
mod norm;
pub(crate) mod phi_u;
mod segments;
mod shape;
#[cfg(test)]
mod shape_tests;
#[cfg(test)]
mod tests;
