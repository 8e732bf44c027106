//! The result JSON (field names are a contract; see the README).

use crate::forces::Energy;
use crate::model::Model;
use crate::solver::{Diagnostics, Iterate, Reaction, Report, Stability};
use crate::state::State;
use serde::Serialize;
use std::collections::BTreeMap;

/// A joint's type and coordinates.
#[derive(Clone, Debug, Serialize)]
pub struct JointResult {
    /// Joint type name.
    #[serde(rename = "type")]
    pub kind: String,
    /// Coordinates \[rad or m\]; quaternion `wxyz` for spherical joints; `[]` for fixed joints.
    pub position: Vec<f64>,
}

/// A link frame in the world.
#[derive(Clone, Debug, Serialize)]
pub struct LinkResult {
    /// Origin of the link frame \[m\].
    pub position: [f64; 3],
    /// Orientation as a unit quaternion `[w, x, y, z]`.
    pub orientation_wxyz: [f64; 4],
}

/// A joint at rest outside its URDF `<limit>` (limits are not enforced; this says so).
#[derive(Clone, Debug, Serialize)]
pub struct LimitViolation {
    /// Joint name.
    pub joint: String,
    /// Its rest position [rad or m].
    pub position: f64,
    /// `[lower, upper]`.
    pub limits: [f64; 2],
}

/// The whole result, as written by `restpose analyze --json`.
#[derive(Clone, Debug, Serialize)]
pub struct AnalysisResult {
    /// Robot name.
    pub robot: String,
    /// Whether the solve converged.
    pub converged: bool,
    /// Why it stopped (`converged`, `max_iterations`, `line_search_failed`, `unbounded`).
    pub termination: String,
    /// Minimizer iterations.
    pub iterations: usize,
    /// Potential energy \[J\].
    pub potential_energy: f64,
    /// Degrees of freedom.
    pub dof: usize,
    /// Iteration history.
    pub history: Vec<Iterate>,
    /// Every joint's coordinates.
    pub joints: BTreeMap<String, JointResult>,
    /// Every link's frame in the world.
    pub links: BTreeMap<String, LinkResult>,
    /// Stability verdict (absent for a structure with no degree of freedom).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stability: Option<Stability>,
    /// Reaction of each joint on its child link at the joint origin.
    pub reactions: BTreeMap<String, Reaction>,
    /// Constraint rows dropped as redundant.
    pub redundant_constraints: Vec<String>,
    /// Independent coordinates of the final partition.
    pub independent_coordinates: Vec<String>,
    /// Energy by source \[J\].
    pub energy: Energy,
    /// Solver counters.
    pub diagnostics: Diagnostics,
    /// Joints resting outside their URDF limits (not enforced).
    pub limit_violations: Vec<LimitViolation>,
    /// Bodies, coordinates, constraint rows.
    pub bodies: usize,
    /// Cartesian coordinates (7 per body).
    pub coordinates: usize,
    /// Constraint rows (before dropping redundant ones).
    pub constraints: usize,
}

impl AnalysisResult {
    /// Builds the result of a solve.
    pub fn new(model: &Model, state: &State, report: &Report) -> Self {
        let joints: BTreeMap<String, JointResult> = state
            .joint_values(model)
            .into_iter()
            .zip(&model.joints)
            .map(|((name, position), j)| {
                (
                    name,
                    JointResult {
                        kind: j.kind.name().to_string(),
                        position,
                    },
                )
            })
            .collect();
        let links = model
            .links
            .iter()
            .map(|l| {
                // The link itself, not a lookup by name (O(N²) over all links).
                let pose = match l.body {
                    Some(b) => state.body_pose(b) * l.body_from_link,
                    None => l.body_from_link,
                };
                let r = pose.rotation;
                let (w, x, y, z) = if r.w < 0.0 {
                    (-r.w, -r.i, -r.j, -r.k)
                } else {
                    (r.w, r.i, r.j, r.k)
                };
                (
                    l.name.clone(),
                    LinkResult {
                        position: pose.translation.vector.into(),
                        orientation_wxyz: [w, x, y, z],
                    },
                )
            })
            .collect();
        let limit_violations = model
            .joints
            .iter()
            .filter(|j| {
                matches!(
                    j.kind,
                    crate::model::JointKind::Revolute | crate::model::JointKind::Prismatic
                )
            })
            .filter_map(|j| {
                let [lo, hi] = j.limits?;
                let p = joints
                    .get(&j.name)
                    .and_then(|r: &JointResult| r.position.first().copied())?;
                (hi > lo && (p < lo - 1e-9 || p > hi + 1e-9)).then(|| LimitViolation {
                    joint: j.name.clone(),
                    position: p,
                    limits: [lo, hi],
                })
            })
            .collect();
        AnalysisResult {
            limit_violations,
            robot: model.name.clone(),
            converged: report.converged(),
            termination: report.termination.as_str().to_string(),
            iterations: report.iterations,
            potential_energy: report.energy.total,
            dof: report.dof,
            history: report.history.clone(),
            joints,
            links,
            stability: report.stability.clone(),
            reactions: report.reactions.iter().cloned().collect(),
            redundant_constraints: report.redundant_constraints.clone(),
            independent_coordinates: report.independent_coordinates.clone(),
            energy: report.energy,
            diagnostics: report.diagnostics.clone(),
            bodies: report.sizes[0],
            coordinates: report.sizes[1],
            constraints: report.sizes[2],
        }
    }

    /// Pretty JSON text.
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).unwrap_or_else(|e| format!("{{\"error\": \"{e}\"}}"))
    }
}
