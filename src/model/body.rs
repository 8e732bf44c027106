//! Rigid bodies and the URDF links they carry.

use nalgebra::{Isometry3, Matrix3, Vector3};

/// Index of a moving body in [`crate::Model::bodies`].
///
/// Ids come from the model (or [`crate::model::ModelBuilder::add_body`]); they cannot be
/// written by hand, so an id always names a body of the model it came from.
///
/// ```compile_fail
/// let forged = restpose::model::BodyId(7);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct BodyId(pub(crate) usize);

impl BodyId {
    /// Position of the body in [`crate::Model::bodies`].
    pub fn index(self) -> usize {
        self.0
    }
}

/// A moving rigid body: one URDF link, or several welded by fixed joints.
#[derive(Clone, Debug)]
pub struct Body {
    /// Name of the link whose frame is the body frame.
    pub name: String,
    /// Total mass \[kg\].
    pub mass: f64,
    /// Centre of mass in the body frame \[m\].
    pub com: Vector3<f64>,
    /// Inertia about the centre of mass, body-frame axes \[kg m²\].
    pub inertia: Matrix3<f64>,
    /// Mass subject to gravity \[kg\] (links can be excluded with `mech:link_gravity`).
    pub gravity_mass: f64,
    /// Centre of the mass subject to gravity, body frame \[m\].
    pub gravity_com: Vector3<f64>,
}

/// A URDF link and where it sits.
#[derive(Clone, Debug)]
pub struct Link {
    /// Link name.
    pub name: String,
    /// The body carrying it; `None` for links welded to the world.
    pub body: Option<BodyId>,
    /// Link frame in the body frame (in the world frame when welded to the world).
    pub body_from_link: Isometry3<f64>,
    /// `<visual>` geometry, in the link frame.
    pub visuals: Vec<crate::geometry::Geometry>,
    /// `<collision>` geometry, in the link frame.
    pub collisions: Vec<crate::geometry::Geometry>,
    /// The link's element in the input file (`None` for a model built in code): errors about
    /// its contact points name it.
    pub source: Option<crate::error::SourceLocation>,
}
