//! Ground planes, and the points of links that rest on them.
//!
//! A ground is the half-space `n·(x − o) ≥ 0` (point `o`, unit normal `n` pointing out of the
//! ground, into free space). A contact point is a point `s` of a body with a radius `ρ` (a
//! sphere's centre, a box's vertex with `ρ = 0`); its gap to a ground is
//!
//! `g(q) = n·(r + A(p) s − o) − ρ ≥ 0`,
//!
//! linear in the body's position and quadratic in its Euler parameters: smooth everywhere, so
//! Newton converges on an active contact as on any other constraint row.

use super::BodyId;
use nalgebra::Vector3;

/// A ground plane (`mech:ground`, or the default plane z = 0 with +z up).
#[derive(Clone, Debug, PartialEq)]
pub struct Ground {
    /// Name (`floor` unless given).
    pub name: String,
    /// A point of the plane, world frame \[m\].
    pub origin: Vector3<f64>,
    /// Unit normal pointing out of the ground (into free space), world frame.
    pub normal: Vector3<f64>,
}

impl Default for Ground {
    /// The plane z = 0 with +z up, named `floor`.
    fn default() -> Self {
        Ground {
            name: "floor".into(),
            origin: Vector3::zeros(),
            normal: Vector3::z(),
        }
    }
}

/// Tangential behaviour of a contact.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, serde::Serialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "snake_case")]
pub enum Friction {
    /// Frictionless: the contact pushes along the normal only (the energy minimum).
    #[default]
    None,
    /// A point that touches is held where it first touched (tangential rows added); the
    /// report gives the friction coefficient each contact needs.
    Stick,
}

/// Per-link contact settings (`mech:contact`); `None` fields take the solver's options.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ContactSettings {
    /// Tangential behaviour.
    pub friction: Option<Friction>,
    /// Friction coefficient: a sticking contact that needs more is reported as slipping.
    pub mu: Option<f64>,
}

/// A point of a body that cannot go below the grounds.
#[derive(Clone, Debug, PartialEq)]
pub struct ContactPoint {
    /// Name of the link whose collision shape gave the point.
    pub link: String,
    /// The body carrying it.
    pub body: BodyId,
    /// The point in the body frame \[m\].
    pub point: Vector3<f64>,
    /// Radius around the point (a sphere's, 0 for a vertex) \[m\].
    pub radius: f64,
    /// Friction settings of the link.
    pub settings: ContactSettings,
}
