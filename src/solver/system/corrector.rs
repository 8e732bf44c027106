//! The corrector: Newton on `Φ(u; v) = 0` for fixed `v`, `Φ_u δu = −Φ` over the independent
//! rows, optionally starting with chord steps on the factors of a nearby point. It gives up
//! at the second Newton step that does not decrease the residual (outside Newton's region of
//! convergence, or no solution for this `v`: the line search then halves the step) rather
//! than after `max_iterations` refactorizations. A point whose rows are all within their
//! rounding floor (module `residual`) is taken as it is: the search path along the tree
//! lands a chain's trial points there, and chasing the chord's target `10⁻³` of the
//! tolerance below it cost two chord steps and a Newton step at every trial point. The
//! residual is `‖D Φ‖∞` (module `residual`): over the independent rows while iterating, over
//! every row at the end.

use super::residual::REDUNDANT_FLOOR;
use super::{Factors, System};
use crate::solver::partition::Partition;
use nalgebra::DVector;

/// Why the corrector gave up.
#[derive(Debug)]
pub(crate) struct CorrectorFailure;

impl System<'_> {
    /// The Newton change of the dependent coordinates `Φ_u δu = −Φ` at `q` (independent rows);
    /// also leaves `Φ(q)` in the scratch.
    pub(crate) fn dependent_step(
        &mut self,
        q: &DVector<f64>,
        part: &Partition,
    ) -> Option<DVector<f64>> {
        self.triplets(q);
        let f = self.factors(part)?;
        let rhs = DVector::from_iterator(
            part.rows.len(),
            part.rows.iter().map(|&a| -self.work.phi[a]),
        );
        f.solve(&rhs)
    }

    /// Newton corrector: solves the independent rows for `u` with `v` fixed; returns the number
    /// of iterations. Also fails if the redundant rows are not satisfied at the end.
    #[cfg(test)]
    pub(crate) fn correct(
        &mut self,
        q: &mut DVector<f64>,
        part: &Partition,
        tol: f64,
        max_iterations: usize,
    ) -> Result<usize, CorrectorFailure> {
        self.correct_from(q, part, tol, max_iterations, None)
    }

    /// The corrector, starting with chord steps on the factors `chord` of `Φ_u` at a nearby
    /// point (no Jacobian, no factorization: `Φ_u(q₀) δu = −Φ(q)`) while each step at least
    /// halves the residual, then Newton steps with `Φ_u(q)` refactored.
    pub(crate) fn correct_from(
        &mut self,
        q: &mut DVector<f64>,
        part: &Partition,
        tol: f64,
        max_iterations: usize,
        chord: Option<&Factors>,
    ) -> Result<usize, CorrectorFailure> {
        self.correct_evaluated(q, part, (tol, max_iterations), chord, false)
    }

    /// [`System::correct_from`]; with `phi_in_scratch` the scratch holds `Φ(q)` already (the
    /// second-order correction of a line search evaluated it), and a first chord step starts
    /// from it instead of evaluating `Φ(q)` again (the same values: `Φ` alone at the same `q`).
    pub(crate) fn correct_evaluated(
        &mut self,
        q: &mut DVector<f64>,
        part: &Partition,
        (tol, max_iterations): (f64, usize),
        mut chord: Option<&Factors>,
        phi_in_scratch: bool,
    ) -> Result<usize, CorrectorFailure> {
        let mut first = f64::INFINITY;
        let mut last = f64::INFINITY;
        let (mut newton, mut stalls) = (false, 0);
        for it in 0..=max_iterations {
            // Before a Newton step `Φ` comes with the Jacobian the step needs (the same values
            // to the last bit as `Φ` alone, module `jet::closed`); where the corrector ends
            // here, the evaluation at the point that follows finds the triplets in place.
            if chord.is_none() {
                self.triplets(q);
            } else if !(it == 0 && phi_in_scratch) {
                self.residual(q);
            }
            let res = self
                .problem
                .scaling
                .residual_over(&self.work.phi, &part.rows);
            if !res.is_finite() {
                return Err(CorrectorFailure);
            }
            // Chord steps converge linearly: they go on to 10⁻³ of the tolerance, so that the
            // result is as tight as a Newton step would leave it (a stalled chord step
            // switches to Newton), or to the rounding floor of every row where that lies above
            // (no step can be resolved below it: module `residual`).
            let target = if chord.is_some() { 1e-3 * tol } else { tol };
            let floor = res <= tol && res > target && self.at_rounding_floor(q, part);
            if res <= target || floor || (res <= tol && it == max_iterations) {
                let all = self.dimensionless_residual();
                return if all <= tol.max(REDUNDANT_FLOOR) {
                    Ok(it)
                } else {
                    Err(CorrectorFailure)
                };
            }
            if it == 0 {
                first = res;
            } else if res > 1e3 * first.max(tol) {
                return Err(CorrectorFailure);
            }
            // Newton steps that do not decrease the residual: outside Newton's region of
            // convergence (or no solution for this `v`); the second one gives up.
            if newton && res >= last {
                stalls += 1;
                if stalls >= 2 {
                    return Err(CorrectorFailure);
                }
            }
            if it == max_iterations {
                break;
            }
            if res > 0.5 * last {
                chord = None;
            }
            last = res;
            newton = chord.is_none();
            let du = match chord {
                Some(f) => {
                    let rhs = DVector::from_iterator(
                        part.rows.len(),
                        part.rows.iter().map(|&a| -self.work.phi[a]),
                    );
                    f.solve(&rhs)
                }
                None => self.dependent_step(q, part),
            };
            let Some(du) = du else {
                return Err(CorrectorFailure);
            };
            for (k, &c) in part.dependent.iter().enumerate() {
                q[c] += du[k];
            }
        }
        Err(CorrectorFailure)
    }

    /// Whether `Φ` of the last evaluation (at `q`) is within the rounding floor of every
    /// independent row (module `residual`).
    fn at_rounding_floor(&self, q: &DVector<f64>, part: &Partition) -> bool {
        let scaling = &self.problem.scaling;
        let m = scaling.extent(q);
        scaling.at_rounding_floor(&self.problem.cons, &self.work.phi, &part.rows, m)
    }
}
