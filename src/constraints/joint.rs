//! Joint constraint equations, evaluated as second-order jets from the rows each kind's file
//! lists ([`crate::joint::Spec::rows`], Haug 1989, Nikravesh 1988):
//!
//! - spherical: `d = r_j + A_j s_j − r_i − A_i s_i = 0` (3 rows);
//! - dot-1: `a_iᵀ b_j = 0` for body vectors `a_i = A_i a'`, `b_j = A_j b'`;
//! - dot-2: `a_iᵀ d = 0`;
//! - length `dᵀd − L²`, thread `d·z_i − h θ`.
//!
//! These generic jets are the reference the closed forms of [`crate::jet::closed`] are tested
//! against, and evaluate the rows without a closed form (a screw's thread). Joint frames and
//! coordinates come from [`crate::kinematics`].
//!
//! ## References
//! - E. J. Haug, *Computer-Aided Kinematics and Dynamics of Mechanical Systems* (1989), ch. 3.

use crate::jet::{Pair, Scalar, Vec3Jet};
use crate::joint::{Row, V};
use crate::kinematics::{angle, frames, on_branch, vector};
use crate::model::Joint;
use nalgebra::Vector3;

fn component(pair: &Pair, d: &Vec3Jet, k: usize) -> Scalar {
    let mut e = Vector3::zeros();
    e[k] = 1.0;
    let mut g = crate::jet::LVec::zeros();
    for i in 0..crate::jet::NL {
        g[i] = d.j[(k, i)];
    }
    let h = pair.hess.then(|| Box::new(d.contract(&e)));
    Scalar { v: d.v[k], g, h }
}

/// Number of constraint rows of a joint (0 for merged and floating joints).
pub(crate) fn row_count(joint: &Joint) -> usize {
    if joint.merged {
        return 0;
    }
    joint.kind.spec().rows.len()
}

/// Names of the constraint rows of a joint, in row order.
pub(crate) fn row_names(joint: &Joint) -> &'static [&'static str] {
    if joint.merged {
        return &[];
    }
    joint.kind.spec().row_names
}

/// Power of length in the unit of a joint row named `name` (`pos_x` is in m, `length` in m²,
/// dot products of unit vectors are dimensionless).
pub(crate) fn length_power(name: &str) -> i32 {
    if name.starts_with("pos")
        || name.starts_with("slide")
        || name.starts_with("line")
        || name == "plane"
        || name == "thread"
    {
        1
    } else if name == "length" {
        2
    } else {
        0
    }
}

/// Evaluates the constraint rows of a joint into `out` (cleared first); a screw's thread row
/// reads its angle on the branch `reference` (see [`crate::kinematics::Branches`]), so that a
/// screw advances over many turns.
pub(crate) fn rows(joint: &Joint, pair: &Pair, reference: f64, out: &mut Vec<Scalar>) {
    out.clear();
    let layout = joint.kind.spec().rows;
    if joint.merged || layout.is_empty() {
        return;
    }
    let f = frames(joint, pair);
    for row in layout {
        out.push(match *row {
            Row::Component(k) => component(pair, &f.d, k),
            Row::Dot(a, b) => pair.dot(vector(&f, a), vector(&f, b)),
            Row::Length => {
                let length = joint.kind.parameter();
                pair.dot(&f.d, &f.d).minus(length * length)
            }
            Row::Thread => {
                let t = on_branch(angle(pair, &f), reference).scale(-joint.kind.parameter());
                pair.dot(vector(&f, V::Z0), &f.d).add(&t)
            }
        });
    }
}

#[cfg(test)]
mod tests;
