//! Closing the loops: damped Newton on `Φ(q) = 0` from the forward-kinematics guess.
//!
//! Each iteration partitions `Φ_q` afresh and solves `Φ_u δu = −Φ` (the minimal change of the
//! dependent coordinates), halving the step until `‖Φ‖∞` decreases. Joints with an initial
//! value are held by temporary lock rows, so that the loop closes around them (choosing the
//! assembly branch); if that fails, the assembly is retried without them.

use super::options::Options;
use super::system::System;
use crate::constraints::Constraints;
use crate::error::{Error, Result};
use crate::model::{JointId, Model};
use nalgebra::DVector;

fn newton(
    sys: &mut System,
    mut q: DVector<f64>,
    tol: f64,
) -> std::result::Result<DVector<f64>, (f64, usize, usize)> {
    const MAX: usize = 100;
    for it in 0..MAX {
        let j = sys.jacobian(&q);
        let phi = sys.residual(&q).clone();
        let res = phi.amax();
        if res <= tol {
            return Ok(q);
        }
        let part = super::partition::partition(&j, &sys.scale);
        let r = part.rows.len();
        let phi_u = nalgebra::DMatrix::from_fn(r, r, |a, b| j[(part.rows[a], part.dependent[b])]);
        let rhs = DVector::from_fn(r, |a, _| -phi[part.rows[a]]);
        let Some(du) = phi_u.lu().solve(&rhs) else {
            return Err((res, phi.iamax(), it));
        };
        let mut alpha = 1.0;
        loop {
            let mut qt = q.clone();
            for (k, &c) in part.dependent.iter().enumerate() {
                qt[c] += alpha * du[k];
            }
            let rt = sys.residual(&qt).amax();
            if rt < res || alpha < 1e-4 {
                q = qt;
                break;
            }
            alpha *= 0.5;
        }
        if alpha < 1e-4 && sys.residual(&q).amax() >= res {
            return Err((res, phi.iamax(), it));
        }
    }
    let phi = sys.residual(&q).clone();
    Err((phi.amax(), phi.iamax(), MAX))
}

/// Assembles `q` (closes loops, applies locks and normalizes) or explains why it cannot.
pub(crate) fn assemble(
    model: &Model,
    q: DVector<f64>,
    locks: &[(JointId, usize, f64)],
    options: &Options,
) -> Result<DVector<f64>> {
    let tol = options.constraint_tolerance;
    let mut held: Vec<(JointId, usize, f64)> = locks.to_vec();
    for i in &model.initial {
        if !held.iter().any(|l| l.0 == i.joint && l.1 == i.dof) {
            held.push((i.joint, i.dof, i.value));
        }
    }
    if held.len() > locks.len() {
        let mut sys = System::new(model, Constraints::new(model, &held));
        if let Ok(qa) = newton(&mut sys, q.clone(), tol) {
            let mut fin = System::new(model, Constraints::new(model, locks));
            if fin.residual(&qa).amax() <= tol.max(1e-8) {
                return Ok(qa);
            }
        }
    }
    project(model, q, locks, options)
}

/// Damped Newton onto `Φ = 0` with the given locks only.
pub(crate) fn project(
    model: &Model,
    q: DVector<f64>,
    locks: &[(JointId, usize, f64)],
    options: &Options,
) -> Result<DVector<f64>> {
    let tol = options.constraint_tolerance;
    let mut sys = System::new(model, Constraints::new(model, locks));
    match newton(&mut sys, q, tol) {
        Ok(qa) => Ok(qa),
        Err((residual, row, iterations)) => {
            let part_rows = sys.cons.row_name(row).to_string();
            // A violated row that is redundant with a satisfied set means inconsistency.
            Err(Error::Assembly {
                residual,
                row: part_rows,
                iterations,
            })
        }
    }
}
