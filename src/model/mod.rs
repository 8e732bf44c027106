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
mod force;
mod joint;
mod mass;
mod numeric;
mod obstacle;
mod shared;
mod site;
mod validate;

pub use crate::geometry::Hull;
pub(crate) use crate::joint::MAX_SCALAR_COORDINATES;
pub use crate::joint::{joint_type, joint_types, Declared, JointKind, JointType};
pub use body::{Body, BodyId, Link};
pub use builder::ModelBuilder;
pub use connect::axis_frame;
pub use contact::{ContactPoint, ContactSettings, Friction, Ground};
pub use force::{
    Effort, ForceLaw, Initial, JointSpring, Load, Lock, Mimic, Servo, Spring, SpringEnd, SpringMode,
};
pub use joint::{Joint, JointId};
pub use mass::Inertial;
pub use numeric::{LARGEST_GRAVITY, LARGEST_LENGTH, LARGEST_MAGNITUDE};
pub use obstacle::Obstacle;
pub(crate) use shared::Shared;

use nalgebra::Vector3;

/// A validated mechanism (built by [`ModelBuilder`], which the URDF importer drives);
/// immutable once built: the library's users read it through the accessors ([`Model::bodies`],
/// [`Model::joints`], …). The lists are shared (copy-on-write) between copies (a load step's model shares
/// everything but the loads it scales).
#[derive(Clone, Debug)]
pub struct Model {
    /// Robot name from `<robot name>`.
    pub(crate) name: String,
    /// Moving rigid bodies (7 coordinates each).
    pub(crate) bodies: Shared<Body>,
    /// Every URDF link, with the body carrying it.
    pub(crate) links: Shared<Link>,
    /// Every joint: URDF joints (fixed ones merged into bodies included) and loop joints.
    pub(crate) joints: Shared<Joint>,
    /// Translational point-to-point springs.
    pub(crate) springs: Shared<Spring>,
    /// Springs on joint coordinates.
    pub(crate) joint_springs: Shared<JointSpring>,
    /// Position servos (their springs are the last entries of `joint_springs`).
    pub(crate) servos: Shared<Servo>,
    /// Constant dead loads.
    pub(crate) loads: Shared<Load>,
    /// Constant generalized forces on joint coordinates.
    pub(crate) efforts: Shared<Effort>,
    /// Held joint coordinates.
    pub(crate) locks: Shared<Lock>,
    /// Linear couplings between joint coordinates.
    pub(crate) mimics: Shared<Mimic>,
    /// Initial guesses of joint coordinates.
    pub(crate) initial: Shared<Initial>,
    /// Gravity in the world frame \[m/s²\].
    pub(crate) gravity: Vector3<f64>,
    /// Ground planes (`mech:ground`).
    pub(crate) grounds: Shared<Ground>,
    /// Collision shapes of world-fixed links that contact points rest on (`mech:obstacle`).
    pub(crate) obstacles: Shared<Obstacle>,
    /// Points of the links that touch the grounds (from their collision shapes).
    pub(crate) contact_points: Shared<ContactPoint>,
    /// Characteristic length of the mechanism \[m\], used to scale position coordinates.
    pub(crate) length_scale: f64,
    /// Start pose of the root link in the world when the base floats (`mech:base`; `None`:
    /// the identity).
    pub(crate) base_pose: Option<nalgebra::Isometry3<f64>>,
    /// Only the orientation of `base_pose` was given (`--base-rpy` alone): with grounds, the
    /// ground start finds its position (`solver::assemble::grounded_start`).
    pub(crate) base_on_ground: bool,
    /// Joint ids by name (the first joint of a name wins), built by the builder.
    pub(crate) joint_names: std::sync::Arc<crate::names::NameMap<String, JointId>>,
}

/// Read access for the library's users (the crate reads the fields).
impl Model {
    /// Robot name from `<robot name>`.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Moving rigid bodies (7 coordinates each), indexed by [`BodyId`].
    pub fn bodies(&self) -> &[Body] {
        &self.bodies
    }

