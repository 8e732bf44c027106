//! The low end of the reduced Hessian's spectrum, for the stability verdict and for leaving
//! saddles.
//!
//! With few degrees of freedom (or the dense path), `Ĥ = Zᵀ W Z` is formed (one column per
//! independent coordinate, through the factors of `Φ_u`) and decomposed exactly. With many, `Ĥ`
//! is dense and too large, and the eigenvalues nearest zero come from `k` steps of the Lanczos
//! iteration with full reorthogonalization on `Ĥ⁻¹`, applied by the KKT factors (`δv̂ = Ĥ⁻¹ x`
//! is the independent part of the KKT solution with right side `x` on the independent
//! coordinates): Lanczos finds the extreme eigenvalues of `Ĥ⁻¹` first, which are the smallest
//! positive eigenvalues of `Ĥ` and, if there is any negative eigenvalue, the negative end. Only
//! Ritz pairs with residual `|β_k s_ki| ≤ 10⁻⁸ |θ_i|` are kept. The largest eigenvalue (scale
//! of the verdict's tolerance) is estimated by a few Lanczos steps on `Ĥ` itself (module
//! `largest`: within 10 % of an eigenvalue and never above `|λ|max`). When the KKT matrix was factored by an accurate LDLᵀ, the number
//! of its negative pivots minus the number of rows is the number of negative eigenvalues of `Ĥ`
//! (Sylvester's law of inertia): an exact count, whatever Lanczos found.
//!
//! ## References
//! - Y. Saad, *Numerical Methods for Large Eigenvalue Problems*, 2nd ed., SIAM (2011), §6.6.

use super::blocks::block_symmetric_eigen;
use super::eigen::symmetric_eigen;
use super::largest::{largest_eigenvalue, orthogonalize_twice, tridiagonal};
use crate::solver::partition::Partition;
use crate::solver::sparse::kkt::Factored;
use crate::solver::system::{Backend, Eval, System};
use nalgebra::{DMatrix, DVector};

/// Up to this many degrees of freedom the reduced Hessian is formed and decomposed exactly.
pub(crate) const EXACT_UP_TO: usize = 200;
/// Up to this many degrees of freedom on the sparse and tree paths the stability verdict
/// comes from the exact spectrum and the report lists the eigenvalues; above, from the
/// inertia of the shifted KKT matrix unless eigenvalues are asked for ([`listed`]). It is
/// the minimizer's `EXACT_NEWTON_DOF`: up to there every Newton step forms `Ĥ` (and
/// decomposes it, or on a small tree away from a stationary point solves `Ĥ + C` by Cholesky,
/// module `step::path_cholesky`), and at the rest the convergence test decomposes it; above, the steps are KKT solves and forming `Ĥ` (`dof`
/// tangent solves and their transposes, `O(dof · N)`) and decomposing it (`O(dof³)`) would
/// cost more than the solve (chain 100: about two thirds of it).
pub(crate) const LISTED_UP_TO: usize = 64;
/// Lanczos steps at most.
const STEPS: usize = 24;
/// Eigenvalues reported (the smallest).
const WANTED: usize = 6;

/// Eigenvalues of the reduced Hessian (ascending) with their eigenvectors (columns).
#[derive(Clone, Debug)]
pub(crate) struct Spectrum {
    pub(crate) values: DVector<f64>,
    pub(crate) vectors: DMatrix<f64>,
    /// The largest eigenvalue magnitude (the scale of the tolerance).
    pub(crate) largest: f64,
    /// Whether all eigenvalues are known (exact decomposition) or only the low end (Lanczos).
    pub(crate) exact: bool,
    /// The number of negative eigenvalues by Sylvester's law of inertia, from an accurate LDLᵀ
    /// of the KKT matrix (negative pivots minus rows), when the Lanczos path had one: a
    /// certificate that does not depend on Lanczos finding the negative end.
    pub(crate) negative_by_inertia: Option<usize>,
    /// The null-space basis `Z` the exact reduced Hessian was formed with, where it was kept
    /// (`System::reduced_hessian_and_basis`).
    pub(crate) basis: Option<DMatrix<f64>>,
}

impl Spectrum {
    /// Eigenvalue tolerance of the stability verdict: `1e-10 max(|λ|max, 1)` (`largest`: exact
    /// where all eigenvalues are known, else the estimate `λ̃ ≤ |λ|max` of module `largest`). Rounding
    /// perturbs `Ŵ` by about `ε |Ŵ|` and the basis `Z` amplifies it by its conditioning, so the
    /// eigenvalues are resolved to about `10⁻¹² … 10⁻¹⁰ |λ|max`; a spread of stiffnesses
    /// beyond 10¹⁰ is called neutral. (The 10,000-link benchmark chain spans 74 … 2.4·10¹⁰.)
    pub(crate) fn tolerance(&self) -> f64 {
        1e-10 * self.largest.max(1.0)
    }

