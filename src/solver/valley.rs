//! Curved valleys: a trial point of the line search brought back to the valley floor along
//! the stiff eigenvectors of the reduced Hessian before it is judged.
//!
//! Where the reduced Hessian has a few near-neutral directions (a hanging leg whose centre of
//! mass lies almost on its hip-yaw axis: curvature `ε″ ≈ 10⁻⁹ N m/rad`) well apart from the
//! rest, the energy near the floor of the valley reads `V ≈ ½ k (θ − a(ψ))² + ε(ψ)`, `ψ` the
//! soft coordinate, `θ` the stiff ones. Off the floor the soft curvature is
//! `ε″ − (∂V/∂θ) a″`: a stiff gradient of 10⁻⁶ already hides `ε″`, the Newton step along `ψ`
//! is a few per cent of the way, and the straight step leaves the curved floor by `½ a″ Δψ²`,
//! which brings the stiff gradient back. The iteration crawls (iCub reduced hanging: 36
//! iterations in one active-set round, the hip yaw moving 0.4 rad by 0.01 rad a step, the energy
//! changing below its rounding).
//!
//! The remedy is the second-order correction of constrained optimization applied to the
//! valley: at a trial point `v̂ + α d` with reduced gradient `g`, the stiff Newton step
//!
//! `δ = −Σ_{i stiff} w_i (w_iᵀ g) / λ_i`
//!
//! (`λ_i, w_i` the eigenpairs of the reduced Hessian at the point corrected, recomputed for
//! each correction: the stiff directions turn with the soft coordinate; the stiff ones all but
//! the valley's soft ones, those below a spectral gap of [`GAP`] at `v̂`; up to
//! [`CORRECTIONS`] times, each kept where it lowers the merit and the gradient) moves the
//! trial point back to the floor, and the line search judges the corrected point. With the
//! eigenpairs of `v̂` instead (main until session 26), iCub's round along its right hip yaw
//! crawled 8 iterations: the trial points 0.6 rad along the yaw stayed 10⁻⁹ … 10⁻⁸ J above
//! the start, off the floor, and the search backtracked to a tenth. The next iterate then sits on the floor, its soft curvature is `ε″` itself
//! and the Newton step along `ψ` goes the whole way. Along the floor the energy may change by
//! less than its rounding: a trial point whose merit is equal to rounding is then accepted when
//! its gradient along the soft eigenvectors is smaller ([`Valley::closer`]). All this only
//! where the iteration has stalled (the gradient fell by less than [`STALL`] over the last step)
//! and the spectrum has the gap; from then on in the round.
//!
//! The watch reads the spectrum of `Ĥ`; where that has no valley it reads the spectrum of the
//! Hessian along the path `Ĥ + C` (module `step::path_hessian`, computed for the Newton step
//! anyway) if that one has a neutral direction, at rounding level ([`RESOLVED`]): the neutral
//! directions are set aside as soft (the correction leaves them alone) and the gap is looked
//! for among the others ([`Valley::along_path`]). A robot hanging from a vertical base yaw has
//! one, and `Ĥ` mixes it with the chart's curvature, a term of the gradient's size and either
//! sign, which `Valley::of` refuses: the KUKA iiwa 14 of rtb-data crawled 32 iterations along
//! its near-neutral wrist (`joint_a5`, 0.08 rad per iteration, `Ĥ`'s lowest eigenvalue
//! −10⁻⁴ where the path's is 10⁻¹⁵) with the watch off; with it, 9 (56 → 33 in all, the same
//! rest). Read only where a neutral direction is present, the path's spectrum changes no answer
//! of the corpora; read wherever `Ĥ`'s has no valley, it moved SO-100 (6 → 7 iterations, a stop
//! fewer at rest, the same energy), iCub (27 → 28) and iCub reduced (26 → 25). Such a
//! valley's corrections cross no inactive inequality (the line search's guard judged the
//! trial point before them): otherwise they carried the PincherX 100 of rtb-data past a stop,
//! whose next round started 0.03 J higher (7 → 9 iterations). Every valley's corrections are
//! now guarded so, bent at the stops they reach (below, "Stops"); the test alone, without the
//! bend, took iCub 27 → 28, and with it iCub takes 26 and iCub reduced rests at the
//! quasi-static release's rest, 8.4·10⁻⁴ J above the one main reached across a stop.
//!
//! In such a valley the gradient test alone does not place the soft coordinate (a curvature of
//! 10⁻⁹ N m/rad and a tolerance of 10⁻⁸ J leave it free over radians), so a point that passes
//! it is taken as the rest only when the Newton step along the soft eigenvectors is below
//! [`SETTLED`] ([`Watch::unsettled`]).
//!
//! ## Stops
//!
//! The stiff step moves joints the line search's trial point did not move, and can carry one
//! across an inactive stop: icub-models' iCubGenova03 (hanging, its massless neck links) had
//! its neck roll, held at its upper stop by the bent trial point, carried 0.235 rad past it by
//! the correction; the point was accepted, the next round's first step met the violated stop at
//! `α = 0` and the round after projected the pose back onto it, 0.034 J uphill (and 5
//! iterations to come back). With the projected search the correction's path is bent at the
//! stops as the line search's is (module `inequality::bend`: a stop at its boundary that the
//! correction closes is held from its start), those stops join the active set with the ones
//! the trial point reached, and a correction step that still violates an inactive inequality
//! (through the corrector) is not taken.
//!
//! ## References
//! - J. Nocedal, S. J. Wright, *Numerical Optimization*, 2nd ed., Springer (2006), §15.6
//!   (second-order correction), §3.4.
//! - H. H. Rosenbrock, An automatic method for finding the greatest or least value of a
//!   function, *Computer Journal* 3 (1960) 175–184 (the curved valley).

