//! The result JSON (field names are a contract, documented in docs/json.md).

use super::configuration::{configuration_of, values as values_only, Convention};
use crate::forces::Energy;
use crate::model::{JointKind, Model};
use crate::solver::balance::Balance;
use crate::solver::{
    ActiveLimit, Contact, ContactState, Diagnostics, FrictionVerdict, Iterate, Reaction, Report,
    Stability,
};
use crate::state::State;
use serde::ser::SerializeMap;
use serde::{Serialize, Serializer};

/// A joint's type and coordinates.
#[derive(Clone, Debug, Serialize)]
pub struct JointResult {
    /// Joint type name.
    #[serde(rename = "type")]
    pub kind: String,
    /// Coordinates \[rad or m\]; quaternion `wxyz` for spherical joints; `[]` for fixed joints.
    pub position: Vec<f64>,
    /// Unit of each entry of `position`: `"rad"`, `"m"`, or `"1"` (a quaternion component).
    pub units: Vec<&'static str>,
}

/// Unit of each coordinate of a joint of this kind, in the order of
/// [`State::joint_values`]: `"rad"`, `"m"`, or `"1"` for a quaternion component.
pub fn coordinate_units(kind: JointKind) -> Vec<&'static str> {
    kind.spec().units.to_vec()
}