    /// Every URDF link, with the body carrying it.
    pub fn links(&self) -> &[Link] {
        &self.links
    }

    /// Every joint, indexed by [`JointId`]: URDF joints (fixed ones merged into bodies
    /// included) and loop joints.
    pub fn joints(&self) -> &[Joint] {
        &self.joints
    }

    /// Translational point-to-point springs.
    pub fn springs(&self) -> &[Spring] {
        &self.springs
    }

    /// Springs on joint coordinates (servos' springs last).
    pub fn joint_springs(&self) -> &[JointSpring] {
        &self.joint_springs
    }

    /// Position servos (their springs are the last entries of [`Model::joint_springs`]).
    pub fn servos(&self) -> &[Servo] {
        &self.servos
    }

    /// Constant dead loads.
    pub fn loads(&self) -> &[Load] {
        &self.loads
    }

    /// Constant generalized forces on joint coordinates.
    pub fn efforts(&self) -> &[Effort] {
        &self.efforts
    }

    /// Held joint coordinates.
    pub fn locks(&self) -> &[Lock] {
        &self.locks
    }

    /// Linear couplings between joint coordinates.
    pub fn mimics(&self) -> &[Mimic] {
        &self.mimics
    }

    /// Initial guesses of joint coordinates.
    pub fn initial(&self) -> &[Initial] {
        &self.initial
    }

    /// Gravity in the world frame \[m/s²\].
    pub fn gravity(&self) -> Vector3<f64> {
        self.gravity
    }

    /// Ground planes (`mech:ground`).
    pub fn grounds(&self) -> &[Ground] {
        &self.grounds
    }

    /// Collision shapes of world-fixed links that contact points rest on (`mech:obstacle`).
    pub fn obstacles(&self) -> &[Obstacle] {
        &self.obstacles
    }

    /// Points of the links that touch the grounds and obstacles.
    pub fn contact_points(&self) -> &[ContactPoint] {
        &self.contact_points
    }

    /// Characteristic length of the mechanism \[m\], used to scale position coordinates.
    pub fn length_scale(&self) -> f64 {
        self.length_scale
    }

    /// Start pose of the root link in the world when the base floats (`mech:base`; `None`:
    /// the identity).
    pub fn base_pose(&self) -> Option<&nalgebra::Isometry3<f64>> {
        self.base_pose.as_ref()
    }

    /// The joint with this id, `None` for an id out of range.
    pub fn get_joint(&self, id: JointId) -> Option<&Joint> {
        self.joints.get(id.0)
    }
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

    /// The joint with this id (an id the crate made: in range by construction; users call
    /// the checked [`Model::get_joint`]).
    pub(crate) fn joint(&self, id: JointId) -> &Joint {
        &self.joints[id.0]
    }

    /// The same model with gravity, dead loads and joint efforts scaled by `factor` (load
    /// stepping). Only the loads and efforts are copied; every other list is shared.
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

    /// The same model with its floating base starting at `pose` (as `mech:base` places it).
    pub fn with_base_pose(&self, pose: nalgebra::Isometry3<f64>) -> Model {
        let mut m = self.clone();
        m.base_pose = Some(pose);
        m.base_on_ground = false;
        m
    }

    /// The same model with the coordinate `lock.dof` of `lock.joint` held (replacing a lock
    /// of that coordinate); `None` when the joint id is out of range or the joint has no such
    /// coordinate.
    pub fn with_lock(&self, lock: Lock) -> Option<Model> {
        let joint = self.get_joint(lock.joint)?;
        if lock.dof >= joint.kind.scalar_coordinates() {
            return None;
        }
        let mut m = self.clone();
        m.locks
            .retain(|l| !(l.joint == lock.joint && l.dof == lock.dof));
        m.locks.push(lock);
        Some(m)
    }

    /// The same model without joint springs (servos, whose springs they are, included): the
    /// efforts a pose needs without them are then the springs' torques.
    pub fn without_joint_springs(&self) -> Model {
        let mut m = self.clone();
        m.joint_springs = Shared::default();
        m.servos = Shared::default();
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