use super::inequality::active_set::Guard;
use super::inequality::bend::Stop;
use super::options::Options;
use super::partition::Partition;
use super::report::{Diagnostics, Iterate};
use super::stability::blocks::block_symmetric_eigen;
use super::stability::spectrum::Spectrum;
use super::system::{Eval, System};
use nalgebra::{DMatrix, DVector};

/// The ratio between the smallest stiff and the largest soft eigenvalue magnitude that
/// separates a valley's floor from its walls.
pub(crate) const GAP: f64 = 1e3;

/// A step after which the reduced gradient is above this fraction of what it was has stalled
/// (a Newton step in its quadratic range cuts it by far more).
pub(crate) const STALL: f64 = 0.1;

/// A valley's soft curvature is resolved above this fraction of the largest eigenvalue (the
/// dense Newton step's floor, module `step::newton`).
pub(crate) const RESOLVED: f64 = 1e-12;

/// A point that passed the gradient test in a valley is settled when the Newton step along
/// the soft eigenvectors moves no scaled coordinate by more than this (rad, or lengths `L`).
pub(crate) const SETTLED: f64 = 1e-3;

/// Iterations a round takes past the gradient test to settle the soft coordinates.
pub(crate) const MAX_SETTLING: usize = 3;

/// Stiff Newton steps that bring a trial point back to the floor at most, each with the
/// reduced Hessian at the point it starts from.
pub(crate) const CORRECTIONS: usize = 3;

/// The soft eigenpairs of the reduced Hessian at the start of a line search (the valley's
/// floor).
pub(crate) struct Valley {
    soft: Vec<(DVector<f64>, f64)>,
    /// Read from the Hessian along the path beside a neutral direction
    /// ([`Valley::along_path`]): its corrections are checked against the inactive
    /// inequalities before they are evaluated (every valley's are, after).
    guarded: bool,
}

/// The valley watch of one minimization (one active-set round).
#[derive(Default)]
pub(crate) struct Watch {
    /// A step has stalled where the spectrum has a valley's gap.
    on: bool,
    /// Iterations taken past the gradient test to settle the soft coordinates.
    settling: usize,
}

