//! The problem description, built once per solve: the model, its constraint rows and their
//! scaling.
//!
//! Coordinates are scaled by `S` (the characteristic length `L` for positions, 1 for Euler
//! parameters) and constraint rows by `D` (`L^−k` for a row in m^k), so that the dimensionless
//! Jacobian `D Φ_q S` and residual `‖D Φ‖∞` (module `residual`) mean the same in any length
//! unit. The solver and `verify` use this one scaling.

use crate::constraints::Constraints;
use crate::model::Model;

/// The model and its constraint rows with their scaling (read-only during a solve, except
/// that the joint-angle branches follow the iterates).
pub(crate) struct Problem<'a> {
    pub(crate) model: &'a Model,
    pub(crate) cons: Constraints,
    pub(crate) scaling: Scaling,
    /// The line search's path along the spanning tree (module `step::retraction`).
    pub(crate) retraction: crate::solver::step::retraction::Retraction,
}

impl<'a> Problem<'a> {
    pub(crate) fn new(model: &'a Model, cons: Constraints) -> Self {
        let scaling = Scaling::new(model, &cons);
        Problem {
            retraction: crate::solver::step::retraction::Retraction::new(model),
            model,
            cons,
            scaling,
        }
    }
}

/// Column and row scales: `S` and `D` of the module docs.
#[derive(Clone, Debug)]
pub(crate) struct Scaling {
    /// Column scale per coordinate (`L` for positions, 1 for Euler parameters).
    pub(crate) columns: Vec<f64>,
    /// Row scale per constraint row (`L^−k` for a row in m^k).
    pub(crate) rows: Vec<f64>,
}

impl Scaling {
    /// The scaling of `cons` on `model` (length `model.length_scale`).
    pub(crate) fn new(model: &Model, cons: &Constraints) -> Self {
        let l = model.length_scale;
        Scaling {
            columns: coordinate_scale(model),
            rows: (0..cons.len())
                .map(|i| l.powi(-cons.length_power(i)))
                .collect(),
        }
    }
}

/// Column scale per coordinate: the characteristic length for positions, 1 for Euler
/// parameters.
pub(crate) fn coordinate_scale(model: &Model) -> Vec<f64> {
    let l = model.length_scale;
    (0..model.coordinate_count())
        .map(|i| if i % 7 < 3 { l } else { 1.0 })
        .collect()
}
