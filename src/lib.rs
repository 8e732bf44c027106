//! restpose: the static equilibrium (rest pose) of spatial mechanisms described in URDF.
//!
//! ```text
//! URDF text --urdf--> Model (immutable) + State (q) --solver--> (State, Report) --export-->
//! ```
//!
//! Every moving body has 7 Cartesian coordinates (origin position and Euler parameters);
//! joints are constraint equations `Φ(q) = 0`, with one normalization row `pᵀp − 1` per body.
//! The equilibrium minimizes the potential energy `V(q)` subject to `Φ = 0`, solved by
//! generalized coordinate partitioning (Nikravesh & Srinivasan 1985): full-pivoting LU of
//! `Φ_q` splits `q` into dependent `u` and independent `v`, the influence matrix
//! `H = −Φ_u⁻¹ Φ_v` gives the reduced gradient `∂V/∂v = V_v + V_u H`, a Newton corrector keeps
//! the constraints, and Newton (default), BFGS or DFP minimize over `v`.
//!
//! Conventions: SI units; right-handed frames; default gravity `(0, 0, −9.81)`; Euler
//! parameters `e0 = w, e1 = x, e2 = y, e3 = z`; URDF `rpy` = `Rz(y) Ry(p) Rx(r)`; transforms
//! are named for what they map (`world_from_body`).
//!
//! ```
//! let loaded = restpose::urdf::load_file("robots/pendulum.urdf", &Default::default())?;
//! let (state, report) = restpose::solve(&loaded.model, &Default::default())?;
//! let result = restpose::export::json::AnalysisResult::new(&loaded.model, &state, &report);
//! assert!(result.converged);
//! # Ok::<(), restpose::Error>(())
//! ```

pub mod constraints;
pub mod cpu;
pub mod error;
pub mod export;
pub mod forces;
pub mod generate;
pub mod geometry;
pub(crate) mod jet;
pub mod joint;
pub mod kinematics;
#[cfg(test)]
pub(crate) mod lcg;
pub mod math;
pub mod model;
pub mod names;
pub mod solver;
pub mod state;
pub mod urdf;
pub mod verify;
#[cfg(feature = "viewer")]
pub mod view;

pub use error::{Error, Result};
pub use model::Model;
pub use solver::{
    solve, solve_from, Limits, LinearAlgebra, Method, Options, Report, StopSearch, Termination,
    Topple,
};
pub use state::State;