/// Whether the last step of the round (`history`, its iterates so far) stalled: its gradient
/// norm above [`STALL`] times the one before.
fn stalled(history: &[Iterate]) -> bool {
    match history {
        [.., a, b] => b.gradient_norm > STALL * a.gradient_norm,
        _ => false,
    }
}

impl Watch {
    /// The valley of the spectrum `e` of `Ĥ` for this step, else of the spectrum `path` of the
    /// Hessian along the path with its neutral directions set aside ([`Valley::along_path`]),
    /// once a step of the round (`history`, its iterates so far) has stalled where a spectrum
    /// has the gap.
    pub(crate) fn step(
        &mut self,
        e: Option<&Spectrum>,
        path: Option<&Spectrum>,
        history: &[Iterate],
    ) -> Option<Valley> {
        let stalled = stalled(history);
        if !(self.on || stalled) {
            return None;
        }
        let valley = e
            .and_then(Valley::of)
            .or_else(|| path.and_then(Valley::along_path));
        self.on |= stalled && valley.is_some();
        valley.filter(|_| self.on)
    }

    /// Whether [`Watch::step`] reads the spectra at this step (on, or the last step stalled):
    /// elsewhere they need not be computed for it (module `step::path_cholesky`).
    pub(crate) fn looks(&self, history: &[Iterate]) -> bool {
        self.on || stalled(history)
    }

    /// Whether a point that passed the gradient test is still far from the lowest point of
    /// its valley: with a soft curvature of 10⁻⁹ N m/rad a gradient tolerance of 10⁻⁸ J
    /// leaves the soft coordinate free over radians. So the round goes on (at most
    /// [`MAX_SETTLING`] times) while the Newton step along the soft eigenvectors moves a scaled
    /// coordinate by more than [`SETTLED`] and their gradient is above ten times the rounding
    /// floor `floor` of the gradient.
    pub(crate) fn unsettled(&mut self, e: &Spectrum, g: &DVector<f64>, floor: f64) -> bool {
        let Some(valley) = Valley::of(e).filter(|_| self.on && self.settling < MAX_SETTLING) else {
            return false;
        };
        let mut d = DVector::zeros(g.len());
        for (w, l) in &valley.soft {
            let c = w.dot(g);
            if c.abs() > 10.0 * floor {
                d += w * (c / l);
            }
        }
        let far = d.amax() > SETTLED;
        self.settling += usize::from(far);
        far
    }
}

impl Valley {
    /// The valley of the spectrum `e` of `Ĥ`, where it has a gap of [`GAP`] between its soft
    /// eigenvalues (at most half of them) and its stiff ones, every eigenvalue positive and
    /// above [`RESOLVED`] of the largest.
    pub(crate) fn of(e: &Spectrum) -> Option<Valley> {
        Valley::split(e, false)
    }

    /// The valley of the spectrum `e` of the Hessian along the path `Ĥ + C` (module
    /// `step::path_hessian`), its neutral directions (magnitudes at most [`RESOLVED`] of the
    /// largest: a base yaw about the vertical) set aside: they count as soft, and the gap is
    /// looked for among the others, every one of them positive. `Ĥ` alone mixes a neutral
    /// direction with the chart's curvature, a term of the gradient's size and either sign
    /// (−10⁻⁴ on the KUKA iiwa 14 whose base yaw is exactly neutral), so [`Valley::of`] finds
    /// no valley there; along the path the neutral direction is at rounding level (10⁻¹⁵).
    /// `None` where the spectrum has no neutral direction (there `Ĥ`'s decides, module docs).
    pub(crate) fn along_path(e: &Spectrum) -> Option<Valley> {
        Valley::split(e, true)
    }

