//! Is a given pose a rest pose? Independent checks of a configuration.
//!
//! With `S` the coordinate scaling of the solver (positions by the characteristic length) and
//! `N` an orthonormal basis of the null space of `Φ_q S` (feasible motions), a pose is
//! balanced when the projected gradient `Nᵀ S ∇V` vanishes. The dense path (module `dense`)
//! uses no partition of the solver; the sparse path (module `reduced`, below) uses the
//! solver's sparse partition, at the pose given, for its null space.
//!
//! The per-joint imbalance is the effort `τ` each joint coordinate would need to hold the pose
//! (Adams' "imbalance"), found with the stop and contact forces `λ` and the joint reactions `a`
//! from `∇V = Φ_qᵀ a + G λ + B τ` (`B` the gradients `∇θ_k` of the tree joints' scalar
//! coordinates, `G` those of the touching stops and contacts; module `held`). Efforts act on
//! joint coordinates only: a floating base and the coordinates a loop determines are balanced
//! by the reactions and the contact forces exactly, and what they cannot balance is reported
//! as `unassigned`. Where the forces are not unique (loops, several feet), the efforts of least
//! norm are reported, then the stop and contact forces of least norm (as `analyze`
//! distributes them); a coordinate held by a lock (`verify --lock`) reports its holding effort
//! without failing the pose. For a tree without contacts `τ_k = ∂V/∂θ_k`. Dense and sparse
//! linear algebra give the same efforts and forces.
//!
//! Models above 40 bodies' coordinates (the solver's automatic switch to sparse linear
//! algebra) are verified in `O(N)` by the solver's sparse partition (module `reduced`); smaller
//! ones by the dense basis `N` (module `dense`).
//!
//! ## Tolerances
//! A pose passes when `‖D Φ‖∞ ≤ constraint` (the solver's dimensionless residual, module
//! `solver::system::residual`) and every effort (and the unassigned force) is at
//! most `force + relative · F`, with `F = ‖S ∇V‖∞` the largest generalized force on any
//! coordinate \[J\]: the rounding of the efforts grows with the forces they balance (a
//! 10,000-link chain carries 10⁸ N m at its base), so an absolute tolerance alone would reject
//! exact answers of large models.

mod closure;
mod dense;
mod friction;
mod full_pivoting;
mod held;
mod initial_guess;
mod lexicographic;
mod loop_efforts;
mod model_rows;
mod pose;
#[cfg(test)]
mod rank_tests;
mod reduced;
mod rounds;
mod run;
mod tree_partition;
mod unilateral;

use closure::closures;
pub use closure::Closure;
pub use initial_guess::{check, ModelCheck};
pub use pose::{parse_pose, pose_state, pose_state_with_bodies, read_pose, read_reference_pose};
pub use unilateral::{UnilateralCheck, Unilaterals};

use crate::error::Result;
use crate::forces::potential;
use crate::model::Model;
use crate::solver::system::Backend;
use crate::solver::Stability;
use crate::state::State;
use nalgebra::DVector;

/// Residuals of a configuration.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Balance {
    /// `‖Φ‖∞` over all constraint rows (locks included).
    pub constraint_residual: f64,
    /// `‖Nᵀ S ∇V‖∞` \[J\]: the gradient of the energy along feasible motions, in coordinates
    /// scaled like the solver's (positions by the characteristic length).
    pub projected_gradient: f64,
    /// Potential energy \[J\].
    pub potential_energy: f64,
    /// Degrees of freedom from the rank of `Φ_q` (singular values below 1e-6 of the largest
    /// count as zero).
    pub dof: usize,
}

/// Tolerances of [`verify`].
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Tolerances {
    /// Largest joint effort (or unassigned generalized force) a balanced pose may need
    /// \[N m or N\] (default: 1e-6).
    pub force: f64,
    /// Largest constraint residual `‖D Φ‖∞` (dimensionless: a row in m^k divided by `L^k`, `L`
    /// the characteristic length; the one residual of module `solver::system::residual`, which
    /// `analyze --constraint-tolerance` bounds too; default 1e-10, the solver's). A gap of a
    /// stop or contact is judged by `gap` instead.
    pub constraint: f64,
    /// The band of a stop's or contact's gap, scaled as its row (`L ε` for a gap in m, `ε` in
    /// rad), within which it touches, and beyond which through a stop or a ground it fails:
    /// the band in which the solver's active set takes an inequality as touching
    /// (`solver::Options::gap_tolerance`, the same default 1e-9), so that every contact set
    /// `analyze` chooses is one `verify` reads the same way.
    pub gap: f64,
    /// Effort tolerance relative to the largest generalized force `‖S ∇V‖∞`, added to `force`
    /// (default: 1e-9).
    pub relative: f64,
}

