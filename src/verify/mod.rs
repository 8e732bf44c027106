//! Is a given pose a rest pose? Independent checks of a configuration.
//!
//! Nothing here uses the solver's partition. With `S` the coordinate scaling of the solver
//! (positions by the characteristic length) and `N` an orthonormal basis of the null space of
//! `Φ_q S` (feasible motions), a pose is balanced when the projected gradient `Nᵀ S ∇V`
//! vanishes.
//!
//! The per-joint imbalance is the effort `τ` each joint coordinate would need to hold the pose
//! (Adams' "imbalance"): with `B` the gradients `∇θ_k` of the tree joints' scalar coordinates,
//! `τ` is the minimum-norm solution of `Nᵀ S B τ = Nᵀ S ∇V`, i.e. the actuator efforts that,
//! together with the joint reactions, balance the loads. For a tree it is `∂V/∂θ_k` exactly;
//! with loops the split among the joints of a loop is the minimum-norm one. What no scalar
//! joint coordinate can carry (a spherical or floating joint) is reported as `unassigned`.
//!
//! Models above 40 bodies' coordinates (the solver's automatic switch to sparse linear
//! algebra) are verified in `O(N)` by the solver's sparse partition instead (module `reduced`);
//! smaller ones by the dense basis `N` (module `dense`). The stops and contacts a pose touches
//! carry their share of the load first on both paths: by a least-squares balance on `N`
//! (module `unilateral`) or by the multipliers of the sparse partition with the touching rows
//! appended (module `unilateral_sparse`); the efforts then balance what they leave.
//!
//! ## Tolerances
//! A pose passes when `‖Φ‖∞ ≤ constraint` and every effort (and the unassigned force) is at
//! most `force + relative · F`, with `F = ‖S ∇V‖∞` the largest generalized force on any
//! coordinate \[J\]: the rounding of the efforts grows with the forces they balance (a
//! 10,000-link chain carries 10⁸ N m at its base), so an absolute tolerance alone would reject
//! exact answers of large models.

mod check;
mod closure;
mod dense;
mod friction;
mod pose;
mod rank;
mod reduced;
mod unilateral;
mod unilateral_sparse;

pub use check::{check, ModelCheck};
use closure::closures;
pub use closure::Closure;
pub use pose::{parse_pose, pose_state, read_pose};
pub use unilateral::{UnilateralCheck, Unilaterals};

use crate::error::{Error, Result};
use crate::forces::potential;
use crate::jet::pair_of;
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
    /// Largest constraint violation \[m or rad\] (default: 1e-8).
    pub constraint: f64,
    /// Effort tolerance relative to the largest generalized force `‖S ∇V‖∞`, added to `force`
    /// (default: 1e-9).
    pub relative: f64,
}

