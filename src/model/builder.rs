//! Building a [`Model`] in code: bodies, the links they carry, joints, force elements;
//! [`ModelBuilder::build`] validates and aggregates.
//!
//! A body's mass properties are the sum of its links' (parallel-axis theorem):
//! `m = Σ mₗ`, `c = Σ mₗ cₗ / m`, `I = Σ (Rₗ Iₗ Rₗᵀ + mₗ (|dₗ|² 𝟙 − dₗ dₗᵀ))` with
//! `dₗ = cₗ − c`, every term in the body frame. Links excluded from gravity
//! (`mech:link_gravity`) count in `m` but not in `gravity_mass`.
//!
//! Ids ([`BodyId`], [`JointId`]) are handed out by the builder; `build` checks every id
//! and coordinate index it was given, so a made-up id is an error, never a panic later.

use super::{
    Body, BodyId, ContactSettings, Effort, ForceLaw, Initial, Joint, JointId, JointKind,
    JointSpring, Link, Load, Lock, Mimic, Model, Spring,
};
use crate::error::{Error, Result, SourceLocation};
use crate::geometry::Geometry;
use nalgebra::{Isometry3, Matrix3, Point3, Vector3};
use std::collections::HashMap;

/// Mass properties of a link in its link frame.
#[derive(Clone, Debug, PartialEq)]
pub struct Inertial {
    /// Mass \[kg\].
    pub mass: f64,
    /// Centre of mass in the link frame \[m\].
    pub com: Vector3<f64>,
    /// Inertia about the centre of mass, link-frame axes \[kg m²\].
    pub inertia: Matrix3<f64>,
}

impl Inertial {
    /// No mass.
    pub fn massless() -> Self {
        Inertial {
            mass: 0.0,
            com: Vector3::zeros(),
            inertia: Matrix3::zeros(),
        }
    }
}

/// Builds a [`Model`]: add bodies (their mass comes from the links added on them), joints,
/// force elements; [`ModelBuilder::build`] validates the ids and sums the mass.
///
/// # Example
/// A pendulum (1 kg at 0.5 m from a hinge about y, torsion spring 10 N m/rad) built and
/// solved in code; its rest angle satisfies `k θ = m g L cos θ`.
/// ```
/// use nalgebra::{Isometry3, Matrix3, Vector3};
/// use restpose::model::{ForceLaw, JointKind, ModelBuilder};
/// let mut b = ModelBuilder::new("pendulum");
/// let arm = b.add_rigid_body("arm", 1.0, Vector3::new(0.5, 0.0, 0.0), Matrix3::identity() * 1e-3);
/// // The hinge frame's z axis is the joint axis: turn z onto y.
/// let hinge_frame = Isometry3::rotation(Vector3::x() * -std::f64::consts::FRAC_PI_2);
/// let hinge = b.add_joint("hinge", JointKind::Revolute, None, hinge_frame, Some(arm), hinge_frame);
/// b.add_joint_spring(hinge, 0, ForceLaw::Linear { stiffness: 10.0, preload: 0.0 }, 0.0);
/// let model = b.build().unwrap();
/// let (state, report) = restpose::solve(&model, &Default::default()).unwrap();
/// let theta = state.joint_values(&model)[0].1[0];
/// assert!(report.converged() && (10.0 * theta - 9.81 * 0.5 * theta.cos()).abs() < 1e-8);
/// ```
#[derive(Clone, Debug)]
pub struct ModelBuilder {
    pub(super) model: Model,
    inertials: Vec<Inertial>,
    no_gravity: Vec<bool>,
    joint_names: HashMap<String, JointId>,
    link_names: HashMap<String, usize>,
    /// `(link index, touches, settings)` from `mech:contact`.
    pub(super) contacts: Vec<(usize, bool, ContactSettings)>,
}

