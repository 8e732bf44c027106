//! The verdict at a rest pose from the eigenvalues of the reduced Hessian `Ĥ = Zᵀ W Z`:
//! stable when `λ_min > t`, unstable when `λ_min < −t`, neutral otherwise, with
//! `t = 10⁻¹⁰ max(λ_max, 1)` (`Spectrum::tolerance`), and the mode shapes of the lowest
//! eigenvalues as joint-coordinate changes. Where the whole spectrum is known the eigenvalues
//! and modes are reported in joint coordinates (module `joint_space`): physical units,
//! independent of the start; `stable` where stops or contacts carrying a force leave no
//! feasible motion. The verdict reads the smallest eigenvalue of the Hessian along the search
//! path `Ĥ + C` where the path keeps every row (module `step::path_hessian`; for a tree, the
//! Hessian in the joint coordinates), `Ĥ`'s elsewhere: at a point stationary only to
//! `‖∂V/∂v‖ = g`, `Ĥ` reads an exactly flat direction (a vertical base yaw) as `−g·a`, `a`
//! that direction's acceleration in the chart, of either sign and above `t`; `Ĥ + C` reads it
//! at rounding. `C` is formed only where `Ĥ`'s smallest eigenvalue is within the Hessian's
//! error `10 g` of `±t` (`Spectrum::error`): elsewhere `C` cannot move it across `±t`. The
//! eigenvalues, modes and `t` reported stay `Ĥ`'s.
//!
//! The entry point is [`stability_verdict`] (stops and contacts that carry a force and those
//! that touch without one, or none); [`stability_on`] holds every given row, and
//! [`stability_of`] judges a system already partitioned and evaluated (as `verify` has made
//! it, or the minimizer).

use super::inertia;
use super::joint_space;
use super::spectrum::{self, Spectrum};
use crate::constraints::unilateral::Active;
use crate::constraints::Constraints;
use crate::model::Model;
use crate::solver::partition::Partition;
use crate::solver::step::path_hessian::{along_path, path_keeps_rows};
use crate::solver::system::{Backend, System};
use crate::solver::{lock_values, Mode, Stability, Verdict};
use crate::state::State;

