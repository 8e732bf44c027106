//! Solver options, with their defaults.

/// Minimization method in the independent coordinates.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Method {
    /// Newton's method with the exact reduced Hessian (modified to be positive definite away
    /// from the minimum) and a backtracking line search.
    #[default]
    Newton,
    /// BFGS quasi-Newton (inverse-Hessian update) with a backtracking line search.
    Bfgs,
    /// Davidon–Fletcher–Powell quasi-Newton, the paper's minimizer.
    Dfp,
}

/// Linear algebra of the solver.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum LinearAlgebra {
    /// Up to 40 bodies (280 coordinates): tree from 3 bodies without closed loops, stops,
    /// contacts, locks or mimics, dense otherwise; above: tree without closed loops, sparse
    /// with them (default).
    #[default]
    Auto,
    /// Dense matrices: full-pivoting partition, dense LU, exact reduced Hessian. `O(N³)`.
    Dense,
    /// Sparse partition, sparse LU (faer), Newton steps from the sparse KKT system. `O(N)` per
    /// iteration for chains, trees and ladders.
    Sparse,
    /// The sparse partition, with `Φ_u` and the KKT system factored body by body along the
    /// kinematic tree (fixed-size blocks, no fill; loops as a small dense border). The sparse
    /// path where a partition does not fit a tree.
    Tree,
}

/// How a step that reaches inactive joint stops is searched (module
/// `inequality::bend`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum StopSearch {
    /// The step is cut where it first reaches a stop: one stop per iteration.
    Cut,
    /// The projected search of bound-constrained Newton methods: each joint is held at a stop
    /// beyond the step length where it reaches it while the others move on, every stop the
    /// accepted step reaches joins the active set at once, and the step is limited in joint
    /// coordinates (`3 max_step` rad per joint, module `step::step_cap`) instead of per body;
    /// frictionless contacts the step pushes into a ground are held on it likewise (module
    /// `inequality::hold`) (default).
    #[default]
    Projected,
}

/// Whether a floating group that cannot stand on its ground start topples first (module
/// `solver::topple`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Topple {
    /// Turn it as a rigid body over the edges of its support, onto the points it lands on,
    /// until its centre of mass is over its support, then solve from there (default).
    #[default]
    On,
    /// Solve from the ground start as placed.
    Off,
}

/// Whether URDF joint limits hold the joints (part of a [`ContactPolicy`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Limits {
    /// `lower ≤ θ ≤ upper` are inequality constraints: a joint can rest on its stop (default).
    #[default]
    Enforce,
    /// Limits are read and a rest pose outside them is reported, not prevented.
    Ignore,
}

/// Called after every minimizer iteration with `(iteration, potential energy [J], ‖∂V/∂v‖∞
/// [J])`, the iteration counted within its round (the CLI draws its progress line from it).
pub type ProgressFn = dyn Fn(usize, f64, f64) + Send + Sync;

/// An optional progress callback ([`ProgressFn`]).
#[derive(Clone, Default)]
pub struct Progress(pub Option<std::sync::Arc<ProgressFn>>);

impl std::fmt::Debug for Progress {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(if self.0.is_some() {
            "Progress(Some)"
        } else {
            "Progress(None)"
        })
    }
}

/// What the stops and contacts do, for `solve` and `verify` alike: whether URDF joint limits
/// hold, and the friction and coefficient of contacts whose `mech:contact` does not say. The
/// one rule resolving a contact's friction ([`ContactPolicy::friction_of`]) and coefficient
/// ([`ContactPolicy::mu_of`]): its own setting, else the policy's.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct ContactPolicy {
    /// Joint limits as inequality constraints, or only reported (default: enforce); with
    /// `friction` and `mu`, the [`ContactPolicy`] of [`Options::contact`].
    pub limits: Limits,
    /// Tangential behaviour of contacts whose `mech:contact` does not say (default: none,
    /// frictionless).
    pub friction: crate::model::Friction,
    /// Friction coefficient of contacts whose `mech:contact` does not say (default: none: the
    /// needed coefficient is reported, never judged).
    pub mu: Option<f64>,
}

impl ContactPolicy {
    /// Whether URDF joint limits are inequality constraints.
    pub fn enforces_limits(&self) -> bool {
        self.limits == Limits::Enforce
    }

    /// The friction of a contact with the settings `c`: its own, else the policy's.
    pub fn friction_of(&self, c: &crate::model::ContactSettings) -> crate::model::Friction {
        c.friction.unwrap_or(self.friction)
    }

    /// Whether a contact with the settings `c` sticks.
    pub fn sticks(&self, c: &crate::model::ContactSettings) -> bool {
        self.friction_of(c) == crate::model::Friction::Stick
    }

    /// The friction coefficient of a contact with the settings `c`: its own, else the
    /// policy's (`None`: the needed coefficient is reported, never judged).
    pub fn mu_of(&self, c: &crate::model::ContactSettings) -> Option<f64> {
        c.mu.or(self.mu)
    }
}

