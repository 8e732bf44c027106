//! The reduced step of one iteration (stage 3 of module `minimize`), by the first that
//! applies:
//!
//! 0. where the convergence test asked for it (a lowest eigenvalue within the Hessian's error
//!    at a gradient below the tolerance) and the Hessian is exact, the settling step: Newton
//!    along the resolved curvatures only (module `newton`);
//! 1. where the path keeps every row (module `path_hessian`) and the Hessian is exact, the
//!    Newton step along the path, escaping maxima and saddles along every direction of
//!    negative curvature (module `escape`); on a small tree by Cholesky where `Ĥ + C` is
//!    positive definite, from `Ĥ` formed and not decomposed where no one reads its spectrum,
//!    and far from the rest Newton on `Ĥ` (module `path_cholesky`);
//! 2. at a stationary saddle, `max_step` along the eigenvector of the most negative
//!    eigenvalue, downhill;
//! 3. the Newton step with the eigenvalue magnitudes (dense, module `newton`), the KKT
//!    direction (sparse, module `kkt_direction`), or `−B ∇f` (module `quasi_newton`).

use crate::solver::inequality::active_set::Guard;
use crate::solver::minimize::EXACT_NEWTON_DOF;
use crate::solver::options::{Method, Options};
use crate::solver::partition::Partition;
use crate::solver::stability::spectrum::Spectrum;
use crate::solver::step::escape::escape_step;
use crate::solver::step::kkt_direction::kkt_direction;
use crate::solver::step::newton::{newton_step, settling_step};
use crate::solver::step::path_cholesky::{self, spectrum_step, Plan};
use crate::solver::step::path_hessian::path_keeps_rows;
use crate::solver::system::{Eval, System};
use nalgebra::{DMatrix, DVector};

/// The reduced step of one iteration (the output of [`direction`]).
pub(crate) struct Direction {
    /// The reduced step `d`.
    pub(crate) d: DVector<f64>,
    /// Whether it escaped along a direction of negative curvature.
    pub(crate) escaped: bool,
    /// Whether it is the KKT direction, whose factors then stay in `sys` (module
    /// `second_order`).
    pub(crate) kkt: bool,
    /// The spectrum of the Hessian along the path `Ĥ + C` where the step was taken with it
    /// (item 1; module `path_hessian`), for the valley watch (module `valley`).
    pub(crate) along_path: Option<Spectrum>,
}

impl Direction {
    fn plain(d: DVector<f64>, kkt: bool) -> Self {
        Direction {
            d,
            escaped: false,
            kkt,
            along_path: None,
        }
    }
}

/// The reduced step at `(q, part, eval)` (module docs), `eig` the reduced Hessian's spectrum
/// when computed, `plan` the small tree's plan where the convergence test made one (module
/// `path_cholesky`: then `eig` is `None`), `negative_curvature` the saddle's direction when
/// the point is stationary,
/// `settle` the Hessian's error where the convergence test asked for the settling step,
/// `binv` the quasi-Newton inverse Hessian.
pub(crate) fn direction(
    sys: &mut System,
    (q, part, eval): (&DVector<f64>, &Partition, &Eval),
    (eig, plan): (Option<&Spectrum>, Option<Plan>),
    negative_curvature: Option<&DVector<f64>>,
    settle: Option<f64>,
    binv: &DMatrix<f64>,
    guard: Option<&Guard>,
    options: &Options,
) -> Direction {
    let g = &eval.grad_v;
    let along = |(d, escaped, along_path)| Direction {
        d,
        escaped,
        kkt: false,
        along_path,
    };
    if let Some(plan) = plan {
        return along(path_cholesky::planned_step(
            sys,
            (q, part, eval),
            plan,
            guard,
            options,
        ));
    }
    if let (Some(band), Some(e)) = (settle, eig.filter(|e| e.exact)) {
        return Direction::plain(settling_step(e, g, band), false);
    }
    let newton = options.method == Method::Newton;
    let small =
        path_cholesky::small_tree(sys, newton && part.independent.len() <= EXACT_NEWTON_DOF);
    let path_step = eig
        .filter(|e| e.exact && newton && path_keeps_rows(sys))
        .map(|e| match small {
            true => spectrum_step(sys, (q, part, eval), e, guard, options),
            false => {
                let (d, escaped, path) = escape_step(sys, q, part, eval, e, guard, options);
                (d, escaped, Some(path))
            }
        });
    match (path_step, negative_curvature) {
        (Some(step), nc) if step.1 || nc.is_none() => along(step),
        (_, Some(nc)) => {
            let sign = if nc.dot(g) > 0.0 { -1.0 } else { 1.0 };
            let d = nc * (sign * options.max_step / nc.amax().max(1e-300));
            Direction::plain(d, false)
        }
        _ => match (eig, options.method) {
            (Some(e), Method::Newton) if e.exact => {
                Direction::plain(newton_step(e, g, None).0, false)
            }
            (_, Method::Newton) => {
                let (d, kkt) = kkt_direction(sys, q, part, eval);
                Direction::plain(d, kkt)
            }
            _ => Direction::plain(-(binv * g), false),
        },
    }
}