impl ModelBuilder {
    /// An empty model named `name`, gravity `(0, 0, −9.81)` m/s².
    pub fn new(name: impl Into<String>) -> Self {
        ModelBuilder {
            model: Model {
                name: name.into(),
                bodies: Vec::new(),
                links: Vec::new(),
                joints: Vec::new(),
                springs: Vec::new(),
                joint_springs: Vec::new(),
                loads: Vec::new(),
                efforts: Vec::new(),
                locks: Vec::new(),
                mimics: Vec::new(),
                initial: Vec::new(),
                gravity: Vector3::new(0.0, 0.0, -9.81),
                grounds: Vec::new(),
                obstacles: Vec::new(),
                contact_points: Vec::new(),
                length_scale: 1.0,
                base_pose: None,
                joint_names: HashMap::new(),
            },
            inertials: Vec::new(),
            no_gravity: Vec::new(),
            joint_names: HashMap::new(),
            link_names: HashMap::new(),
            contacts: Vec::new(),
        }
    }

    /// Sets gravity in the world frame \[m/s²\].
    pub fn set_gravity(&mut self, gravity: Vector3<f64>) {
        self.model.gravity = gravity;
    }

    /// Adds a moving body whose frame is the frame of the link named `name`; its mass comes
    /// from the links added on it.
    pub fn add_body(&mut self, name: impl Into<String>) -> BodyId {
        self.model.bodies.push(Body {
            name: name.into(),
            mass: 0.0,
            com: Vector3::zeros(),
            inertia: Matrix3::zeros(),
            gravity_mass: 0.0,
            gravity_com: Vector3::zeros(),
        });
        BodyId(self.model.bodies.len() - 1)
    }

    /// Adds a link on `body` (`None`: welded to the world) at `body_from_link`, and returns
    /// its index in [`Model::links`].
    pub fn add_link(
        &mut self,
        name: impl Into<String>,
        body: Option<BodyId>,
        body_from_link: Isometry3<f64>,
        inertial: Inertial,
        visuals: Vec<Geometry>,
        collisions: Vec<Geometry>,
    ) -> usize {
        let name = name.into();
        self.link_names
            .entry(name.clone())
            .or_insert(self.model.links.len());
        self.model.links.push(Link {
            name,
            body,
            body_from_link,
            visuals,
            collisions,
        });
        self.inertials.push(inertial);
        self.no_gravity.push(false);
        self.model.links.len() - 1
    }

    /// A body carrying one link of the same name with these mass properties (centre of mass
    /// `com` \[m\] in the body frame, inertia \[kg m²\] about it).
    pub fn add_rigid_body(
        &mut self,
        name: impl Into<String>,
        mass: f64,
        com: Vector3<f64>,
        inertia: Matrix3<f64>,
    ) -> BodyId {
        let name = name.into();
        let body = self.add_body(name.clone());
        let inertial = Inertial { mass, com, inertia };
        self.add_link(
            name,
            Some(body),
            Isometry3::identity(),
            inertial,
            Vec::new(),
            Vec::new(),
        );
        body
    }

    /// Excludes link `link` (an index from [`Self::add_link`]) from gravity.
    pub fn exclude_from_gravity(&mut self, link: usize) {
        if let Some(g) = self.no_gravity.get_mut(link) {
            *g = true;
        }
    }

    /// Adds a spanning-tree joint between bodies (`None` = world) with its joint frame `J`
    /// given in each body frame (`J`'s z axis is the joint axis, see [`JointKind`]).
    pub fn add_joint(
        &mut self,
        name: impl Into<String>,
        kind: JointKind,
        parent: Option<BodyId>,
        parent_from_joint: Isometry3<f64>,
        child: Option<BodyId>,
        child_from_joint: Isometry3<f64>,
    ) -> JointId {
        let link = |b: Option<BodyId>, m: &Model| {
            b.and_then(|b| m.bodies.get(b.0))
                .map_or_else(|| "world".to_string(), |b| b.name.clone())
        };
        let joint = Joint {
            name: name.into(),
            kind,
            parent_link: link(parent, &self.model),
            child_link: link(child, &self.model),
            bodies: [parent, child],
            body_from_joint: [parent_from_joint, child_from_joint],
            tree: true,
            merged: false,
            limits: None,
            source: None,
        };
        self.push_joint(joint)
    }

