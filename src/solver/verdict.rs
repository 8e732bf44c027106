//! The stability verdict at a rest pose and what is reported with it: the reduced Hessian's
//! lowest eigenvalues and mode shapes (in joint coordinates, module `joint_space`), or the
//! verdict alone from the KKT inertia on large models (module `stability_inertia`); `stable`
//! where stops or contacts carrying a force leave no feasible motion.

use super::report::{Mode, Stability, Verdict};
use super::system::{self, System};
use super::{joint_space, lock_values, partition, spectrum, stability_inertia};
use crate::constraints::unilateral::Active;
use crate::constraints::Constraints;
use crate::model::Model;
use crate::state::State;

/// The stability verdict from the reduced-Hessian eigenvalues (ascending, at least one) and
/// eigenvectors, with the mode shapes of the smallest as joint-coordinate changes.
pub(super) fn stability(
    sys: &System,
    q: &nalgebra::DVector<f64>,
    part: &partition::Partition,
    eval: &system::Eval,
    spectrum: &spectrum::Spectrum,
) -> Stability {
    let (vals, vecs) = (&spectrum.values, &spectrum.vectors);
    let tol = spectrum.tolerance();
    let negative_by_inertia = spectrum.negative_by_inertia.unwrap_or(0) > 0;
    let verdict = if vals[0] < -tol || negative_by_inertia {
        Verdict::Unstable
    } else if vals[0] <= tol {
        Verdict::Neutral
    } else {
        Verdict::Stable
    };
    let shown = vals.len().min(6);
    // In joint coordinates where the whole spectrum is known (module `joint_space`).
    if spectrum.exact && shown > 0 {
        let h = vecs * nalgebra::DMatrix::from_diagonal(vals) * vecs.transpose();
        if let Some((values, modes)) = joint_space::joint_spectrum(sys, q, part, eval, &h, shown) {
            return Stability {
                verdict,
                tolerance: tol,
                eigenvalues: values.into_iter().take(shown).collect(),
                modes: modes.into_iter().map(Mode).collect(),
            };
        }
    }
    // The gradients of every joint coordinate, once for all modes: (joint, per coordinate the
    // (global index, derivative) pairs).
    type Gradient = Vec<(usize, f64)>;
    let gradients: Vec<(&str, Vec<Gradient>)> = if shown == 0 {
        Vec::new()
    } else {
        sys.problem
            .model
            .joints
            .iter()
            .filter(|j| !j.merged)
            .map(|j| {
                let pair = crate::jet::pair_of(&j.bodies, q, false);
                let g = (0..j.kind.scalar_coordinates())
                    .filter_map(|dof| crate::kinematics::coordinate(j, &pair, dof, 0.0))
                    .map(|s| {
                        (0..crate::jet::NL)
                            .filter_map(|i| {
                                crate::jet::global_index(&j.bodies, i).map(|g| (g, s.g[i]))
                            })
                            .collect()
                    })
                    .collect();
                (j.name.as_str(), g)
            })
            .collect()
    };
    let modes = (0..shown)
        .map(|k| {
            let dq = sys.tangent_step(part, eval, &vecs.column(k).into_owned());
            let mut mode = Vec::new();
            for (name, coords) in &gradients {
                let d: Vec<f64> = coords
                    .iter()
                    .map(|c| c.iter().map(|&(g, x)| x * dq[g]).sum())
                    .collect();
                if !d.is_empty() {
                    mode.push((name.to_string(), d));
                }
            }
            let big = mode
                .iter()
                .flat_map(|m| &m.1)
                .fold(0.0f64, |a, &b| a.max(b.abs()));
            if big > 0.0 {
                mode.iter_mut()
                    .flat_map(|m| &mut m.1)
                    .for_each(|x| *x /= big);
            }
            Mode(mode)
        })
        .collect();
    Stability {
        verdict,
        tolerance: tol,
        eigenvalues: vals.iter().take(shown).copied().collect(),
        modes,
    }
}

/// Stability verdict at a state that is feasible and balanced (`None` with no degree of
/// freedom or where the energy is undefined).
/// `eigenvalues` as in [`stability_of`].
pub(crate) fn stability_at(model: &Model, state: &State, eigenvalues: bool) -> Option<Stability> {
    stability_on(model, state, &[], eigenvalues)
}

/// [`stability_at`] on the tangent space of the equality rows and the inequalities `active`
/// (the stops and contacts that carry a force); `eigenvalues` as in [`stability_of`].
pub(crate) fn stability_on(
    model: &Model,
    state: &State,
    active: &[Active],
    eigenvalues: bool,
) -> Option<Stability> {
    let q = &state.q;
    let sys_cons = Constraints::new(model, &lock_values(model))
        .with_active(model, active)
        .on_branches(state.branches.clone());
    let mut sys = System::new(model, sys_cons);
    let part = sys.partition(q);
    if part.independent.is_empty() {
        // Stops or contacts carrying a force leave no feasible motion: every motion the model
        // allows raises the energy at first order (a strict minimum), if the model has any.
        let free = !active.is_empty() && {
            let cons =
                Constraints::new(model, &lock_values(model)).on_branches(state.branches.clone());
            !System::new(model, cons).partition(q).independent.is_empty()
        };
        return free.then(|| Stability {
            verdict: Verdict::Stable,
            tolerance: 0.0,
            eigenvalues: Vec::new(),
            modes: Vec::new(),
        });
    }
    let eval = sys.evaluate(q, &part)?;
    stability_of(&mut sys, q, &part, &eval, eigenvalues)
}

/// [`stability_at`] with the system of the model's rows already partitioned and evaluated at
/// `q` (what `verify` has made for its balance check); `None` with no degree of freedom.
///
/// Where the eigenvalues would come from Lanczos (sparse path, more than
/// `spectrum::EXACT_UP_TO` degrees of freedom) and `eigenvalues` is false, the verdict comes
/// from the inertia of the shifted KKT matrix alone (module `stability_inertia`), without
/// eigenvalues or mode shapes; Lanczos only if that inertia cannot be trusted.
pub(crate) fn stability_of(
    sys: &mut System,
    q: &nalgebra::DVector<f64>,
    part: &partition::Partition,
    eval: &system::Eval,
    eigenvalues: bool,
) -> Option<Stability> {
    if part.independent.is_empty() {
        return None;
    }
    let lanczos =
        sys.backend == system::Backend::Sparse && part.independent.len() > spectrum::EXACT_UP_TO;
    if lanczos && !eigenvalues {
        if let Some((verdict, tolerance)) = stability_inertia::inertia_verdict(sys, q, part, eval) {
            return Some(Stability {
                verdict,
                tolerance,
                eigenvalues: Vec::new(),
                modes: Vec::new(),
            });
        }
    }
    let eig = spectrum::spectrum(sys, q, part, eval);
    Some(stability(sys, q, part, eval, &eig))
}