    /// Whether a negative eigenvalue `lambda` beyond [`Spectrum::tolerance`] is still below the
    /// reduced Hessian's error at a point stationary only to `gnorm = ‖∂V/∂v‖∞` (above the
    /// gradient's rounding floor `rounding`): the multipliers' term `λ·Φ_qq` of `Ĥ` carries the
    /// gradient's residual, an error of the order of `gnorm` in the eigenvalues (taken as
    /// `10 gnorm`: the chart's second derivatives are of order one in the scaled coordinates).
    /// Such a direction is not a saddle's yet: a Newton step that lowers the gradient comes
    /// first (the settling step, module `step::newton`). (A leg whose yaw axis is tilted 6·10⁻⁶ rad from vertical: −1.4·10⁻⁹ at `gnorm`
    /// 7·10⁻⁹, +6.2·10⁻¹⁰ after one more step, the curvature its energy shows along the yaw.)
    pub(crate) fn unresolved(&self, lambda: f64, gnorm: f64, rounding: f64) -> bool {
        lambda < -self.tolerance() && lambda > -Self::error(gnorm) && gnorm > rounding
    }

    /// The error of the reduced Hessian's eigenvalues at a point stationary only to
    /// `gnorm = ‖∂V/∂v‖∞`: `10 gnorm` ([`Spectrum::unresolved`]).
    pub(crate) fn error(gnorm: f64) -> f64 {
        10.0 * gnorm
    }

    /// The smallest eigenvalue and its index.
    pub(crate) fn lowest(&self) -> Option<(usize, f64)> {
        self.values
            .iter()
            .copied()
            .enumerate()
            .min_by(|a, b| a.1.total_cmp(&b.1))
    }
}

/// Whether the spectrum of `dof` degrees of freedom with `backend` is exact (the reduced
/// Hessian formed and decomposed) rather than found by Lanczos.
pub(crate) fn exact(backend: Backend, dof: usize) -> bool {
    backend == Backend::Dense || dof <= EXACT_UP_TO
}

/// Whether the stability verdict of `dof` degrees of freedom with `backend` lists its
/// eigenvalues by default (the dense path, or at most [`LISTED_UP_TO`]); otherwise the verdict
/// comes from the KKT inertia (module `inertia`) unless eigenvalues are asked for.
pub(crate) fn listed(backend: Backend, dof: usize) -> bool {
    backend == Backend::Dense || dof <= LISTED_UP_TO
}

/// The spectrum at a feasible `q` (dof > 0): exact where [`exact`], else by Lanczos.
pub(crate) fn spectrum(
    sys: &mut System,
    q: &DVector<f64>,
    part: &Partition,
    eval: &Eval,
) -> Spectrum {
    spectrum_knowing(sys, q, part, eval, None)
}

/// [`spectrum`], with the estimate `λ_max` (module `largest`) at this same point if already at hand
/// (an inertia verdict's: `stability::inertia::ByInertia`), not iterated again.
pub(crate) fn spectrum_knowing(
    sys: &mut System,
    q: &DVector<f64>,
    part: &Partition,
    eval: &Eval,
    largest: Option<f64>,
) -> Spectrum {
    let dof = part.independent.len();
    if exact(sys.backend, dof) {
        let (h, basis) = sys.reduced_hessian_and_basis(q, part, eval);
        return exact_spectrum(&h, basis);
    }
    lanczos(sys, q, part, eval, largest).unwrap_or_else(|| Spectrum {
        // A singular reduced Hessian (the KKT matrix cannot be factored): neutral.
        values: DVector::zeros(1),
        vectors: DMatrix::zeros(dof, 1),
        largest: 1.0,
        exact: false,
        negative_by_inertia: None,
        basis: None,
    })
}

/// The exact spectrum of the reduced Hessian `h`, formed with the null-space basis `basis`
/// (kept where `System::reduced_hessian_and_basis` kept it).
pub(crate) fn exact_spectrum(h: &DMatrix<f64>, basis: Option<DMatrix<f64>>) -> Spectrum {
    let (values, vectors) = block_symmetric_eigen(h);
    let largest = values.amax();
    Spectrum {
        values,
        vectors,
        largest,
        exact: true,
        negative_by_inertia: None,
        basis,
    }
}

