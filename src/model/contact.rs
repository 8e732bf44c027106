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

use super::{BodyId, Model, ModelBuilder};
use crate::error::{Error, Result};
use nalgebra::{Point3, Vector3};

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

/// The contact points of the links that touch the grounds, in their body frames: the links
/// selected by `contacts` (`(link index, touches, settings)`), or with no selection every
/// moving link with collision geometry.
///
/// # Errors
/// [`Error::Model`] for a selected link without collision geometry, or a mesh that cannot be
/// read.
pub(crate) fn points(
    m: &Model,
    contacts: &[(usize, bool, ContactSettings)],
) -> Result<Vec<ContactPoint>> {
    if m.grounds.is_empty() && m.obstacles.is_empty() {
        return Ok(Vec::new());
    }
    let explicit = contacts.iter().any(|c| c.1);
    let mut out = Vec::new();
    for (i, l) in m.links.iter().enumerate() {
        let Some(body) = l.body else { continue };
        let chosen = contacts.iter().find(|c| c.0 == i);
        let (touches, settings) = match chosen {
            Some(&(_, t, s)) => (t, s),
            None => (!explicit, ContactSettings::default()),
        };
        if !touches {
            continue;
        }
        if chosen.is_some() && l.collisions.is_empty() {
            return Err(Error::Model(format!(
                "link `{}` is selected for contact but has no <collision> geometry",
                l.name
            )));
        }
        for g in &l.collisions {
            let pts = crate::geometry::contact_points(g)
                .map_err(|e| Error::Model(format!("contact points of link `{}`: {e}", l.name)))?;
            for (p, radius) in pts {
                out.push(ContactPoint {
                    link: l.name.clone(),
                    body,
                    point: (l.body_from_link * Point3::from(p)).coords,
                    radius,
                    settings,
                });
            }
        }
    }
    Ok(out)
}

impl ModelBuilder {
    /// Adds a ground plane through `origin` with the normal `normal` (pointing out of the
    /// ground; normalized here).
    ///
    /// # Errors
    /// [`Error::Model`] for a zero or non-finite normal or a non-finite origin.
    pub fn add_ground(
        &mut self,
        name: impl Into<String>,
        origin: Vector3<f64>,
        normal: Vector3<f64>,
    ) -> Result<()> {
        let name = name.into();
        let len = normal.norm();
        if !(len.is_finite() && len > 1e-12 && origin.iter().all(|x| x.is_finite())) {
            return Err(Error::Model(format!(
                "ground `{name}` needs a finite origin and a non-zero normal (got normal {} {} {})",
                normal.x, normal.y, normal.z
            )));
        }
        self.model.grounds.push(Ground {
            name,
            origin,
            normal: normal / len,
        });
        Ok(())
    }

    /// Selects whether the link with index `link` touches the grounds (`mech:contact`). With
    /// no selection at all, every moving link with collision geometry does.
    pub fn set_contact(&mut self, link: usize, touches: bool, settings: ContactSettings) {
        self.contacts.retain(|c| c.0 != link);
        self.contacts.push((link, touches, settings));
    }

    /// Sets the start pose of the root link in the world, used when the base floats
    /// (`mech:base`): the first guess of the floating base, which the joints' initial values
    /// then extend to the whole tree.
    pub fn set_base_pose(&mut self, pose: nalgebra::Isometry3<f64>) {
        self.model.base_pose = Some(pose);
        self.model.base_on_ground = false;
    }

    /// Sets the start orientation of the floating root link and leaves its position to the
    /// ground start: with grounds and contact points, the floating bodies are raised along
    /// gravity, so turned, until their lowest contact point touches a ground; without, the
    /// root link starts at the world origin.
    pub fn set_base_orientation(&mut self, rotation: nalgebra::UnitQuaternion<f64>) {
        self.model.base_pose = Some(nalgebra::Isometry3::from_parts(
            nalgebra::Translation3::identity(),
            rotation,
        ));
        self.model.base_on_ground = true;
    }

    /// Makes the collision shapes of the world-fixed link with index `link` obstacles
    /// (`mech:obstacle`): boxes, spheres, capsules, cylinders and meshes (their convex hull).
    ///
    /// # Errors
    /// [`Error::Model`] for a moving link, a link without collision geometry, or a mesh that
    /// cannot be read or spans no volume.
    pub fn add_obstacle(&mut self, link: usize) -> Result<()> {
        let l = self
            .model
            .links
            .get(link)
            .ok_or_else(|| Error::Model(format!("no link with index {link}")))?;
        if l.body.is_some() {
            return Err(Error::Model(format!(
                "link `{}` is an obstacle but is not fixed to the world",
                l.name
            )));
        }
        if l.collisions.is_empty() {
            return Err(Error::Model(format!(
                "link `{}` is an obstacle but has no <collision> geometry",
                l.name
            )));
        }
        let mut found = Vec::new();
        for g in &l.collisions {
            let world_from_shape = l.body_from_link * g.link_from_shape;
            found.push(
                super::Obstacle::new(&l.name, world_from_shape, &g.shape)
                    .map_err(|e| Error::Model(format!("link `{}` (obstacle): {e}", l.name)))?,
            );
        }
        self.model.obstacles.extend(found);
        Ok(())
    }

    /// The grounds added so far.
    pub fn grounds(&self) -> &[Ground] {
        &self.model.grounds
    }
}
