//! Force laws and their exact potentials.
//!
//! A law gives the force `F(δ)` at deflection `δ` (positive = tension). A tension-only spring
//! carries `max(F, 0)`, a compression-only one `min(F, 0)`. The stored energy is the exact
//! integral `U(δ) = ∫₀^δ F_eff(s) ds`: `F` is piecewise linear (one piece for a linear law), so
//! the integral is a sum of trapezoids between the table knots and the zero crossings of `F`.

use crate::model::{ForceLaw, SpringMode};

/// Energy `U(δ)`, force `F_eff(δ)` and stiffness `dF_eff/dδ` at deflection `δ`; `None` when
/// `δ` lies outside a table declared with `extrapolate="error"`.
pub(crate) fn evaluate(law: &ForceLaw, mode: SpringMode, delta: f64) -> Option<(f64, f64, f64)> {
    match law {
        ForceLaw::Linear { stiffness, preload } if mode == SpringMode::Both => Some((
            preload * delta + 0.5 * stiffness * delta * delta,
            preload + stiffness * delta,
            *stiffness,
        )),
        _ => {
            if let ForceLaw::Table {
                points,
                bounded: true,
                ..
            } = law
            {
                let (lo, hi) = (points.first()?.0, points.last()?.0);
                if delta < lo || delta > hi || 0.0 < lo || 0.0 > hi {
                    return None;
                }
            }
            let (f, k) = raw(law, delta);
            let (f, k) = clip(mode, f, k);
            let (a, b) = if delta >= 0.0 {
                (0.0, delta)
            } else {
                (delta, 0.0)
            };
            let mut cuts = vec![a, b];
            if let ForceLaw::Table { points, .. } = law {
                cuts.extend(points.iter().map(|p| p.0).filter(|&t| t > a && t < b));
            }
            cuts.sort_by(f64::total_cmp);
            let mut all = Vec::with_capacity(cuts.len() * 2);
            for w in cuts.windows(2) {
                all.push(w[0]);
                let (f0, _) = raw(law, w[0]);
                let (f1, _) = raw(law, w[1]);
                if f0 * f1 < 0.0 {
                    all.push(w[0] + (w[1] - w[0]) * f0 / (f0 - f1));
                }
            }
            all.push(b);
            let mut integral = 0.0;
            for w in all.windows(2) {
                let f0 = clip(mode, raw(law, w[0]).0, 0.0).0;
                let f1 = clip(mode, raw(law, w[1]).0, 0.0).0;
                integral += 0.5 * (f0 + f1) * (w[1] - w[0]);
            }
            let u = if delta >= 0.0 { integral } else { -integral };
            Some((u, f, k))
        }
    }
}

fn clip(mode: SpringMode, f: f64, k: f64) -> (f64, f64) {
    match mode {
        SpringMode::Both => (f, k),
        SpringMode::Tension if f > 0.0 => (f, k),
        SpringMode::Compression if f < 0.0 => (f, k),
        _ => (0.0, 0.0),
    }
}

/// Unclipped force and slope of the law at `δ`.
fn raw(law: &ForceLaw, delta: f64) -> (f64, f64) {
    match law {
        ForceLaw::Linear { stiffness, preload } => (preload + stiffness * delta, *stiffness),
        ForceLaw::Table {
            points,
            extrapolate_linear,
            ..
        } => {
            let n = points.len();
            if n == 0 {
                return (0.0, 0.0);
            }
            if n == 1 {
                return (points[0].1, 0.0);
            }
            let seg = points.partition_point(|p| p.0 <= delta).clamp(1, n - 1) - 1;
            let (x0, f0) = points[seg];
            let (x1, f1) = points[seg + 1];
            let slope = (f1 - f0) / (x1 - x0);
            let outside = delta < points[0].0 || delta > points[n - 1].0;
            if outside && !extrapolate_linear {
                let end = if delta < points[0].0 {
                    points[0].1
                } else {
                    points[n - 1].1
                };
                return (end, 0.0);
            }
            (f0 + slope * (delta - x0), slope)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table() -> ForceLaw {
        ForceLaw::Table {
            points: vec![(-0.1, -50.0), (0.0, 0.0), (0.05, 20.0), (0.1, 80.0)],
            extrapolate_linear: true,
            bounded: false,
        }
    }

    /// The energy's derivative is the force and the force's derivative the stiffness.
    #[test]
    fn energy_derivative_is_force() {
        let laws = [
            (
                ForceLaw::Linear {
                    stiffness: 300.0,
                    preload: 10.0,
                },
                SpringMode::Both,
            ),
            (
                ForceLaw::Linear {
                    stiffness: 300.0,
                    preload: 10.0,
                },
                SpringMode::Tension,
            ),
            (
                ForceLaw::Linear {
                    stiffness: 300.0,
                    preload: -10.0,
                },
                SpringMode::Compression,
            ),
            (table(), SpringMode::Both),
            (table(), SpringMode::Tension),
        ];
        for (law, mode) in laws {
            for i in -30..30 {
                let d = i as f64 * 0.0071 + 0.0013;
                let h = 1e-7;
                let (_, f, k) = evaluate(&law, mode, d).unwrap();
                let (up, fp, _) = evaluate(&law, mode, d + h).unwrap();
                let (um, fm, _) = evaluate(&law, mode, d - h).unwrap();
                assert!(
                    ((up - um) / (2.0 * h) - f).abs() < 1e-5,
                    "{law:?} {mode:?} at {d}"
                );
                assert!(
                    ((fp - fm) / (2.0 * h) - k).abs() < 1e-4,
                    "{law:?} {mode:?} at {d}"
                );
            }
        }
    }

    #[test]
    fn table_energy_closed_form() {
        // ∫₀^0.1 F = 0.5·0.05·20 + 0.5·(20 + 80)·0.05 = 0.5 + 2.5
        let (u, f, _) = evaluate(&table(), SpringMode::Both, 0.1).unwrap();
        assert!((u - 3.0).abs() < 1e-12);
        assert!((f - 80.0).abs() < 1e-12);
        let (u, _, _) = evaluate(&table(), SpringMode::Both, -0.1).unwrap();
        assert!((u - 2.5).abs() < 1e-12);
    }

    #[test]
    fn bounded_table_refuses_outside() {
        let law = ForceLaw::Table {
            points: vec![(-0.1, -1.0), (0.1, 1.0)],
            extrapolate_linear: false,
            bounded: true,
        };
        assert!(evaluate(&law, SpringMode::Both, 0.2).is_none());
        assert!(evaluate(&law, SpringMode::Both, 0.05).is_some());
    }
}