fn lanczos(
    sys: &mut System,
    q: &DVector<f64>,
    part: &Partition,
    eval: &Eval,
    largest: Option<f64>,
) -> Option<Spectrum> {
    let dof = part.independent.len();
    let n = q.len();
    let factored = sys.factor_kkt(q, part, eval, true, 0.0);
    if factored == Factored::None {
        return None;
    }
    // Make sure the factors solve accurately (LDLᵀ may not: then LU, and no inertia).
    let mut probe = DVector::zeros(n);
    for &c in &part.independent {
        probe[c] = 1.0;
    }
    let negative_by_inertia = match (sys.kkt_solve(&probe), factored) {
        (Some(_), Factored::Ldlt { negative }) => Some(negative.saturating_sub(part.rows.len())),
        (Some(_), _) => None,
        (None, _) => {
            sys.kkt_fall_back_to_lu();
            None
        }
    };
    // The largest eigenvalue: Lanczos on `Ĥ` (module `largest`: products through `Φ_u`'s factors and
    // `W`); the smallest: Lanczos through the KKT factors.
    let largest = largest.unwrap_or_else(|| largest_eigenvalue(sys, part, eval));
    let steps = lanczos_steps(sys, part, n, negative_by_inertia);
    let (alpha, beta, basis) = steps?;
    let k = alpha.len();
    let (theta, s) = ritz(&alpha, &beta);
    let last_beta = beta[k - 1];
    let mut pairs: Vec<(f64, DVector<f64>)> = (0..k)
        .filter(|&i| theta[i] != 0.0 && (last_beta * s[(k - 1, i)]).abs() <= 1e-8 * theta[i].abs())
        .map(|i| {
            let mut y = DVector::zeros(dof);
            for (j, b) in basis.iter().take(k).enumerate() {
                y.axpy(s[(j, i)], b, 1.0);
            }
            (1.0 / theta[i], y)
        })
        .collect();
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    pairs.truncate(WANTED);
    if pairs.is_empty() {
        return None;
    }
    let values = DVector::from_iterator(pairs.len(), pairs.iter().map(|p| p.0));
    let mut vectors = DMatrix::zeros(dof, pairs.len());
    for (i, p) in pairs.iter().enumerate() {
        vectors.set_column(i, &p.1);
    }
    Some(Spectrum {
        largest: largest.max(values.amax()),
        values,
        vectors,
        exact: false,
        negative_by_inertia,
        basis: None,
    })
}

/// The Lanczos recurrence on `Ĥ⁻¹` (applied by the KKT factors) with full
/// reorthogonalization: the diagonal `α`, off-diagonal `β` of `T_k` and the basis; `None` if a
/// solve fails. Stops early once the low end has converged when `negative_by_inertia` shows no
/// negative eigenvalue ([`low_end_converged`]).
#[allow(clippy::type_complexity)]
fn lanczos_steps(
    sys: &System,
    part: &Partition,
    n: usize,
    negative_by_inertia: Option<usize>,
) -> Option<(Vec<f64>, Vec<f64>, Vec<DVector<f64>>)> {
    let dof = part.independent.len();
    let apply_inverse = |x: &DVector<f64>| -> Option<DVector<f64>> {
        let mut b = DVector::zeros(n);
        for (k, &c) in part.independent.iter().enumerate() {
            b[c] = x[k];
        }
        // Lanczos needs the solves to about 10⁻¹¹, not to the last digit.
        let dq = sys.kkt_solve_to(&b, 1e-11)?;
        Some(DVector::from_iterator(
            dof,
            part.independent.iter().map(|&c| dq[c]),
        ))
    };
    let k_max = STEPS.min(dof);
    let mut basis: Vec<DVector<f64>> = Vec::with_capacity(k_max + 1);
    let mut v = DVector::from_fn(dof, |i, _| {
        ((i as f64 + 1.0) * 0.618_033_988_749).fract() - 0.5
    });
    v /= v.norm();
    basis.push(v);
    let (mut alpha, mut beta) = (Vec::new(), Vec::new());
    for k in 0..k_max {
        let mut w = apply_inverse(&basis[k])?;
        let a = w.dot(&basis[k]);
        alpha.push(a);
        orthogonalize_twice(&mut w, &basis);
        let bnorm = w.norm();
        beta.push(bnorm);
        if bnorm <= 1e-14 * a.abs().max(1e-300)
            || k + 1 == k_max
            || (negative_by_inertia == Some(0) && low_end_converged(&alpha, &beta))
        {
            break;
        }
        basis.push(w / bnorm);
    }
    Some((alpha, beta, basis))
}

