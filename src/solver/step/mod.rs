//! The step of the minimizer (module `minimize`): its direction, its length and the path it
//! follows.
//!
//! - `kkt_direction`: the Newton direction of the sparse path from the KKT system
//!   `[W Φ_qᵀ; Φ_q 0] [δq; λ] = [−S(V_qᵀ − Φ_qᵀ μ); 0]`.
//! - `direction`: the choice of the reduced step among the ones below.
//! - `escape`: the dense Newton step along the path, leaving maxima and saddles along every
//!   direction of negative curvature.
//! - `newton`: the dense Newton step from the eigen-decomposition of the Hessian along the
//!   search path.
//! - `path_cholesky`: on small trees away from stationary points, the Newton step along the
//!   path by Cholesky of `Ĥ + C` summed from `Ĥ` formed and not decomposed.
//! - `path_hessian`: that Hessian, `Ĥ + C`, `C` the search path's curvature times `∇f`;
//!   `tr_product`: its per-edge products `aᵀ b` over the columns that are not zero.
//! - `quasi_newton`: the BFGS / DFP inverse-Hessian approximation `B ≈ Ĥ⁻¹`.
//! - `step_cap`: the step limit, every body's Euler parameters moving by at most `max_step`.
//! - `line_search`: the backtracking line search along a reduced step `d` (`δq = Z d`).
//! - `retraction`: the search path of the line search, `δq` followed as rigid motions along
//!   the spanning tree (`θ(α) = θ + α θ̇` on every tree joint).
//! - `second_order`: the second-order correction of a trial point, the rows the path leaves
//!   open closed in all coordinates with the KKT factors of the step.

pub(super) mod direction;
pub(super) mod escape;
pub(super) mod kkt_direction;
pub(super) mod line_search;
pub(super) mod newton;
pub(super) mod path_cholesky;
pub(super) mod path_hessian;
pub(super) mod quasi_newton;
pub(super) mod retraction;
pub(super) mod second_order;
pub(super) mod step_cap;
mod tr_product;
