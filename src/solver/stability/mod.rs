//! Stability of a rest pose: the verdict from the lowest eigenvalues of the reduced Hessian
//! `Ĥ = Zᵀ W Z` (`Z` a basis of the tangent space of the active rows, `W` the Lagrangian
//! Hessian): stable when `λ_min > t`, unstable when `λ_min < −t`, neutral otherwise
//! (`t = 10⁻¹⁰ max(λ_max, 1)`).
//!
//! - `eigen`: guarded symmetric eigendecomposition `A = V Λ Vᵀ` (dense).
//! - `svd`: guarded singular value decomposition `A = U Σ Vᵀ` (dense; nalgebra's checked,
//!   one-sided Jacobi where it fails).
//! - `spectrum`: the low end of the spectrum of `Ĥ`, exact (dense) or by Lanczos on `Ĥ⁻¹`
//!   (sparse, many degrees of freedom); also used by the minimizer to leave saddles.
//! - `inertia`: the verdict from the inertia of the shifted KKT matrix, without eigenvalues.
//! - `cone`: the verdict on the critical cone, where stops and contacts touch without force.
//! - `leave`: a converged point only the cone shows unstable, left along its direction of
//!   negative curvature with the stops and contacts it opens released.
//! - `at_rest`: what the minimizer computes at a point: the exact spectrum where cheap, else
//!   the inertia verdict, and Lanczos only to leave a saddle.
//! - `verdict`: the verdict and mode shapes from the eigenpairs, and the entry points.
//! - `joint_space`: the reported eigenvalues and modes in joint coordinates,
//!   `H_θ = T⁻ᵀ Ĥ T⁻¹` (physical units, independent of the partition).

pub(crate) mod at_rest;
pub(crate) mod blocks;
pub(crate) mod cone;
pub(crate) mod eigen;
pub(crate) mod inertia;
pub(crate) mod joint_space;
pub(crate) mod largest;
pub(crate) mod leave;
pub(crate) mod spectrum;
pub(crate) mod svd;
pub(crate) mod verdict;
