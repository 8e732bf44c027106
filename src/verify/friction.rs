//! The friction verdict of a pose in `verify`: the stop and contact forces that balance it are
//! `λ + K t` (basic forces and the self-equilibrated directions of module `held`); module
//! `solver::friction` picks among them the distribution needing the least friction (then the
//! least norm), exactly as `analyze` does, so that `verify` accepts every answer `analyze`
//! gives and refuses a pose only when no forces inside the friction cones balance it.

use crate::constraints::unilateral::Active;
use crate::model::Model;
use crate::solver::friction;
use crate::solver::FrictionVerdict;
use nalgebra::{DMatrix, DVector};

/// The failure of a pose whose contacts cannot hold it.
pub(super) fn slipping(v: &FrictionVerdict) -> String {
    match v.mu {
        Some(mu) => format!(
            "the contacts cannot hold the pose: no forces inside their friction cones balance it (required_mu = {:.6} > mu = {mu})",
            v.required_mu
        ),
        None => format!(
            "the contacts cannot hold the pose: no forces inside their friction cones balance it (required_mu = {:.6}; the sticking contacts marked slipping need more than their mu)",
            v.required_mu
        ),
    }
}

/// The distribution of module `solver::friction` among `lambda + dirs t` (the sparse path's
/// basic forces of the touching rows and their self-equilibrated combinations), `None` where
/// none keeps every contact pushing.
pub(super) fn choose(
    model: &Model,
    lambda: &DVector<f64>,
    dirs: &DMatrix<f64>,
    items: &[(Active, Option<f64>)],
) -> Option<friction::Distribution> {
    // An orthonormal basis of range(dirs) from the eigenvectors of dirsᵀ dirs (nalgebra's SVD
    // loses accuracy with repeated singular values).
    let basis = if dirs.ncols() == 0 {
        DMatrix::zeros(dirs.nrows(), 0)
    } else {
        let (values, vectors) = crate::solver::eigen::symmetric_eigen(&(dirs.transpose() * dirs));
        let top = values.amax();
        if !top.is_finite() {
            return None;
        }
        let keep: Vec<usize> = (0..values.len())
            .filter(|&i| values[i] > 1e-20 * top && top > 0.0)
            .collect();
        dirs * DMatrix::from_fn(dirs.ncols(), keep.len(), |r, c| {
            vectors[(r, keep[c])] / values[keep[c]].sqrt()
        })
    };
    let support = friction::holders_of(model, items).support(lambda.clone(), basis);
    friction::distribute(&support, friction::force_scale(model))
}
