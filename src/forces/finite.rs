//! Which term of `V = V_gravity + V_springs + V_joint_springs − W_loads − W_efforts` is not
//! finite at a configuration: the cause a non-finite energy or gradient is reported with,
//! instead of letting NaN reach a decomposition or a report.
//!
//! Each term is evaluated alone (the model with every other source removed); only the error
//! path pays for it.

use super::potential;
use crate::error::Error;
use crate::kinematics::Branches;
use crate::model::Model;
use nalgebra::DVector;

/// Whether `V` and `∇V` of `model` alone are finite at `q` (an undefined table counts as
/// finite: it has its own error).
fn finite(model: &Model, branches: &Branches, q: &DVector<f64>) -> bool {
    let mut g = DVector::zeros(q.len());
    potential(model, branches, q, &mut g, None)
        .is_none_or(|e| e.total.is_finite() && g.iter().all(|x| x.is_finite()))
}

/// The first term of `V` that is not finite at `q`, described (`spring `s``, `gravity on body
/// `b``, …), or the first non-finite coordinate.
pub(crate) fn non_finite_term(model: &Model, branches: &Branches, q: &DVector<f64>) -> String {
    if let Some(i) = q.iter().position(|x| !x.is_finite()) {
        return format!("coordinate {} = {}", model.coordinate_name(i), q[i]);
    }
    let mut none = model.clone();
    none.gravity = nalgebra::Vector3::zeros();
    none.springs.clear();
    none.joint_springs.clear();
    none.loads.clear();
    none.efforts.clear();
    let probe = |add: &dyn Fn(&mut Model)| {
        let mut m = none.clone();
        add(&mut m);
        !finite(&m, branches, q)
    };
    for (i, b) in model.bodies.iter().enumerate() {
        let mut m = none.clone();
        m.gravity = model.gravity;
        for (k, other) in m.bodies.iter_mut().enumerate() {
            if k != i {
                other.gravity_mass = 0.0;
            }
        }
        if !finite(&m, branches, q) {
            return format!("gravity on body `{}`", b.name);
        }
    }
    for s in &model.springs {
        if probe(&|m: &mut Model| m.springs.push(s.clone())) {
            return format!("spring `{}`", s.name);
        }
    }
    for js in &model.joint_springs {
        if probe(&|m: &mut Model| m.joint_springs.push(js.clone())) {
            return format!("joint spring on `{}`", model.joint(js.joint).name);
        }
    }
    for l in &model.loads {
        if probe(&|m: &mut Model| m.loads.push(l.clone())) {
            return format!("load `{}`", l.name);
        }
    }
    for e in &model.efforts {
        if probe(&|m: &mut Model| m.efforts.push(e.clone())) {
            return format!("effort on `{}`", model.joint(e.joint).name);
        }
    }
    "the sum of its terms (each is finite alone)".into()
}

/// [`Error::NonFiniteEnergy`] at `at` unless `energy` and `grad` are finite.
pub(crate) fn check(
    model: &Model,
    branches: &Branches,
    q: &DVector<f64>,
    energy: f64,
    grad: &DVector<f64>,
    at: &str,
) -> Result<(), Error> {
    if energy.is_finite() && grad.iter().all(|x| x.is_finite()) {
        return Ok(());
    }
    Err(Error::NonFiniteEnergy {
        at: at.into(),
        term: non_finite_term(model, branches, q),
    })
}
