//! The normalized model as `restpose check` prints it: what the importer understood.

use crate::model::ForceLaw;
use serde::Serialize;

/// One body.
#[derive(Clone, Debug, Serialize)]
pub struct BodySummary {
    /// Body name (its topmost link).
    pub name: String,
    /// Mass \[kg\].
    pub mass: f64,
    /// Links it carries.
    pub links: Vec<String>,
}

/// One joint.
#[derive(Clone, Debug, Serialize)]
pub struct JointSummary {
    /// Joint name.
    pub name: String,
    /// Type.
    #[serde(rename = "type")]
    pub kind: String,
    /// Parent link (or frame).
    pub parent: String,
    /// Child link (or frame).
    pub child: String,
    /// `tree`, `loop` (closes a loop) or `merged` (a fixed joint inside a body).
    pub role: String,
    /// Constraint rows it adds.
    pub rows: usize,
}

/// The model as understood.
#[derive(Clone, Debug, Serialize)]
pub struct ModelSummary {
    /// Robot name.
    pub robot: String,
    /// Moving bodies.
    pub bodies: Vec<BodySummary>,
    /// Links welded to the world.
    pub fixed_links: Vec<String>,
    /// Joints.
    pub joints: Vec<JointSummary>,
    /// Springs as `name: link-link (law)`.
    pub springs: Vec<String>,
    /// Joint springs, loads, efforts, locks, mimics, as one line each.
    pub forces: Vec<String>,
    /// Gravity \[m/s²\].
    pub gravity: [f64; 3],
    /// Coordinates (7 per body).
    pub coordinates: usize,
    /// Constraint rows (normalization, locks and mimics included).
    pub constraints: usize,
    /// Degrees of freedom at the assembled initial guess (`None` if it does not assemble).
    pub dof: Option<usize>,
    /// Why the initial guess does not assemble, if it does not.
    pub assembly_error: Option<String>,
    /// Importer warnings.
    pub warnings: Vec<String>,
    /// Ignored foreign elements.
    pub ignored: Vec<String>,
}

fn law(l: &ForceLaw) -> String {
    match l {
        ForceLaw::Linear { stiffness, preload } if *preload == 0.0 => format!("k = {stiffness}"),
        ForceLaw::Linear { stiffness, preload } => format!("k = {stiffness}, preload {preload}"),
        ForceLaw::Table { points, .. } => format!("table of {} points", points.len()),
    }
}

impl ModelSummary {
    /// Summarizes a loaded model and its check ([`crate::verify::check`]).
    pub fn new(loaded: &crate::urdf::Loaded, check: &crate::verify::ModelCheck) -> Self {
        Self::of_model(loaded).with_check(check)
    }

    /// The summary with the check's rows, degrees of freedom and assembly error.
    pub fn with_check(mut self, check: &crate::verify::ModelCheck) -> Self {
        self.constraints = check.constraint_rows;
        self.dof = check.dof;
        self.assembly_error.clone_from(&check.assembly_error);
        self
    }

    /// Summarizes a loaded model before its check (no constraint rows, degrees of freedom or
    /// assembly error yet: [`Self::with_check`] adds them), so that the two can be made at
    /// the same time.
    pub fn of_model(loaded: &crate::urdf::Loaded) -> Self {
        let m = &loaded.model;
        // Links by body in one pass (a scan of all links per body was O(N²)).
        let mut links_of: Vec<Vec<String>> = vec![Vec::new(); m.bodies.len()];
        for l in &m.links {
            if let Some(list) = l.body.and_then(|b| links_of.get_mut(b.0)) {
                list.push(l.name.clone());
            }
        }
        let bodies = m
            .bodies
            .iter()
            .zip(links_of)
            .map(|(b, links)| BodySummary {
                name: b.name.clone(),
                mass: b.mass,
                links,
            })
            .collect();
        let joints = m
            .joints
            .iter()
            .map(|j| JointSummary {
                name: j.name.clone(),
                kind: j.kind.name().to_string(),
                parent: j.parent_link.clone(),
                child: j.child_link.clone(),
                role: (if j.merged {
                    "merged"
                } else if j.tree {
                    "tree"
                } else {
                    "loop"
                })
                .to_string(),
                rows: crate::constraints::joint::row_count(j),
            })
            .collect();
        let body_name = |b: Option<crate::model::BodyId>| {
            b.map_or("world".to_string(), |b| m.bodies[b.0].name.clone())
        };
        let springs = m
            .springs
            .iter()
            .map(|s| {
                format!(
                    "{}: {} – {}, free length {} m, {}",
                    s.name,
                    body_name(s.ends[0].body),
                    body_name(s.ends[1].body),
                    s.free_length,
                    law(&s.law)
                )
            })
            .collect();
        let jn = |id: crate::model::JointId| m.joints[id.0].name.clone();
        let mut forces: Vec<String> = Vec::new();
        forces.extend(m.joint_springs.iter().map(|s| {
            format!(
                "joint spring on {}[{}]: {}, reference {}",
                jn(s.joint),
                s.dof,
                law(&s.law),
                s.reference
            )
        }));
        forces.extend(m.loads.iter().map(|l| {
            format!(
                "load {} on {}: {:?} N",
                l.name,
                m.bodies[l.body.0].name,
                l.force.as_slice()
            )
        }));
        forces.extend(
            m.efforts
                .iter()
                .map(|e| format!("effort on {}[{}]: {}", jn(e.joint), e.dof, e.value)),
        );
        forces.extend(m.locks.iter().map(|l| {
            format!(
                "lock {}[{}] at {}",
                jn(l.joint),
                l.dof,
                l.value
                    .map_or("the initial value".to_string(), |v| v.to_string())
            )
        }));
        forces.extend(m.mimics.iter().map(|x| {
            format!(
                "mimic {} = {} × {} + {}",
                jn(x.joint),
                x.multiplier,
                jn(x.reference),
                x.offset
            )
        }));
        ModelSummary {
            robot: m.name.clone(),
            bodies,
            fixed_links: m
                .links
                .iter()
                .filter(|l| l.body.is_none())
                .map(|l| l.name.clone())
                .collect(),
            joints,
            springs,
            forces,
            gravity: m.gravity.into(),
            coordinates: m.coordinate_count(),
            constraints: 0,
            dof: None,
            assembly_error: None,
            warnings: loaded.warnings.clone(),
            ignored: loaded.ignored.clone(),
        }
    }
}