    /// Adds a joint given in full (loop closures: `tree: false`; welded fixed joints:
    /// `merged: true`).
    pub fn push_joint(&mut self, joint: Joint) -> JointId {
        let id = JointId(self.model.joints.len());
        self.joint_names.entry(joint.name.clone()).or_insert(id);
        self.model.joints.push(joint);
        id
    }

    /// Adds a point-to-point spring.
    pub fn add_spring(&mut self, spring: Spring) {
        self.model.springs.push(spring);
    }

    /// Adds a spring on coordinate `dof` of `joint`, `reference` \[rad or m\] at zero force.
    pub fn add_joint_spring(&mut self, joint: JointId, dof: usize, law: ForceLaw, reference: f64) {
        self.model.joint_springs.push(JointSpring {
            joint,
            dof,
            reference,
            law,
        });
    }

    /// Adds a joint spring given in full.
    pub fn push_joint_spring(&mut self, spring: JointSpring) {
        self.model.joint_springs.push(spring);
    }

    /// Adds a dead load.
    pub fn add_load(&mut self, load: Load) {
        self.model.loads.push(load);
    }

    /// Adds a constant generalized force on a joint coordinate.
    pub fn add_effort(&mut self, effort: Effort) {
        self.model.efforts.push(effort);
    }

    /// Holds a joint coordinate.
    pub fn add_lock(&mut self, lock: Lock) {
        self.model.locks.push(lock);
    }

    /// Adds a linear coupling between joint coordinates.
    pub fn add_mimic(&mut self, mimic: Mimic) {
        self.model.mimics.push(mimic);
    }

    /// Sets the initial guess of a joint coordinate (the last one given counts).
    pub fn add_initial(&mut self, initial: Initial) {
        self.model.initial.push(initial);
    }

    /// The joint named `name`, if added.
    pub fn joint_id(&self, name: &str) -> Option<JointId> {
        self.joint_names.get(name).copied()
    }

    /// A joint added earlier.
    pub fn joint(&self, id: JointId) -> Option<&Joint> {
        self.model.joints.get(id.0)
    }

    /// The link with index `i` (from [`Self::add_link`]).
    pub fn link(&self, i: usize) -> Option<&Link> {
        self.model.links.get(i)
    }

    /// The mimics added so far.
    pub fn mimics(&self) -> &[Mimic] {
        &self.model.mimics
    }

    /// The model as built so far, without validation or mass aggregation (for computing an
    /// initial pose during import).
    pub fn partial(&self) -> &Model {
        &self.model
    }

    /// Records where joint `joint` is declared in the input file (named in later errors).
    pub fn set_joint_source(&mut self, joint: JointId, source: SourceLocation) {
        if let Some(j) = self.model.joints.get_mut(joint.0) {
            j.source = Some(source);
        }
    }

    /// Replaces the child-side joint frame of `joint` (a loop joint closed at the initial
    /// guess).
    pub fn set_child_frame(&mut self, joint: JointId, child_from_joint: Isometry3<f64>) {
        if let Some(j) = self.model.joints.get_mut(joint.0) {
            j.body_from_joint[1] = child_from_joint;
        }
    }

    /// Validates the ids and coordinate indices, sums the links' mass into their bodies and
    /// sets the characteristic length.
    ///
    /// # Errors
    /// [`Error::Model`] naming the element with an id or coordinate out of range or a
    /// non-finite mass property.
    pub fn build(mut self) -> Result<Model> {
        self.validate()?;
        aggregate_mass(&mut self.model, &self.inertials, &self.no_gravity);
        self.model.contact_points = super::contact::points(&self.model, &self.contacts)?;
        self.model.length_scale = length_scale(&self.model);
        self.model.index_names();
        Ok(self.model)
    }

