//! The support of a pose as the friction verdict (module `friction`) sees it: every stop and
//! contact with its rows, and every distribution of their forces that balances the pose,
//! `λ(z) = λ₀ + N z`. A sticking contact has three rows (normal force, then the friction
//! force along the ground's tangents `t̂₁, t̂₂`), a stop or a frictionless contact one. A stop's
//! row weighs `1/L` in the least-norm choice when it is an angle (its effort in N m, `L` the
//! characteristic length), and is bounded by its joint's URDF `<limit effort>`.

use super::conic::Holder;
use crate::constraints::unilateral::{Active, Unilateral};
use crate::model::{JointId, Model};
use nalgebra::{DMatrix, DVector};

/// The stops and contacts of a pose with every distribution that balances it.
pub(crate) struct Support {
    /// One balancing distribution `λ₀` (every row of every holder).
    pub(crate) base: DVector<f64>,
    /// Self-equilibrated combinations `N` (columns; may be empty).
    pub(crate) null: DMatrix<f64>,
    /// First row and kind of each stop and contact, in row order.
    pub(crate) holders: Vec<(usize, Holder)>,
    /// The friction coefficient of each sticking contact (by holder; `None` elsewhere or where
    /// none is given).
    pub(crate) mu: Vec<Option<f64>>,
    /// Weight of each row in the least-norm choice (`D`).
    pub(crate) weight: Vec<f64>,
    /// The plane ground of each contact (by holder; `None` for stops and obstacles): contacts
    /// on one plane share its frame (module `friction::shortcut`).
    pub(crate) plane: Vec<Option<usize>>,
}

/// Holders (first row, kind), coefficients, least-norm weights and plane grounds of a
/// support's rows (the fields of [`Support`] but its forces).
pub(crate) struct Rows {
    pub(crate) holders: Vec<(usize, Holder)>,
    pub(crate) mu: Vec<Option<f64>>,
    pub(crate) weight: Vec<f64>,
    pub(crate) plane: Vec<Option<usize>>,
}

impl Rows {
    /// The support of these rows with the distributions `base + null z`.
    pub(crate) fn support(self, base: DVector<f64>, null: DMatrix<f64>) -> Support {
        Support {
            base,
            null,
            holders: self.holders,
            mu: self.mu,
            weight: self.weight,
            plane: self.plane,
        }
    }
}

/// The holders, coefficients and least-norm weights of the stops and contacts `items` (each
/// with its coefficient when it sticks), rows in their order: a sticking contact has three
/// rows, a stop's row weighs `1/L` when it is an angle (its effort in N m).
pub(crate) fn holders_of(model: &Model, items: &[(Active, Option<f64>)]) -> Rows {
    let (mut holders, mut mu, mut weight) = (Vec::new(), Vec::new(), Vec::new());
    let mut plane = Vec::new();
    for (a, m) in items {
        let first = weight.len();
        let (h, w) = match a.row {
            Unilateral::Limit { joint, .. } => (
                Holder::Stop {
                    limit: effort_limit(model, joint),
                },
                if model.joints[joint.0].kind.is_angle(0) {
                    1.0 / model.length_scale
                } else {
                    1.0
                },
            ),
            Unilateral::Contact { .. } if a.anchor.is_some() => {
                (Holder::Stick { c: Some(1.0) }, 1.0)
            }
            Unilateral::Contact { .. } => (Holder::Smooth, 1.0),
        };
        weight.extend(std::iter::repeat_n(w, h.rows()));
        holders.push((first, h));
        plane.push(match a.row {
            Unilateral::Contact { ground, .. } if ground < model.grounds.len() => Some(ground),
            _ => None,
        });
        mu.push(if matches!(h, Holder::Stick { .. }) {
            *m
        } else {
            None
        });
    }
    Rows {
        holders,
        mu,
        weight,
        plane,
    }
}

/// The joint's `effort` limit (URDF `<limit effort>`) as a bound on its stop's multiplier.
pub(crate) fn effort_limit(model: &Model, joint: JointId) -> Option<f64> {
    model.joints[joint.0].effort_limit.filter(|e| *e > 0.0)
}