impl Default for Tolerances {
    fn default() -> Self {
        Tolerances {
            force: 1e-6,
            constraint: 1e-8,
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
}

/// Result of [`verify`].
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Verification {
    /// Constraint residual and tolerance met, and no joint needs more than the force tolerance.
    pub passed: bool,
    /// `‖Φ‖∞`.
    pub constraint_residual: f64,
    /// Per joint with constraint rows: loop joints always, tree joints when violated.
    pub closure: Vec<Closure>,
    /// Per tree-joint scalar coordinate.
    pub imbalance: Vec<Imbalance>,
    /// The largest `|effort|`, if any coordinate.
    pub max_imbalance: Option<Imbalance>,
    /// Generalized force no scalar joint coordinate carries (spherical, floating joints) \[J\].
    pub unassigned: f64,
    /// `‖Nᵀ S ∇V‖∞` \[J\].
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

/// Whether `model` is verified on the sparse path (module `reduced`).
fn sparse_path(model: &Model) -> bool {
    Backend::choose(model, crate::solver::LinearAlgebra::Auto) == Backend::Sparse
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
/// [`Error::ForceTableOutOfRange`] if the energy cannot be evaluated,
/// [`Error::SingularPartition`] if the constraint Jacobian is singular there.
pub fn balance(model: &Model, state: &State) -> Result<Balance> {
    if sparse_path(model) {
        let r = {
            let locks = crate::solver::lock_values(model);
            reduced::reduced(model, state, &locks, locks.len())?
        };
        return Ok(Balance {
            constraint_residual: r.phi.amax(),
            projected_gradient: r.reduced_gradient,
            potential_energy: r.energy,
            dof: r.dof,
        });
    }
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
/// [`Error::ForceTableOutOfRange`] if the energy cannot be evaluated,
/// [`Error::SingularPartition`] if the constraint Jacobian is singular there.
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
    verify_on(model, state, tol, uni, sparse_path(model), false)
}

/// [`verify_with_options`] on the path `linear_algebra` says: `Auto` as
/// [`verify_with_options`] (sparse above 40 bodies), `Dense` the dense null-space basis,
/// `Sparse` the solver's sparse partition (modules `dense`, `reduced`).
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
    /// reduced Hessian formed and decomposed: up to 200 degrees of freedom, or up to 40
    /// bodies, where the stability uses dense linear algebra); above, the verdict alone, from
    /// the inertia of the shifted KKT matrix (`stability.eigenvalues` and `modes` empty).
    #[default]
    WhenCheap,
    /// Always the lowest eigenvalues and mode shapes (above 200 degrees of freedom on the
    /// sparse path, the low end found by Lanczos, as `analyze` reports them).
    Always,
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
    let sparse = match linear_algebra {
        crate::solver::LinearAlgebra::Auto => sparse_path(model),
        crate::solver::LinearAlgebra::Dense => false,
        crate::solver::LinearAlgebra::Sparse => true,
    };
    verify_on(
        model,
        state,
        tol,
        uni,
        sparse,
        eigenvalues == Eigenvalues::Always,
    )
}

/// The scalar coordinates of the tree joints: `(joint, dof, value)` and their gradients.
fn tree_coordinates(
    model: &Model,
    state: &State,
) -> Vec<(crate::model::JointId, usize, crate::jet::Scalar)> {
    let mut coords = Vec::new();
    for (i, j) in model.joints.iter().enumerate() {
        if !j.tree || j.merged {
            continue;
        }
        let pair = pair_of(&j.bodies, &state.q, false);
        for dof in 0..j.kind.scalar_coordinates() {
            if let Some(s) = crate::kinematics::coordinate(
                j,
                &pair,
                dof,
                state.branches.get(crate::model::JointId(i), dof),
            ) {
                coords.push((crate::model::JointId(i), dof, s));
            }
        }
    }
    coords
}

/// [`verify`] on the dense (`sparse = false`) or the sparse path.
///
/// On the sparse path the stability verdict reuses the partition and evaluation of the
/// balance check, and is computed on a second thread while the efforts are (kept only when
/// the pose passes); both only read the model and the state. `eigenvalues`: the lowest
/// eigenvalues also where only Lanczos finds them ([`Eigenvalues::Always`]).
fn verify_on(
    model: &Model,
    state: &State,
    tol: &Tolerances,
    uni: &Unilaterals,
    sparse: bool,
    eigenvalues: bool,
) -> Result<Verification> {
    let (
        coords,
        phi,
        energy,
        projected_gradient,
        force_scale,
        closure,
        efforts,
        unassigned,
        stability,
        contact,
        (strong, weak),
    ) = if sparse {
        let locks = crate::solver::lock_values(model);
        let r = reduced::reduced(model, state, &locks, locks.len())?;
        let closure = closures(model, &r.sys.problem.cons, &r.phi, tol.constraint);
        let reduced::Reduced {
            phi,
            energy,
            reduced_gradient,
            force_scale,
            redundant,
            mut sys,
            part,
            eval,
            ..
        } = r;
        let assembled = phi.amax() <= tol.constraint;
        // The stops and contacts take their share of the load first (module
        // `unilateral_sparse`).
        let tau = tol.force + tol.relative * force_scale;
        let contact = unilateral_sparse::check(model, state, uni, &locks, tol.constraint, tau)?;
        let carried = contact.touching.then_some(&contact.carried);
        // Without a stop or contact carrying a force, the verdict on this partition.
        let free = contact.strong.is_empty() && contact.weak.is_empty();
        let (coords, efforts, unassigned, stability) = std::thread::scope(|s| {
            let verdict = (assembled && free).then(|| {
                s.spawn(|| {
                    crate::solver::stability_of(&mut sys, &state.q, &part, &eval, eigenvalues)
                })
            });
            // The joint coordinates here, off the verdict's path.
            let coords = tree_coordinates(model, state);
            let values: Vec<_> = coords.iter().map(|c| (c.0, c.1, c.2.v)).collect();
            let (efforts, unassigned) =
                reduced::efforts(model, state, &locks, &values, redundant.len(), carried)?;
            let passed = passes(phi.amax(), &efforts, unassigned, force_scale, tol);
            // A panic there is re-raised here, as if the verdict had been computed on
            // this thread.
            let stability = match verdict {
                Some(h) if passed => h
                    .join()
                    .unwrap_or_else(|panic| std::panic::resume_unwind(panic)),
                _ => None,
            };
            Ok::<_, Error>((coords, efforts, unassigned, stability))
        })?;
        (
            coords,
            phi,
            energy,
            reduced_gradient,
            force_scale,
            closure,
            DVector::from_vec(efforts),
            unassigned,
            stability,
            contact.check,
            (contact.strong, contact.weak),
        )
    } else {
        let coords = tree_coordinates(model, state);
        let d = dense::dense_checks(model, state, tol, uni, &coords)?;
        // The stability is judged below, once the stops and contacts have settled.
        (
            coords,
            d.phi,
            d.energy,
            d.projected_gradient,
            d.force_scale,
            d.closure,
            d.efforts,
            d.unassigned,
            None,
            d.unilateral,
            (d.strong, d.weak),
        )
    };
    let imbalance: Vec<Imbalance> = coords
        .iter()
        .zip(efforts.iter())
        .map(|((id, dof, _), &effort)| Imbalance {
            joint: model.joint(*id).name.clone(),
            dof: *dof,
            effort,
        })
        .collect();
    let max_imbalance = imbalance
        .iter()
        .max_by(|a, b| a.effort.abs().total_cmp(&b.effort.abs()))
        .cloned();
    let constraint_residual = phi.amax();
    let effort_tolerance = tol.force + tol.relative * force_scale;
    let balanced = passes(
        constraint_residual,
        efforts.as_slice(),
        unassigned,
        force_scale,
        tol,
    );
    let mut contact = contact;
    let passed = contact.settle(tol.constraint, balanced) && balanced;
    // The sparse path judged the stability beside the efforts where no stop or contact
    // touches; otherwise it is judged here, on the tangent space of those that carry a force
    // and the critical cone of those that touch without one (`solver::cone`).
    let stability = match (passed, sparse) {
        (false, _) => None,
        (true, _) if !strong.is_empty() || !weak.is_empty() => {
            crate::solver::stability_touching(model, state, &strong, &weak, eigenvalues)
        }
        (true, true) => stability,
        (true, false) => crate::solver::stability_at(model, state, eigenvalues),
    };
    Ok(Verification {
        passed,
        constraint_residual,
        closure,
        imbalance,
        max_imbalance,
        unassigned,
        projected_gradient,
        potential_energy: energy,
        stability,
        tolerances: *tol,
        force_scale,
        effort_tolerance,
        unilateral: contact,
    })
}

/// Whether a pose passes: `‖Φ‖∞` within the constraint tolerance, every effort and the
/// unassigned force within `force + relative · force_scale`.
fn passes(
    residual: f64,
    efforts: &[f64],
    unassigned: f64,
    force_scale: f64,
    tol: &Tolerances,
) -> bool {
    let effort_tolerance = tol.force + tol.relative * force_scale;
    residual <= tol.constraint
        && efforts.iter().all(|e| e.abs() <= effort_tolerance)
        && unassigned <= effort_tolerance
}

/// Brings `state` onto `Φ = 0` by a damped Newton iteration that changes the dependent
/// coordinates of a fresh partition at each step (as the solver's assembly does).
///
/// # Errors
/// [`Error::Assembly`] if the constraints cannot be satisfied from there.
pub fn assemble(model: &Model, state: &State) -> Result<State> {
    let locks = crate::solver::lock_values(model);
    let mut branches = state.branches.clone();
    let q = crate::solver::assemble_only(model, state.q.clone(), &mut branches, &locks)?;
    Ok(State { q, branches })
}

#[cfg(test)]
mod tests;