    fn validate(&self) -> Result<()> {
        let m = &self.model;
        let nb = m.bodies.len();
        let body_ok = |b: &Option<BodyId>| b.is_none_or(|b| b.0 < nb);
        let bad = |what: String| Err(Error::Model(what));
        for l in &m.links {
            if !body_ok(&l.body) {
                return bad(format!(
                    "link `{}` is on a body that does not exist",
                    l.name
                ));
            }
        }
        for (l, i) in m.links.iter().zip(&self.inertials) {
            let finite = i.mass.is_finite()
                && i.com.iter().all(|x| x.is_finite())
                && i.inertia.iter().all(|x| x.is_finite());
            if !finite || i.mass < 0.0 {
                return bad(format!(
                    "link `{}` has a negative or non-finite mass property",
                    l.name
                ));
            }
        }
        for j in &m.joints {
            if !j.bodies.iter().all(body_ok) {
                return bad(format!(
                    "joint `{}` joins a body that does not exist",
                    j.name
                ));
            }
            if !j.merged && j.bodies[0] == j.bodies[1] {
                return bad(format!("joint `{}` joins a body to itself", j.name));
            }
        }
        let coordinate = |joint: JointId, dof: usize, what: &str| -> Result<()> {
            match m.joints.get(joint.0) {
                None => bad(format!("{what} refers to a joint that does not exist")),
                Some(j) if dof >= j.kind.scalar_coordinates() => bad(format!(
                    "{what} on joint `{}` ({}): coordinate {dof} is out of range",
                    j.name,
                    j.kind.name()
                )),
                Some(_) => Ok(()),
            }
        };
        for s in &m.joint_springs {
            coordinate(s.joint, s.dof, "a joint spring")?;
        }
        for e in &m.efforts {
            coordinate(e.joint, e.dof, "an effort")?;
        }
        for l in &m.locks {
            coordinate(l.joint, l.dof, "a lock")?;
        }
        for i in &m.initial {
            if m.joints.get(i.joint.0).is_none() {
                return bad("an initial value refers to a joint that does not exist".into());
            }
        }
        for x in &m.mimics {
            coordinate(x.joint, 0, "a mimic")?;
            coordinate(x.reference, 0, "a mimic")?;
        }
        for s in &m.springs {
            if !s.ends.iter().all(|e| body_ok(&e.body)) {
                return bad(format!(
                    "spring `{}` ends on a body that does not exist",
                    s.name
                ));
            }
        }
        for l in &m.loads {
            if l.body.0 >= nb {
                return bad(format!(
                    "load `{}` is on a body that does not exist",
                    l.name
                ));
            }
        }
        if !m.gravity.iter().all(|g| g.is_finite()) {
            return bad("gravity is not finite".into());
        }
        Ok(())
    }
}

/// Sums link masses into their bodies (parallel-axis theorem for the inertia).
fn aggregate_mass(model: &mut Model, inertials: &[Inertial], no_gravity: &[bool]) {
    let n = model.bodies.len();
    let mut m = vec![0.0; n];
    let mut mc = vec![Vector3::zeros(); n];
    let mut gm = vec![0.0; n];
    let mut gmc = vec![Vector3::zeros(); n];
    for (i, l) in inertials.iter().enumerate() {
        let link = &model.links[i];
        let Some(body) = link.body else { continue };
        let c = link.body_from_link * Point3::from(l.com);
        m[body.0] += l.mass;
        mc[body.0] += l.mass * c.coords;
        if !no_gravity[i] {
            gm[body.0] += l.mass;
            gmc[body.0] += l.mass * c.coords;
        }
    }
    for k in 0..n {
        let body = &mut model.bodies[k];
        body.mass = m[k];
        body.com = if m[k] > 0.0 {
            mc[k] / m[k]
        } else {
            Vector3::zeros()
        };
        body.gravity_mass = gm[k];
        body.gravity_com = if gm[k] > 0.0 {
            gmc[k] / gm[k]
        } else {
            Vector3::zeros()
        };
        body.inertia = Matrix3::zeros();
    }
    for (i, l) in inertials.iter().enumerate() {
        let link = &model.links[i];
        let Some(body) = link.body else { continue };
        let r = link.body_from_link.rotation.to_rotation_matrix();
        let c = (link.body_from_link * Point3::from(l.com)).coords - model.bodies[body.0].com;
        let parallel = l.mass * (Matrix3::identity() * c.dot(&c) - c * c.transpose());
        model.bodies[body.0].inertia += r.matrix() * l.inertia * r.matrix().transpose() + parallel;
    }
}

