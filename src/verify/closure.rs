//! The closure error of each joint at a pose: the largest violation of its position rows
//! \[m\] (a distance joint's squared-length row `|d|² − L²` as `|Φ| / 2L`) and of its
//! orientation rows (sine of the angle error) \[rad\], for loop joints always and for tree
//! joints when above the tolerance (on `‖D Φ‖∞`: the position error over the characteristic
//! length).

use crate::constraints::{joint, BlockKind, Constraints};
use crate::model::Model;
use nalgebra::DVector;

/// Closure error of one joint.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Closure {
    /// Joint name.
    pub joint: String,
    /// Whether it closes a loop.
    pub loop_joint: bool,
    /// Largest violation of its position rows \[m\].
    pub position_error: f64,
    /// Largest violation of its orientation rows (sine of the angle error) \[rad\].
    pub rotation_error: f64,
}

/// Closure errors per joint from the rows `cons` and their values `phi`.
pub(super) fn closures(
    model: &Model,
    cons: &Constraints,
    phi: &DVector<f64>,
    tol: f64,
) -> Vec<Closure> {
    let mut closure = Vec::new();
    for block in &cons.blocks {
        let BlockKind::Joint(id) = block.kind else {
            continue;
        };
        let j = model.joint(id);
        let (mut pos, mut rot) = (0.0f64, 0.0f64);
        for k in 0..joint::row_count(j) {
            let r = phi[block.first + k].abs();
            match (cons.length_power(block.first + k), j.kind) {
                (0, _) => rot = rot.max(r),
                (2, crate::model::JointKind::Distance { length }) => {
                    pos = pos.max(r / (2.0 * length.max(1e-12)));
                }
                _ => pos = pos.max(r),
            }
        }
        // The constraint tolerance bounds `‖D Φ‖∞`: positions over the characteristic length.
        if !j.tree || (pos / model.length_scale).max(rot) > tol {
            closure.push(Closure {
                joint: j.name.clone(),
                loop_joint: !j.tree,
                position_error: pos,
                rotation_error: rot,
            });
        }
    }
    closure
}