    /// [`Valley::of`], with the neutral directions set aside where `neutral_aside` is set.
    fn split(e: &Spectrum, neutral_aside: bool) -> Option<Valley> {
        let n = e.values.len();
        if !e.exact || n < 2 {
            return None;
        }
        let mut order: Vec<usize> = (0..n).collect();
        order.sort_by(|&a, &b| e.values[a].abs().total_cmp(&e.values[b].abs()));
        let resolved = RESOLVED * e.values.amax();
        // The neutral directions set aside: the smallest magnitudes, at rounding level.
        let neutral = if neutral_aside {
            order
                .iter()
                .take_while(|&&i| e.values[i].abs() <= resolved)
                .count()
        } else {
            0
        };
        // The widest gap among the lower half of the other magnitudes.
        let (mut split, mut ratio) = (0, 0.0);
        for k in neutral..neutral + (n - neutral) / 2 {
            let r = e.values[order[k + 1]].abs() / e.values[order[k]].abs().max(1e-300);
            if r > ratio {
                (split, ratio) = (k + 1, r);
            }
        }
        // Otherwise a soft eigenvalue at rounding level is a neutral direction (a wrist whose
        // axis passes through its load), not a valley floor: every rest along it is as good.
        // Along the path, only a spectrum with a neutral direction is read (where it has none,
        // `Ĥ`'s is: `Valley::of`).
        if ratio < GAP
            || (neutral_aside && neutral == 0)
            || order[neutral..].iter().any(|&i| e.values[i] <= resolved)
        {
            return None;
        }
        Some(Valley {
            guarded: neutral_aside,
            soft: order[..split]
                .iter()
                .map(|&i| (e.vectors.column(i).into_owned(), e.values[i]))
                .collect(),
        })
    }

    /// The stiff Newton step at the reduced gradient `g` (module docs) with the eigenpairs
    /// `(values, vectors)` of the reduced Hessian where `g` was taken: along all but the
    /// valley's number of soft directions (the smallest magnitudes); `None` where one of
    /// those stiff eigenvalues is not positive (no floor to go back to).
    fn stiff_step(
        &self,
        values: &DVector<f64>,
        vectors: &DMatrix<f64>,
        g: &DVector<f64>,
    ) -> Option<DVector<f64>> {
        let mut order: Vec<usize> = (0..values.len()).collect();
        order.sort_by(|&a, &b| values[a].abs().total_cmp(&values[b].abs()));
        let mut d = DVector::zeros(g.len());
        for &i in order.iter().skip(self.soft.len()) {
            if values[i] <= 0.0 {
                return None;
            }
            let w = vectors.column(i);
            d -= w * (w.dot(g) / values[i]);
        }
        Some(d)
    }

    /// Whether the gradient along the floor (on the soft eigenvectors) is smaller at `g1` than
    /// at `g0`: the line search's test where the energy along the floor changes below its
    /// rounding (module docs).
    pub(crate) fn closer(&self, g0: &DVector<f64>, g1: &DVector<f64>) -> bool {
        let along = |g: &DVector<f64>| self.soft.iter().map(|(w, _)| w.dot(g).powi(2)).sum::<f64>();
        along(g1) < along(g0)
    }

