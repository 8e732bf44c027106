//! Building a [`Model`] in code: bodies and the links they carry (here), joints
//! ([`super::connect`]), force elements and coordinate inputs ([`super::force`]), grounds
//! ([`super::contact`]); [`ModelBuilder::build`] validates ([`super::validate`]) and sums the
//! links' mass into their bodies ([`super::mass`]).
//!
//! The characteristic length that scales position coordinates is
//! `L = max(‖t_J‖, ‖c_b‖, ‖s_e‖, |L₀|)` over joint-frame offsets, centres of mass, spring end
//! points on bodies and spring free lengths (1 m if all are zero).
//!
//! Ids ([`BodyId`], [`JointId`]) are handed out by the builder; `build` checks every id
//! and coordinate index it was given, so a made-up id is an error, never a panic later.

use super::mass::{aggregate_mass, Inertial};
use super::{Body, BodyId, ContactSettings, Joint, JointId, Link, Mimic, Model, Shared};
use crate::error::Result;
use crate::geometry::Geometry;
use crate::names::NameMap;
use nalgebra::{Isometry3, Matrix3, Vector3};

/// Builds a [`Model`]: add bodies (their mass comes from the links added on them), joints,
/// force elements; [`ModelBuilder::build`] validates the ids and numbers and sums the mass.
///
/// # Example
/// A pendulum (1 kg at 0.5 m from a hinge about y, torsion spring 10 N m/rad) built and
/// solved in code; its rest angle satisfies `k θ = m g L cos θ`.
/// ```
/// use nalgebra::{Isometry3, Matrix3, Vector3};
/// use restpose::model::{axis_frame, ForceLaw, JointKind, ModelBuilder};
/// let mut b = ModelBuilder::new("pendulum");
/// let arm = b.add_rigid_body("arm", 1.0, Vector3::new(0.5, 0.0, 0.0), Matrix3::identity() * 1e-3);
/// let hinge_frame = axis_frame(Isometry3::identity(), &Vector3::y_axis()); // z onto y
/// let hinge = b.add_joint("hinge", JointKind::Revolute, None, hinge_frame, Some(arm), hinge_frame);
/// b.add_joint_spring(hinge, 0, ForceLaw::Linear { stiffness: 10.0, preload: 0.0 }, 0.0);
/// let model = b.build().unwrap();
/// let (state, report) = restpose::solve(&model, &Default::default()).unwrap();
/// let theta = state.joint(&model, "hinge").unwrap()[0];
/// assert!(report.converged() && (10.0 * theta - 9.81 * 0.5 * theta.cos()).abs() < 1e-8);
/// ```
#[derive(Clone, Debug)]
pub struct ModelBuilder {
    pub(super) model: Model,
    /// Mass properties of `model.links[i]`.
    pub(super) inertials: Vec<Inertial>,
    /// Whether `model.links[i]` is excluded from gravity.
    pub(super) no_gravity: Vec<bool>,
    pub(super) joint_names: NameMap<String, JointId>,
    link_names: NameMap<String, usize>,
    /// `(link index, touches, settings)` from `mech:contact`.
    pub(super) contacts: Vec<(usize, bool, ContactSettings)>,
}

impl ModelBuilder {
    /// An empty model named `name`, gravity `(0, 0, −9.81)` m/s².
    pub fn new(name: impl Into<String>) -> Self {
        ModelBuilder {
            model: Model {
                name: name.into(),
                bodies: Shared::default(),
                links: Shared::default(),
                joints: Shared::default(),
                springs: Shared::default(),
                joint_springs: Shared::default(),
                servos: Shared::default(),
                loads: Shared::default(),
                efforts: Shared::default(),
                locks: Shared::default(),
                mimics: Shared::default(),
                initial: Shared::default(),
                gravity: Vector3::new(0.0, 0.0, -9.81),
                grounds: Shared::default(),
                obstacles: Shared::default(),
                contact_points: Shared::default(),
                length_scale: 1.0,
                base_pose: None,
                base_on_ground: false,
                joint_names: Default::default(),
            },
            inertials: Vec::new(),
            no_gravity: Vec::new(),
            joint_names: NameMap::default(),
            link_names: NameMap::default(),
            contacts: Vec::new(),
        }
    }

    /// Sets gravity in the world frame \[m/s²\].
    pub fn set_gravity(&mut self, gravity: Vector3<f64>) {
        self.model.gravity = gravity;
    }

    /// Adds a moving body whose frame is the frame of the link named `name`; its mass comes
    /// from the links added on it. A body that is no tree joint's child floats (six degrees
    /// of freedom, starting at the world origin).
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

    /// Room for `bodies`, `links` and `joints` more (and their names), so that importing a
    /// large model does not regrow and copy its tables link by link.
    pub fn reserve(&mut self, bodies: usize, links: usize, joints: usize) {
        self.model.bodies.reserve(bodies);
        self.model.links.reserve(links);
        self.inertials.reserve(links);
        self.no_gravity.reserve(links);
        self.link_names.reserve(links);
        self.model.joints.reserve(joints);
        self.joint_names.reserve(joints);
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
            source: None,
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

    /// The index of the link named `name`, if added.
    pub fn link_index(&self, name: &str) -> Option<usize> {
        self.link_names.get(name).copied()
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

    /// Validates the ids, coordinate indices, joint graph and numbers, sums the links' mass
    /// into their bodies and sets the characteristic length.
    ///
    /// # Errors
    /// [`crate::Error::Model`] naming the element with an id or coordinate out of range, a
    /// body placed by two tree joints or on a cycle of them, limits with lower > upper or a
    /// non-finite mass property; [`crate::Error::InvalidNumber`] for a number outside the
    /// accepted range ([`Model::check_numbers`]).
    pub fn build(mut self) -> Result<Model> {
        self.validate()?;
        aggregate_mass(&mut self.model, &self.inertials, &self.no_gravity);
        // The numbers first: the contact points are computed from the checked shapes.
        self.model.check_numbers()?;
        self.model.contact_points = super::contact::points(&self.model, &self.contacts)?.into();
        self.model.length_scale = length_scale(&self.model);
        // The builder's map of the joints pushed (the first of a name wins; joints are never
        // renamed or removed once pushed), moved rather than rebuilt.
        self.model.joint_names = std::mem::take(&mut self.joint_names).into();
        Ok(self.model)
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