impl Default for Tolerances {
    fn default() -> Self {
        Tolerances {
            force: 1e-6,
            constraint: crate::solver::system::residual::TOLERANCE,
            gap: crate::solver::Options::default().gap_tolerance,
            relative: 1e-9,
        }
    }
}

/// Effort a joint coordinate needs to hold the pose.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Imbalance {
    /// Joint name.
    pub joint: String,
    /// Coordinate index.
    pub dof: usize,
    /// Effort on the child along the coordinate \[N m or N\].
    pub effort: f64,
    /// Whether a lock of the model (`verify --lock`, `mech:lock`) holds the coordinate: its
    /// effort is then the lock's holding effort, not an imbalance (it does not fail the pose).
    pub locked: bool,
}

/// Result of [`verify`].
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Verification {
    /// The robot's name.
    pub robot: String,
    /// Constraint residual and tolerance met, and no joint needs more than the force tolerance.
    pub passed: bool,
    /// `‖Φ‖∞` \[m or rad\], raw.
    pub constraint_residual: f64,
    /// `‖D Φ‖∞` (dimensionless): the residual [`Tolerances::constraint`] bounds.
    pub scaled_constraint_residual: f64,
    /// Per joint with constraint rows: loop joints always, tree joints when violated.
    pub closure: Vec<Closure>,
    /// Per tree-joint scalar coordinate.
    pub imbalance: Vec<Imbalance>,
    /// The largest `|effort|`, if any coordinate.
    pub max_imbalance: Option<Imbalance>,
    /// Generalized force no scalar joint coordinate carries (spherical, floating joints) \[J\].
    pub unassigned: f64,
    /// `‖Nᵀ S ∇V‖∞` \[J\] (NaN where not computed: [`Eigenvalues::Skip`]).
    pub projected_gradient: f64,
    /// Potential energy \[J\].
    pub potential_energy: f64,
    /// Stability at the pose, when it passed and has degrees of freedom.
    pub stability: Option<Stability>,
    /// Tolerances used.
    pub tolerances: Tolerances,
    /// `‖S ∇V‖∞` \[J\]: the largest generalized force on any coordinate.
    pub force_scale: f64,
    /// The effort tolerance applied: `force + relative · force_scale` \[N m or N\].
    pub effort_tolerance: f64,
    /// Stops and contacts at the pose (module `unilateral`), flattened into the JSON.
    #[serde(flatten)]
    pub unilateral: UnilateralCheck,
}

/// Whether closed loops or mimics couple bodies beyond a joint's two (no tree count of the
/// degrees of freedom).
fn coupled(model: &Model) -> bool {
    model.joints.iter().any(|j| !j.tree && !j.merged) || !model.mimics.is_empty()
}

/// Whether `model` is verified on the sparse path (module `reduced`).
fn sparse_path(model: &Model) -> bool {
    auto_backend(model) != Backend::Dense
}

/// The linear algebra `model` is verified with by default: dense as the solver's automatic
/// choice, else the sparse partition with the tree factors on a mechanism without closed
/// loops (stops or not), with the sparse ones otherwise ([`Backend::for_verify`]).
fn auto_backend(model: &Model) -> Backend {
    Backend::for_verify(model)
}

/// Potential energy of a state \[J\], `None` where a force table is out of its range.
pub fn potential_energy(model: &Model, state: &State) -> Option<f64> {
    let mut g = DVector::zeros(state.q.len());
    potential(model, &state.branches, &state.q, &mut g, None).map(|e| e.total)
}

/// Constraint residual and projected energy gradient of `state` (with the model's locks held
/// at their given values, or at the initial value when they have none).
///
/// # Errors
/// [`Error::ForceTableOutOfRange`](crate::Error::ForceTableOutOfRange) if the energy cannot be evaluated,
/// [`Error::SingularPartition`](crate::Error::SingularPartition) if the constraint Jacobian is singular there.
pub fn balance(model: &Model, state: &State) -> Result<Balance> {
    if sparse_path(model) {
        // The finiteness guard inside, on the rows it evaluates anyway.
        let r = {
            let locks = crate::solver::lock_values(model);
            reduced::reduced(model, state, &locks, auto_backend(model), true)?
        };
        return Ok(Balance {
            constraint_residual: r.phi.amax(),
            projected_gradient: r.reduced_gradient,
            potential_energy: r.energy,
            dof: r.dof,
        });
    }
    crate::solver::finite::guard(model, state, "the given pose")?;
    let p = dense::project(model, state)?;
    let pg = p.null.transpose() * &p.grad_s;
    Ok(Balance {
        constraint_residual: p.phi.amax(),
        projected_gradient: pg.amax(),
        potential_energy: p.energy,
        dof: p.null.ncols(),
    })
}