    /// The trial point `(q, eval)` moved to the valley floor by up to [`CORRECTIONS`] stiff
    /// Newton steps, each kept while it lowers both the merit and the gradient and, under a
    /// `guard`, violates no inactive inequality (in a valley read beside a neutral direction
    /// checked before the trial point is evaluated); the stops a kept step holds at their
    /// boundary (the projected search) are added to `held` (module docs, "Stops").
    pub(crate) fn correct(
        &self,
        sys: &mut System,
        part: &Partition,
        (options, guard): (&Options, Option<&Guard>),
        diag: &mut Diagnostics,
        (mut q, mut eval): (DVector<f64>, Eval),
        held: &mut Vec<Stop>,
    ) -> (DVector<f64>, Eval) {
        for _ in 0..CORRECTIONS {
            // The stiff directions of the trial point itself: they turn with the soft
            // coordinate (iCub's leg as its hip yaw turns 0.6 rad).
            let h = sys.reduced_hessian(&q, part, &eval);
            let (values, vectors) = block_symmetric_eigen(&h);
            let Some(d) = self.stiff_step(&values, &vectors, &eval.grad_v) else {
                break;
            };
            let dq = sys.tangent_step(part, &eval, &d);
            // The stops the correction reaches (those at their boundary that it closes from
            // its start) held there, as along the line search's bent path (module docs).
            let bend = options.stop_search == super::options::StopSearch::Projected;
            let caps: Vec<Stop> = match guard.filter(|_| bend) {
                Some(g) => g
                    .stops_from(sys, &q, &dq, 1.0, true)
                    .into_iter()
                    .filter(|s| s.alpha < 1.0)
                    .collect(),
                None => Vec::new(),
            };
            let mut qc = if caps.is_empty() {
                sys.problem.retraction.point(&q, &dq, 1.0)
            } else {
                let bodies: Vec<(usize, f64)> = caps.iter().map(|s| (s.body, s.alpha)).collect();
                sys.problem.retraction.bent_point(&q, &dq, 1.0, &bodies)
            };
            if sys
                .correct_from(
                    &mut qc,
                    part,
                    options.constraint_tolerance,
                    options.max_corrector_iterations,
                    Some(&eval.factors),
                )
                .is_err()
            {
                diag.corrector_failures += 1;
                break;
            }
            if self.guarded && guard.is_some_and(|g| g.violated(sys, &qc)) {
                break;
            }
            let Some(ec) = sys.evaluate(&qc, part) else {
                break;
            };
            diag.function_evaluations += 1;
            if ec.merit > eval.merit
                || ec.grad_v.amax() >= eval.grad_v.amax()
                || guard.is_some_and(|g| g.violated(sys, &qc))
            {
                break;
            }
            (q, eval) = (qc, ec);
            held.extend(caps);
        }
        (q, eval)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spectrum(values: &[f64]) -> Spectrum {
        let n = values.len();
        Spectrum {
            values: DVector::from_row_slice(values),
            vectors: DMatrix::identity(n, n),
            largest: values.iter().fold(0.0f64, |m, v| m.max(v.abs())),
            exact: true,
            negative_by_inertia: None,
            basis: None,
        }
    }

    #[test]
    fn a_gap_of_a_thousand_separates_the_floor_from_the_walls() {
        let v = Valley::of(&spectrum(&[2.0, 1e-7, 0.02, 70.0])).expect("a valley");
        // The stiff step leaves the soft component alone and is Newton's on the others.
        let g = DVector::from_row_slice(&[4.0, 1.0, 0.02, 7.0]);
        let e = spectrum(&[2.0, 1e-7, 0.02, 70.0]);
        let d = v.stiff_step(&e.values, &e.vectors, &g).unwrap();
        assert_eq!(d[1], 0.0);
        assert!(
            (d[0] + 2.0).abs() < 1e-15 && (d[2] + 1.0).abs() < 1e-15 && (d[3] + 0.1).abs() < 1e-15
        );
    }

    #[test]
    fn the_stiff_step_follows_the_directions_of_the_point_it_corrects() {
        // The valley of the start: soft along e₀, stiff along e₁. At the trial point the
        // floor has turned by 30°: the stiff step is Newton's along the turned direction
        // (leaving the turned soft one alone), not along e₁.
        let v = Valley::of(&spectrum(&[1e-9, 1.0])).expect("a valley");
        let (c, s) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
        let vectors = DMatrix::from_row_slice(2, 2, &[c, -s, s, c]);
        let values = DVector::from_row_slice(&[2e-9, 4.0]);
        let g = DVector::from_row_slice(&[0.3, 0.5]);
        let d = v.stiff_step(&values, &vectors, &g).unwrap();
        let (soft, stiff) = (vectors.column(0), vectors.column(1));
        assert!(d.dot(&soft).abs() < 1e-15, "{d}");
        assert!((d.dot(&stiff) + stiff.dot(&g) / 4.0).abs() < 1e-15, "{d}");
        // No floor where a stiff eigenvalue is not positive.
        let values = DVector::from_row_slice(&[2e-9, -4.0]);
        assert!(v.stiff_step(&values, &vectors, &g).is_none());
    }

    #[test]
    fn the_floor_gradient_decides_and_a_long_soft_step_is_not_a_rest() {
        let e = spectrum(&[1e-9, 1.0]);
        let v = Valley::of(&e).expect("a valley");
        let g0 = DVector::from_row_slice(&[6e-10, 1e-3]);
        // Smaller along the floor, larger on the wall: closer to the floor's lowest point.
        assert!(v.closer(&g0, &DVector::from_row_slice(&[1e-10, 1e-2])));
        assert!(!v.closer(&g0, &DVector::from_row_slice(&[-7e-10, 0.0])));
        // 6·10⁻¹⁰ J below the gradient tolerance, but the Newton step along the floor is
        // 0.6 rad: not settled, once the round is in the valley, and at most MAX_SETTLING times.
        let g = DVector::from_row_slice(&[6e-10, 0.0]);
        let mut watch = Watch::default();
        assert!(!watch.unsettled(&e, &g, 1e-12));
        watch.on = true;
        for _ in 0..MAX_SETTLING {
            assert!(watch.unsettled(&e, &g, 1e-12));
        }
        assert!(!watch.unsettled(&e, &g, 1e-12));
        // Settled: a step of 10⁻⁴; or a soft gradient at the rounding floor.
        let mut watch = Watch {
            on: true,
            settling: 0,
        };
        assert!(!watch.unsettled(&e, &DVector::from_row_slice(&[1e-13, 0.0]), 1e-12));
        assert!(!watch.unsettled(&e, &DVector::from_row_slice(&[6e-10, 0.0]), 1e-10));
    }

    #[test]
    fn along_the_path_a_neutral_direction_is_set_aside() {
        // The KUKA iiwa's round along its wrist: the base yaw exactly neutral (10⁻¹⁵ along the
        // path), the wrist soft (10⁻³), three stiff directions.
        let e = spectrum(&[1.5, 1e-15, 16.0, 1e-3, 33.0]);
        assert!(Valley::of(&e).is_none());
        let v = Valley::along_path(&e).expect("a valley beside the neutral direction");
        assert_eq!(v.soft.len(), 2);
        // The correction leaves both alone: Newton along the three stiff directions only.
        let g = DVector::from_row_slice(&[3.0, 1e-16, 32.0, 1e-4, 66.0]);
        let d = v.stiff_step(&e.values, &e.vectors, &g).unwrap();
        assert_eq!((d[1], d[3]), (0.0, 0.0));
        assert!(
            (d[0] + 2.0).abs() < 1e-15 && (d[2] + 2.0).abs() < 1e-15,
            "{d}"
        );
        // Only the gap among the others counts, and they must all be positive.
        assert!(Valley::along_path(&spectrum(&[1e-15, 1e-1, 1.5, 16.0])).is_none());
        assert!(Valley::along_path(&spectrum(&[1e-15, -1e-3, 1.5, 16.0])).is_none());
        // Without a neutral direction the path's spectrum is not read (`Ĥ`'s decides).
        assert!(Valley::along_path(&spectrum(&[1e-7, 1.0, 3.0])).is_none());
        assert!(Valley::of(&spectrum(&[1e-7, 1.0, 3.0])).is_some());
    }

    #[test]
    fn no_valley_without_a_gap_with_negative_curvature_or_a_neutral_direction() {
        assert!(Valley::of(&spectrum(&[1.0, 1e-2, 3.0])).is_none());
        assert!(Valley::of(&spectrum(&[-1.0, 1e-7, 3.0])).is_none());
        assert!(Valley::of(&spectrum(&[-1e-7, 1.0, 3.0])).is_none());
        assert!(Valley::of(&spectrum(&[1e-17, 1.0, 3.0])).is_none());
    }
}