/// Serializes `(name, value)` pairs as a JSON object with the keys in the given order.
fn ordered_map<T: Serialize, S: Serializer>(
    pairs: &[(String, T)],
    s: S,
) -> std::result::Result<S::Ok, S::Error> {
    let mut map = s.serialize_map(Some(pairs.len()))?;
    for (k, v) in pairs {
        map.serialize_entry(k, v)?;
    }
    map.end()
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

/// A position servo (`--servo`) at the rest pose: the actuator torque (or force) that holds
/// its joint, `τ = −k (θ − θ_ref)`.
#[derive(Clone, Debug, Serialize)]
pub struct ServoResult {
    /// Joint name.
    pub joint: String,
    /// Stiffness `k` \[N m/rad or N/m\].
    pub stiffness: f64,
    /// Reference `θ_ref` \[rad or m\].
    pub reference: f64,
    /// Rest position `θ` \[rad or m\].
    pub position: f64,
    /// Actuator torque \[N m\] (force \[N\] on a prismatic joint).
    pub torque: f64,
}

/// The servos of `model` at `state`.
pub fn servo_results(model: &Model, state: &State) -> Vec<ServoResult> {
    model
        .servos
        .iter()
        .filter_map(|s| {
            let j = &model.joints[s.joint.index()];
            let position = *state.joint(model, &j.name)?.first()?;
            Some(ServoResult {
                joint: j.name.clone(),
                stiffness: s.stiffness,
                reference: s.reference,
                position,
                torque: s.torque(position),
            })
        })
        .collect()
}

/// The whole result, as written by `restpose analyze --json`.
#[derive(Clone, Debug, Serialize)]
pub struct AnalysisResult {
    /// Robot name.
    pub robot: String,
    /// Whether the solve converged.
    pub converged: bool,
    /// Why it stopped (`converged`, `max_iterations`, `line_search_failed`, `unbounded`,
    /// `active_set_cycling`, `rejected_by_verify`).
    pub termination: String,
    /// Minimizer iterations.
    pub iterations: usize,
    /// Potential energy \[J\].
    pub potential_energy: f64,
    /// Degrees of freedom.
    pub dof: usize,
    /// Iteration history.
    pub history: Vec<Iterate>,
    /// Every joint's coordinates, in model order (URDF `<joint>` elements in file order, then
    /// loop joints declared by extensions).
    #[serde(serialize_with = "ordered_map")]
    pub joints: Vec<(String, JointResult)>,
    /// Every link's frame in the world, in model order.
    #[serde(serialize_with = "ordered_map")]
    pub links: Vec<(String, LinkResult)>,
    /// The pose as MuJoCo's `qpos` for this URDF (see [`super::configuration`]): depth first,
    /// children in `<joint>` element order, floating base `x y z w x y z` first; when the
    /// model has a joint MuJoCo does not read from a URDF, absent.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub q_mujoco: Option<Vec<f64>>,
    /// The pose as Pinocchio's `q` for this URDF: depth first, children sorted by joint name,
    /// free flyer `x y z qx qy qz qw` first, a continuous joint as `cos θ, sin θ`; when the
    /// model has a joint Pinocchio does not read from a URDF, absent.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub q_pinocchio: Option<Vec<f64>>,
    /// Stability verdict (absent for a structure with no degree of freedom).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stability: Option<Stability>,
    /// Reaction of each joint on its child link at the joint origin, in model order.
    #[serde(serialize_with = "ordered_map")]
    pub reactions: Vec<(String, Reaction)>,
    /// Constraint rows dropped as redundant.
    pub redundant_constraints: Vec<String>,
    /// Independent coordinates of the final partition.
    pub independent_coordinates: Vec<String>,
    /// Energy by source \[J\].
    pub energy: Energy,
    /// Solver counters.
    pub diagnostics: Diagnostics,
    /// Joints resting outside their URDF limits (with `--limits ignore`; empty when limits
    /// are enforced and the solve converged).
    pub limit_violations: Vec<LimitViolation>,
    /// Contact points resting on a ground: `{link, ground, point_world, normal_world, gap,
    /// normal_force, tangential_force, required_friction, state}`.
    pub contacts: Vec<Contact>,
    /// Joints resting on a stop: `{joint, bound, value, effort}`.
    pub active_limits: Vec<ActiveLimit>,
    /// Whether no contact forces inside the friction cones (with the coefficients `mu`)
    /// balance the pose: the mechanism would slide from it.
    pub slipping: bool,
    /// The friction verdict with sticking contacts: `{required_mu, mu, margin, slipping}`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub friction: Option<FrictionVerdict>,
    /// A free mechanism on its contacts: `{centre_of_mass, com_projection, support_polygon,
    /// stability_margin}`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub balance: Option<Balance>,
    /// Bodies, coordinates, constraint rows.
    pub bodies: usize,
    /// Cartesian coordinates (7 per body).
    pub coordinates: usize,
    /// Constraint rows (before dropping redundant ones).
    pub constraints: usize,
    /// Position servos with their holding torques (absent without `--servo`).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub servos: Vec<ServoResult>,
    /// Bodies without contact points whose centre of mass lies inside a ground, deepest
    /// first: `{body, ground, depth}` (absent when there are none; module
    /// [`super::buried`]).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub buried_bodies: Vec<super::buried::BuriedBody>,
    /// The floating groups that could not stand on their ground start and toppled before the
    /// solve: `{body, steps, angle, support_before, support_after, com_outside,
    /// energy_released, stopped}` (absent when none did; `restpose::solver::Toppled`).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub topple: Vec<crate::solver::Toppled>,
}

impl AnalysisResult {
    /// Builds the result of a solve.
    pub fn new(model: &Model, state: &State, report: &Report) -> Self {
        let values = state.joint_values(model);
        let q = |c| {
            configuration_of(model, state, &values, c)
                .ok()
                .map(|q| values_only(&q))
        };
        let (q_mujoco, q_pinocchio) = (q(Convention::Mujoco), q(Convention::Pinocchio));
        let joints: Vec<(String, JointResult)> = values
            .into_iter()
            .zip(&model.joints)
            .map(|((name, position), j)| {
                (
                    name,
                    JointResult {
                        kind: j.kind.name().to_string(),
                        position,
                        units: coordinate_units(j.kind),
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
            .zip(&joints)
            .filter(|(j, _)| matches!(j.kind, JointKind::Revolute | JointKind::Prismatic))
            .filter_map(|(j, (_, r))| {
                let [lo, hi] = j.limits?;
                let p = r.position.first().copied()?;
                (hi > lo && (p < lo - 1e-9 || p > hi + 1e-9)).then(|| LimitViolation {
                    joint: j.name.clone(),
                    position: p,
                    limits: [lo, hi],
                })
            })
            .collect();
        AnalysisResult {
            limit_violations,
            contacts: report.contacts.clone(),
            active_limits: report.active_limits.clone(),
            slipping: report.friction.as_ref().is_some_and(|f| f.slipping)
                || report
                    .contacts
                    .iter()
                    .any(|c| c.state == ContactState::Slipping),
            friction: report.friction.clone(),
            balance: report.balance.clone(),
            robot: model.name.clone(),
            converged: report.converged(),
            termination: report.termination.as_str().to_string(),
            iterations: report.iterations,
            potential_energy: report.energy.total,
            dof: report.dof,
            history: report.history.clone(),
            joints,
            links,
            q_mujoco,
            q_pinocchio,
            stability: report.stability.clone(),
            reactions: report.reactions.clone(),
            redundant_constraints: report.redundant_constraints.clone(),
            independent_coordinates: report.independent_coordinates.clone(),
            energy: report.energy,
            diagnostics: report.diagnostics.clone(),
            bodies: report.sizes.bodies,
            coordinates: report.sizes.coordinates,
            constraints: report.sizes.constraint_rows,
            servos: servo_results(model, state),
            buried_bodies: super::buried::buried_bodies(model, state),
            topple: report.toppled.clone(),
        }
    }

    /// Pretty JSON text.
    pub fn to_json(&self) -> String {
        String::from_utf8(self.to_json_bytes())
            .unwrap_or_else(|e| String::from_utf8_lossy(e.as_bytes()).into_owned())
    }

    /// Pretty JSON text as bytes (UTF-8), as [`AnalysisResult::to_json`] without its copy.
    pub fn to_json_bytes(&self) -> Vec<u8> {
        super::pretty_json(self).unwrap_or_else(|e| format!("{{\"error\": \"{e}\"}}").into_bytes())
    }

    /// The bytes of [`AnalysisResult::to_json_bytes`] written to `out` as they are formed.
    ///
    /// # Errors
    /// The writer's error, or the serializer's as an I/O error.
    pub fn write_json(&self, out: &mut dyn std::io::Write) -> std::io::Result<()> {
        super::pretty_json_to(out, self).map_err(Into::into)
    }
}
