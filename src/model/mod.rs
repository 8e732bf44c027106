//! The immutable mechanism model: rigid bodies, the links they carry, joints, forces.
//!
//! Each moving body `i` has 7 Cartesian coordinates `q_i = [r_i; p_i]` (body-frame origin in
//! the world, Euler parameters). Links welded by URDF `fixed` joints share one body; every
//! link keeps its own `body_from_link` transform so that its pose can be reported. The world
//! (ground) is not a body: joints and forces refer to it with `None`.

mod body;
mod builder;
mod connect;
mod contact;
mod curvature;
mod force;
mod joint;
mod joint_kind;
mod mass;
mod numeric;
mod obstacle;
mod site;
mod validate;

pub use crate::geometry::Hull;
pub use body::{Body, BodyId, Link};
pub use builder::ModelBuilder;
pub use connect::axis_frame;
pub use contact::{ContactPoint, ContactSettings, Friction, Ground};
pub use force::{
    Effort, ForceLaw, Initial, JointSpring, Load, Lock, Mimic, Servo, Spring, SpringEnd, SpringMode,
};
pub use joint::{Joint, JointId, JointKind};
pub(crate) use joint_kind::MAX_SCALAR_COORDINATES;
pub use mass::Inertial;
pub use numeric::{LARGEST_GRAVITY, LARGEST_LENGTH, LARGEST_MAGNITUDE};
pub use obstacle::Obstacle;

use nalgebra::Vector3;

/// A validated mechanism (built by [`ModelBuilder`], which the URDF importer drives);
/// immutable once built.
#[derive(Clone, Debug)]
pub struct Model {
    /// Robot name from `<robot name>`.
    pub name: String,
    /// Moving rigid bodies (7 coordinates each).
    pub bodies: Vec<Body>,
    /// Every URDF link, with the body carrying it.
    pub links: Vec<Link>,
    /// Every joint: URDF joints (fixed ones merged into bodies included) and loop joints.
    pub joints: Vec<Joint>,
    /// Translational point-to-point springs.
    pub springs: Vec<Spring>,
    /// Springs on joint coordinates.
    pub joint_springs: Vec<JointSpring>,
    /// Position servos (their springs are the last entries of `joint_springs`).
    pub servos: Vec<Servo>,
    /// Constant dead loads.
    pub loads: Vec<Load>,
    /// Constant generalized forces on joint coordinates.
    pub efforts: Vec<Effort>,
    /// Held joint coordinates.
    pub locks: Vec<Lock>,
    /// Linear couplings between joint coordinates.
    pub mimics: Vec<Mimic>,
    /// Initial guesses of joint coordinates.
    pub initial: Vec<Initial>,
    /// Gravity in the world frame \[m/s²\].
    pub gravity: Vector3<f64>,
    /// Ground planes (`mech:ground`).
    pub grounds: Vec<Ground>,
    /// Collision shapes of world-fixed links that contact points rest on (`mech:obstacle`).
    pub obstacles: Vec<Obstacle>,
    /// Points of the links that touch the grounds (from their collision shapes).
    pub contact_points: Vec<ContactPoint>,
    /// Characteristic length of the mechanism \[m\], used to scale position coordinates.
    pub length_scale: f64,
    /// Start pose of the root link in the world when the base floats (`mech:base`; `None`:
    /// the identity).
    pub base_pose: Option<nalgebra::Isometry3<f64>>,
    /// Joint ids by name (the first joint of a name wins), built by the builder.
    pub(crate) joint_names: crate::names::NameMap<String, JointId>,
}

impl Model {
    /// Number of Cartesian coordinates `n = 7 b`.
    pub fn coordinate_count(&self) -> usize {
        7 * self.bodies.len()
    }

    /// The ids of the bodies, in model order.
    pub fn body_ids(&self) -> impl Iterator<Item = BodyId> {
        (0..self.bodies.len()).map(BodyId)
    }

    /// The ids of the joints, in model order.
    pub fn joint_ids(&self) -> impl Iterator<Item = JointId> {
        (0..self.joints.len()).map(JointId)
    }

    /// Looks a joint up by name (through the name map when it is current, else by a scan).
    pub fn joint_id(&self, name: &str) -> Option<JointId> {
        match self.joint_names.get(name) {
            Some(&id) if self.joints.get(id.0).is_some_and(|j| j.name == name) => Some(id),
            _ => self.joints.iter().position(|j| j.name == name).map(JointId),
        }
    }

    /// The joint name closest to `name`, if one is close ([`crate::names::closest`]): the
    /// "did you mean" of error messages.
    pub fn closest_joint(&self, name: &str) -> Option<String> {
        crate::names::closest(name, self.joints.iter().map(|j| j.name.as_str())).map(str::to_owned)
    }

    /// [`crate::Error::UnknownJoint`] for `name`, with the closest joint name as a suggestion.
    pub fn unknown_joint(&self, what: &str, name: &str) -> crate::Error {
        crate::Error::UnknownJoint {
            what: what.into(),
            name: name.into(),
            suggestion: self.closest_joint(name),
        }
    }

    /// Looks a link up by name.
    pub fn link(&self, name: &str) -> Option<&Link> {
        self.links.iter().find(|l| l.name == name)
    }

    /// The joint with this id.
    pub fn joint(&self, id: JointId) -> &Joint {
        &self.joints[id.0]
    }

    /// The same model with gravity, dead loads and joint efforts scaled by `factor` (load
    /// stepping).
    pub fn with_load_factor(&self, factor: f64) -> Model {
        let mut m = self.clone();
        m.gravity *= factor;
        for l in &mut m.loads {
            l.force *= factor;
        }
        for e in &mut m.efforts {
            e.value *= factor;
        }
        m
    }

    /// Name of the coordinate `i` of the state vector, as `body.x` … `body.e3`.
    pub fn coordinate_name(&self, i: usize) -> String {
        const C: [&str; 7] = ["x", "y", "z", "e0", "e1", "e2", "e3"];
        match self.bodies.get(i / 7) {
            Some(b) => format!("{}.{}", b.name, C[i % 7]),
            None => format!("q{i}"),
        }
    }
}
