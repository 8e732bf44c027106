//! The friction verdict of a pose in `verify`: the stop and contact forces that balance it in
//! the least-squares sense are `free + null(M) y` (`M = Nᵀ S G` with normalized columns, module
//! `unilateral`); module `solver::friction` picks among them the distribution needing the
//! least friction (then the least norm), exactly as `analyze` does, so that `verify` accepts
//! every answer `analyze` gives and refuses a pose only when no forces inside the friction
//! cones balance it.

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

/// The distribution of module `solver::friction` among the least-squares balances
/// `free + null(M) y` (`M`'s columns normalized by `norms`), `None` where none keeps every
/// contact pushing.
pub(super) fn distribution(
    model: &Model,
    m: &DMatrix<f64>,
    free: &DVector<f64>,
    norms: &[f64],
    items: &[(Active, Option<f64>)],
) -> Option<friction::Distribution> {
    let k = m.ncols();
    let unscaled = |v: DVector<f64>| {
        let mut v = DVector::from_fn(k, |i, _| if norms[i] > 0.0 { v[i] / norms[i] } else { 0.0 });
        let n = v.norm();
        if n > 0.0 {
            v /= n;
        }
        v
    };
    let mut null = Vec::new();
    if m.nrows() == 0 {
        null.extend(
            (0..k).map(|i| unscaled(DVector::from_fn(k, |r, _| f64::from(u8::from(r == i))))),
        );
    } else {
        // Candidates from the eigenvalues of MᵀM (rounding leaves about 10⁻¹⁶ of the largest
        // on the zero ones), kept where ‖M v‖ is at rounding level.
        let eig = (m.transpose() * m).symmetric_eigen();
        let top = eig.eigenvalues.amax().max(1e-300);
        for (i, &e) in eig.eigenvalues.iter().enumerate() {
            let v = eig.eigenvectors.column(i).into_owned();
            if e <= 1e-10 * top && (m * &v).norm() <= 1e-10 * top.sqrt() {
                null.push(unscaled(v));
            }
        }
    }
    let (holders, mu, weight) = friction::holders_of(model, items);
    let support = friction::Support {
        base: free.clone(),
        null: if null.is_empty() {
            DMatrix::zeros(k, 0)
        } else {
            DMatrix::from_columns(&null)
        },
        holders,
        mu,
        weight,
    };
    friction::distribute(&support, friction::force_scale(model))
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
    let eig = (dirs.transpose() * dirs).symmetric_eigen();
    let top = eig.eigenvalues.amax();
    let keep: Vec<usize> = (0..eig.eigenvalues.len())
        .filter(|&i| eig.eigenvalues[i] > 1e-20 * top && top > 0.0)
        .collect();
    let basis = dirs
        * DMatrix::from_fn(dirs.ncols(), keep.len(), |r, c| {
            eig.eigenvectors[(r, keep[c])] / eig.eigenvalues[keep[c]].sqrt()
        });
    let (holders, mu, weight) = friction::holders_of(model, items);
    let support = friction::Support {
        base: lambda.clone(),
        null: basis,
        holders,
        mu,
        weight,
    };
    friction::distribute(&support, friction::force_scale(model))
}