/// Options of [`crate::solve`].
#[derive(Clone, Debug)]
pub struct Options {
    /// Minimization method (default: Newton).
    pub method: Method,
    /// Convergence tolerance on the reduced gradient `‖∂V/∂v‖∞` in scaled coordinates \[J\]
    /// (default: 1e-8).
    pub gradient_tolerance: f64,
    /// Tolerance on the dimensionless constraint residual `‖D Φ‖∞` (rows in m^k divided by
    /// `L^k`, `L` the characteristic length; the one meaning, module `system::residual`) of the
    /// assembly, the corrector and the stops' and contacts' gaps (default: 1e-10).
    pub constraint_tolerance: f64,
    /// Maximum minimizer iterations (default: 200).
    pub max_iterations: usize,
    /// Maximum Newton iterations of the corrector per trial point (default: 25).
    pub max_corrector_iterations: usize,
    /// Step limit per iteration (default: 0.3): the largest change of any body's Euler
    /// parameters (0.3 is about 35° of rotation); body origins move at most ten times this in
    /// lengths `ℓ`, the larger of the characteristic length and the mechanism's extent (the
    /// diagonal of the bounding box of the body origins).
    pub max_step: f64,
    /// Load stepping: solve with gravity, loads and efforts ramped in this many equal steps,
    /// each from the previous rest pose (default: 0 = automatic: the full load at once, and 8
    /// steps if that does not converge; 1 = never ramp).
    pub load_steps: usize,
    /// Stop at a stationary point even if it is unstable (default: false: leave saddles and
    /// maxima along the direction of negative curvature).
    pub allow_unstable: bool,
    /// Report the lowest eigenvalues and mode shapes of the stability verdict at any size
    /// (default: false: above 64 degrees of freedom on the tree and sparse paths the verdict
    /// comes from the inertia of the shifted KKT matrix alone, `eigenvalues` and `modes` empty
    /// and `diagnostics.eigenvalues_by` `"inertia"`; up to 64, or on the dense path, they are
    /// exact and cheap (the Newton steps decompose the reduced Hessian anyway) and always
    /// reported; asked for, exact up to 200 and the low end by Lanczos above).
    pub eigenvalues: bool,
    /// Dense or sparse linear algebra (default: automatic by size).
    pub linear_algebra: LinearAlgebra,
    /// Keep the configuration of every accepted iterate in [`crate::Report::iterates`] (for the
    /// viewer's iteration timeline; default: false).
    pub record_iterates: bool,
    /// Joint limits as inequality constraints, or only reported (default: enforce).
    pub limits: Limits,
    /// Tangential behaviour of contacts whose `mech:contact` does not say (default: none,
    /// frictionless).
    pub friction: crate::model::Friction,
    /// Friction coefficient of contacts whose `mech:contact` does not say (default: none: the
    /// needed coefficient is reported, never judged).
    pub mu: Option<f64>,
    /// Gap below which an inequality counts as violated \[m or rad\] (default: 1e-9, relative
    /// to the characteristic length for gaps in m).
    pub gap_tolerance: f64,
    /// Complementarity tolerance: a contact force or stop effort of the wrong sign smaller
    /// than this fraction of the largest applied force does not release it (default: 1e-9).
    pub force_tolerance: f64,
    /// How a step that reaches inactive joint stops is searched (default: the projected search).
    pub stop_search: StopSearch,
    /// Whether a floating group whose centre of mass is not over its support at the ground
    /// start topples as a rigid body before the solve (default: on).
    pub topple: Topple,
    /// Called after every iteration (default: none).
    pub progress: Progress,
}

impl Options {
    /// The stops' and contacts' policy of these options (`limits`, `friction`, `mu`).
    pub fn contact(&self) -> ContactPolicy {
        ContactPolicy {
            limits: self.limits,
            friction: self.friction,
            mu: self.mu,
        }
    }

    /// These options with the stops' and contacts' policy `policy`.
    #[must_use]
    pub fn with_contact(self, policy: ContactPolicy) -> Self {
        Options {
            limits: policy.limits,
            friction: policy.friction,
            mu: policy.mu,
            ..self
        }
    }
}

impl Default for Options {
    fn default() -> Self {
        Options {
            method: Method::Newton,
            gradient_tolerance: 1e-8,
            constraint_tolerance: super::system::residual::TOLERANCE,
            max_iterations: 200,
            max_corrector_iterations: 25,
            max_step: 0.3,
            load_steps: 0,
            allow_unstable: false,
            eigenvalues: false,
            record_iterates: false,
            linear_algebra: LinearAlgebra::Auto,
            limits: ContactPolicy::default().limits,
            friction: ContactPolicy::default().friction,
            mu: ContactPolicy::default().mu,
            gap_tolerance: 1e-9,
            force_tolerance: 1e-9,
            stop_search: StopSearch::Projected,
            topple: Topple::On,
            progress: Progress::default(),
        }
    }
}