/// Verifies that `state` is a rest pose: it assembles, and no joint needs an effort to hold it.
///
/// # Errors
/// [`Error::ForceTableOutOfRange`](crate::Error::ForceTableOutOfRange) if the energy cannot be evaluated,
/// [`Error::SingularPartition`](crate::Error::SingularPartition) if the constraint Jacobian is singular there.
///
/// # Example
/// ```
/// let model = restpose::urdf::load_file("robots/pendulum.urdf", &Default::default())?.model;
/// let (rest, _) = restpose::solve(&model, &Default::default())?;
/// let v = restpose::verify::verify(&model, &rest, &Default::default())?;
/// assert!(v.passed);
/// let pose = [("pivot".to_string(), vec![-1.3])].into_iter().collect();
/// let (moved, _) = restpose::verify::pose_state(&model, &pose)?;
/// let v = restpose::verify::verify(&model, &moved, &Default::default())?;
/// assert!(!v.passed);
/// assert_eq!(v.max_imbalance.unwrap().joint, "pivot");
/// # Ok::<(), restpose::Error>(())
/// ```
pub fn verify(model: &Model, state: &State, tol: &Tolerances) -> Result<Verification> {
    verify_with_options(model, state, tol, &Unilaterals::default())
}

/// [`verify`] with stops and contacts as `uni` says: they carry the forces (module `unilateral`).
/// # Errors
/// As [`verify`].
pub fn verify_with_options(
    model: &Model,
    state: &State,
    tol: &Tolerances,
    uni: &Unilaterals,
) -> Result<Verification> {
    run::verify_on(
        model,
        state,
        tol,
        uni,
        auto_backend(model),
        Eigenvalues::WhenCheap,
    )
}

/// [`verify_with_options`] on the path `linear_algebra` says: `Auto` as
/// [`verify_with_options`] (the solver's automatic choice), `Dense` the dense null-space basis,
/// `Sparse` the solver's sparse partition and factors, `Tree` that partition with the tree
/// factors where it fits a tree (modules `dense`, `reduced`, `solver::tree`).
/// # Errors
/// As [`verify`].
pub fn verify_using(
    model: &Model,
    state: &State,
    tol: &Tolerances,
    uni: &Unilaterals,
    linear_algebra: crate::solver::LinearAlgebra,
) -> Result<Verification> {
    verify_reporting(
        model,
        state,
        tol,
        uni,
        linear_algebra,
        Eigenvalues::WhenCheap,
    )
}

/// What the stability verdict of [`verify`] reports besides the verdict.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Eigenvalues {
    /// The lowest eigenvalues and their mode shapes where they are exact and cheap (the
    /// reduced Hessian formed and decomposed: up to 64 degrees of freedom on the tree and
    /// sparse paths, or up to 40 bodies, where the stability uses dense linear algebra);
    /// above, the verdict alone, from the inertia of the shifted KKT matrix
    /// (`stability.eigenvalues` and `modes` empty), as `analyze` reports it.
    #[default]
    WhenCheap,
    /// Always the lowest eigenvalues and mode shapes (exact up to 200 degrees of freedom; above
    /// on the sparse path, the low end found by Lanczos, as `analyze` reports them).
    Always,
    /// No stability verdict (`stability` is `None`): the balance checks only, as `analyze`
    /// runs them on its own answer. The model's rows are then not partitioned at all, on
    /// either path (no null-space basis on the dense path: the pass reads the residual and
    /// the forces of module `held`, which partition their own system): `projected_gradient`
    /// is NaN (not computed). The pass, the failures, the efforts and the stops' and
    /// contacts' report are those of the other modes.
    Skip,
}

/// [`verify_using`] with the eigenvalues `eigenvalues` asks for.
/// # Errors
/// As [`verify`].
pub fn verify_reporting(
    model: &Model,
    state: &State,
    tol: &Tolerances,
    uni: &Unilaterals,
    linear_algebra: crate::solver::LinearAlgebra,
    eigenvalues: Eigenvalues,
) -> Result<Verification> {
    let backend = match linear_algebra {
        crate::solver::LinearAlgebra::Auto => auto_backend(model),
        crate::solver::LinearAlgebra::Dense => Backend::Dense,
        crate::solver::LinearAlgebra::Sparse => Backend::Sparse,
        crate::solver::LinearAlgebra::Tree => Backend::Tree,
    };
    run::verify_on(model, state, tol, uni, backend, eigenvalues)
}

/// Brings `state` onto `Φ = 0` by a damped Newton iteration that changes the dependent
/// coordinates of a fresh partition at each step (as the solver's assembly does).
///
/// # Errors
/// [`Error::Assembly`](crate::Error::Assembly) if the constraints cannot be satisfied from there.
pub fn assemble(model: &Model, state: &State) -> Result<State> {
    let locks = crate::solver::lock_values(model);
    let mut branches = state.branches.clone();
    let q = crate::solver::assemble_only(model, state.q.clone(), &mut branches, &locks)?;
    Ok(State { q, branches })
}

#[cfg(test)]
mod test_support;
#[cfg(test)]
mod tests;