/// Characteristic length: the largest offset of a joint frame, spring end or centre of mass
/// from its body origin (1 m if all are zero).
fn length_scale(model: &Model) -> f64 {
    let mut l: f64 = 0.0;
    for j in &model.joints {
        for f in &j.body_from_joint {
            l = l.max(f.translation.vector.norm());
        }
    }
    for b in &model.bodies {
        l = l.max(b.com.norm());
    }
    for s in &model.springs {
        for e in &s.ends {
            if e.body.is_some() {
                l = l.max(e.point.norm());
            }
        }
        l = l.max(s.free_length.abs());
    }
    if l > 0.0 {
        l
    } else {
        1.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two links on one body: the parallel-axis sum by hand.
    #[test]
    fn links_aggregate_into_their_body() {
        let mut b = ModelBuilder::new("m");
        let body = b.add_body("a");
        let point = |mass: f64, x: f64| Inertial {
            mass,
            com: Vector3::new(x, 0.0, 0.0),
            inertia: Matrix3::zeros(),
        };
        b.add_link(
            "a",
            Some(body),
            Isometry3::identity(),
            point(1.0, 0.0),
            vec![],
            vec![],
        );
        let l = b.add_link(
            "b",
            Some(body),
            Isometry3::translation(0.0, 0.0, 0.0),
            point(3.0, 2.0),
            vec![],
            vec![],
        );
        b.exclude_from_gravity(l);
        b.add_joint(
            "j",
            JointKind::Revolute,
            None,
            Isometry3::identity(),
            Some(body),
            Isometry3::identity(),
        );
        let m = b.build().unwrap();
        let body = &m.bodies[0];
        assert_eq!(body.mass, 4.0);
        assert!((body.com.x - 1.5).abs() < 1e-15);
        // Σ m d²: 1 · 1.5² + 3 · 0.5² = 3 about y and z, 0 about x.
        assert!((body.inertia[(1, 1)] - 3.0).abs() < 1e-12);
        assert!((body.inertia[(2, 2)] - 3.0).abs() < 1e-12);
        assert_eq!(body.inertia[(0, 0)], 0.0);
        assert_eq!((body.gravity_mass, body.gravity_com.x), (1.0, 0.0));
        assert_eq!(m.length_scale, 1.5);
    }

    /// Ids from another builder, or coordinates a joint does not have, are errors.
    #[test]
    fn build_refuses_ids_out_of_range() {
        let mut other = ModelBuilder::new("other");
        other.add_body("x");
        let stranger = other.add_body("y");
        let mut b = ModelBuilder::new("m");
        let a = b.add_rigid_body("a", 1.0, Vector3::zeros(), Matrix3::identity());
        let j = b.add_joint(
            "j",
            JointKind::Revolute,
            None,
            Isometry3::identity(),
            Some(a),
            Isometry3::identity(),
        );
        let mut bad = b.clone();
        bad.add_joint(
            "k",
            JointKind::Revolute,
            Some(a),
            Isometry3::identity(),
            Some(stranger),
            Isometry3::identity(),
        );
        let e = bad.build().unwrap_err().to_string();
        assert!(
            e.contains("joint `k` joins a body that does not exist"),
            "{e}"
        );
        let mut bad = b.clone();
        bad.add_joint_spring(
            j,
            1,
            ForceLaw::Linear {
                stiffness: 1.0,
                preload: 0.0,
            },
            0.0,
        );
        let e = bad.build().unwrap_err().to_string();
        assert!(e.contains("coordinate 1 is out of range"), "{e}");
        assert!(b.build().is_ok());
    }
}