/// The Ritz values `θ` (ascending) and vectors of the Lanczos tridiagonal matrix with diagonal
/// `alpha` and off-diagonal `beta`.
fn ritz(alpha: &[f64], beta: &[f64]) -> (DVector<f64>, DMatrix<f64>) {
    symmetric_eigen(&tridiagonal(alpha, beta))
}

/// Whether the `WANTED` largest Ritz values of the tridiagonal `T_k` (`alpha`, `beta`; the
/// smallest eigenvalues of `Ĥ` when all are positive) pass the residual test of the kept
/// pairs, `|β_k s_ki| ≤ 10⁻⁸ |θ_i|`: then further steps would change the reported values in
/// their last digits only. Checked once `k ≥ WANTED + 2`; the cost is one `k × k` symmetric
/// eigendecomposition, far below a KKT solve.
fn low_end_converged(alpha: &[f64], beta: &[f64]) -> bool {
    let k = alpha.len();
    if k < WANTED + 2 {
        return false;
    }
    let (theta, s) = ritz(alpha, beta);
    let last_beta = beta[k - 1];
    // Ascending: the largest θ (smallest positive eigenvalues of Ĥ) last.
    (k - WANTED..k)
        .all(|i| theta[i] > 0.0 && (last_beta * s[(k - 1, i)]).abs() <= 1e-8 * theta[i].abs())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::constraints::Constraints;
    use crate::urdf::{load_str, ImportOptions};

    /// Lanczos on the inverse through the KKT factors finds the smallest eigenvalues of the
    /// explicitly formed reduced Hessian of a 240-link chain (more degrees of freedom than
    /// `EXACT_UP_TO`), and a negative one on a chain held upside down.
    #[test]
    fn lanczos_finds_the_low_end_of_the_exact_spectrum() {
        let n = EXACT_UP_TO + 40;
        let text = crate::generate::chain(n, false);
        for flip in [false, true] {
            let text = if flip {
                // Gravity up and weak springs: the bent chain is far from stable.
                let mut t = String::new();
                let mut rest = text.replace("0 0 -9.81", "0 0 9.81");
                while let Some(i) = rest.find("stiffness=\"") {
                    t.push_str(&rest[..i]);
                    t.push_str("stiffness=\"0.01");
                    let tail = &rest[i + 11..];
                    rest = tail[tail.find('"').unwrap()..].to_string();
                }
                t + &rest
            } else {
                text.clone()
            };
            let model = load_str(&text, "c.urdf", &ImportOptions::default())
                .unwrap()
                .model;
            // A bent configuration, away from any symmetry.
            let mut values = crate::state::JointValues::new();
            for i in 0..n {
                values.insert(format!("joint{i}"), vec![0.3 * ((i as f64) * 0.7).sin()]);
            }
            let q = crate::state::State::from_joint_values(&model, &values).q;
            let mut sys = System::new(&model, Constraints::new(&model, &[]), Backend::Sparse);
            let part = sys.partition(&q);
            let eval = sys.evaluate(&q, &part).unwrap();
            let exact = symmetric_eigen(&sys.reduced_hessian(&q, &part, &eval)).0;
            let lz = lanczos(&mut sys, &q, &part, &eval, None).unwrap();
            let lo = lz.values[0];
            // Each Ritz value is an eigenvalue; without a flip the lowest is the lowest.
            for &l in lz.values.iter() {
                let nearest = exact
                    .iter()
                    .map(|e| (e - l).abs())
                    .fold(f64::INFINITY, f64::min);
                assert!(
                    nearest <= 1e-6 * l.abs(),
                    "flip {flip}: Ritz value {l} off the spectrum"
                );
            }
            if !flip {
                assert!(
                    (lo - exact[0]).abs() <= 1e-6 * exact[0].abs(),
                    "{lo} vs {}",
                    exact[0]
                );
                // Stopped once converged (no negative pivot): the six smallest, in order.
                assert_eq!(lz.values.len(), WANTED);
                for (i, &l) in lz.values.iter().enumerate() {
                    assert!(
                        (l - exact[i]).abs() <= 1e-8 * exact[i].abs(),
                        "eigenvalue {i}: {l} vs {}",
                        exact[i]
                    );
                }
            }
            assert_eq!(lo < 0.0, flip);
            assert_eq!(exact[0] < 0.0, flip);
            // The inertia of the KKT matrix counts the negative eigenvalues exactly.
            let negatives = exact.iter().filter(|&&e| e < 0.0).count();
            assert_eq!(lz.negative_by_inertia, Some(negatives), "flip {flip}");
            assert!((lz.largest - exact.amax()).abs() < 0.05 * exact.amax());
        }
    }
}