/// The stability verdict from the reduced-Hessian eigenvalues (ascending, at least one) and
/// eigenvectors, with the mode shapes of the smallest as joint-coordinate changes.
pub(crate) fn from_spectrum(
    sys: &System,
    q: &nalgebra::DVector<f64>,
    part: &Partition,
    eval: &crate::solver::system::Eval,
    spectrum: &Spectrum,
) -> Stability {
    let (vals, vecs) = (&spectrum.values, &spectrum.vectors);
    let tol = spectrum.tolerance();
    // On the Hessian along the search path where the path keeps every row (module docs).
    let unresolved = vals[0].abs() <= tol + Spectrum::error(eval.grad_v.amax());
    let lowest = if unresolved && spectrum.exact && path_keeps_rows(sys) {
        along_path(sys, q, part, eval, spectrum).values[0]
    } else {
        vals[0]
    };
    let negative_by_inertia = spectrum.negative_by_inertia.unwrap_or(0) > 0;
    let verdict = if lowest < -tol || negative_by_inertia {
        Verdict::Unstable
    } else if lowest <= tol {
        Verdict::Neutral
    } else {
        Verdict::Stable
    };
    let shown = vals.len().min(6);
    // In joint coordinates where the whole spectrum is known (module `joint_space`).
    if spectrum.exact && shown > 0 {
        let h = vecs * nalgebra::DMatrix::from_diagonal(vals) * vecs.transpose();
        if let Some((values, modes)) =
            joint_space::joint_spectrum(sys, q, part, eval, spectrum.basis.as_ref(), &h, shown)
        {
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

/// The stability verdict at a state that is feasible and balanced, where the stops and
/// contacts `strong` carry a force and `weak` touch without one (both empty: the model's
/// equality rows alone), with the linear algebra `backend`: the entry point. On the tangent
/// space of the rows held ([`stability_on`]), or on the critical cone where some touch
/// without a force ([`stability_touching`](super::cone::stability_touching)). `None` with no
/// degree of freedom or where the energy is undefined; `eigenvalues` as in [`stability_of`].
pub(crate) fn stability_verdict(
    model: &Model,
    state: &State,
    strong: &[Active],
    weak: &[Active],
    backend: Backend,
    eigenvalues: bool,
) -> Option<Stability> {
    super::cone::stability_touching(model, state, strong, weak, backend, eigenvalues, None)
}

/// [`stability_verdict`] at the end of an active-set round that held every one of `strong`
/// and `weak` as a row and judged its tangent space (`all_held`, if it has a verdict): that
/// verdict's eigenvalues and modes are reported, not computed again.
pub(crate) fn stability_verdict_after_round(
    model: &Model,
    state: &State,
    (strong, weak): (&[Active], &[Active]),
    backend: Backend,
    eigenvalues: bool,
    all_held: Option<Stability>,
) -> Option<Stability> {
    super::cone::stability_touching(model, state, strong, weak, backend, eigenvalues, all_held)
}

/// The verdict on the tangent space of the equality rows and the inequalities `active` (every
/// one held as a row); `eigenvalues` as in [`stability_of`].
pub(crate) fn stability_on(
    model: &Model,
    state: &State,
    active: &[Active],
    backend: Backend,
    eigenvalues: bool,
) -> Option<Stability> {
    let q = &state.q;
    let sys_cons = Constraints::new(model, &lock_values(model))
        .with_active(model, active)
        .on_branches(state.branches.clone());
    let mut sys = System::new(model, sys_cons, backend);
    let part = sys.partition(q);
    if part.independent.is_empty() {
        // Stops or contacts carrying a force leave no feasible motion: every motion the model
        // allows raises the energy at first order (a strict minimum), if the model has any.
        let free = !active.is_empty() && {
            let cons =
                Constraints::new(model, &lock_values(model)).on_branches(state.branches.clone());
            !System::new(model, cons, backend)
                .partition(q)
                .independent
                .is_empty()
        };
        return free.then(|| Stability {
            verdict: Verdict::Stable,
            tolerance: 0.0,
            eigenvalues: Vec::new(),
            modes: Vec::new(),
        });
    }
    let eval = sys.evaluate(q, &part)?;
    stability_of(&mut sys, q, &part, eval, eigenvalues)
}

/// The verdict with the system of the model's rows already partitioned and evaluated at
/// `q` (what `verify` has made for its balance check); `None` with no degree of freedom.
///
/// Where the eigenvalues are not listed by default (sparse or tree path, more than
/// `spectrum::LISTED_UP_TO` degrees of freedom) and `eigenvalues` is false, the verdict comes
/// from the inertia of the shifted KKT matrix alone (module `stability::inertia`), without
/// eigenvalues or mode shapes; the spectrum (exact up to `spectrum::EXACT_UP_TO`, Lanczos
/// above) only if that inertia cannot be trusted. `eval` is taken: on the inertia path its
/// factors of `Φ_u` (and the system's split they came from) are freed once `λ_max` is known,
/// before the KKT matrix is built (which reuses their memory: fewer fresh pages), and the
/// block Hessian once that matrix is assembled (its factors reuse that memory); the
/// spectrum after an untrusted inertia evaluates again (the same numbers: the same `q`,
/// partition and triplets).
pub(crate) fn stability_of(
    sys: &mut System,
    q: &nalgebra::DVector<f64>,
    part: &Partition,
    eval: crate::solver::system::Eval,
    eigenvalues: bool,
) -> Option<Stability> {
    if part.independent.is_empty() {
        return None;
    }
    let mut eval = Some(eval);
    if !spectrum::listed(sys.backend, part.independent.len()) && !eigenvalues {
        let largest = inertia::largest_at(sys, q, part, eval.as_ref()?);
        drop(eval.take());
        sys.work.tree_split = None;
        if let Some(judged) = inertia::inertia_verdict_knowing(sys, q, part, largest, true) {
            return Some(Stability {
                verdict: judged.verdict,
                tolerance: judged.tolerance,
                eigenvalues: Vec::new(),
                modes: Vec::new(),
            });
        }
    }
    let eval = match eval {
        Some(e) => e,
        None => sys.evaluate(q, part)?,
    };
    let eig = spectrum::spectrum(sys, q, part, &eval);
    Some(from_spectrum(sys, q, part, &eval, &eig))
}
