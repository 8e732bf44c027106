//! Mass properties: a link's [`Inertial`], and their sum into the body that carries the links.
//!
//! A body's mass properties are the sum of its links' (parallel-axis theorem):
//! `m = Σ mₗ`, `c = Σ mₗ cₗ / m`, `I = Σ (Rₗ Iₗ Rₗᵀ + mₗ (|dₗ|² 𝟙 − dₗ dₗᵀ))` with
//! `dₗ = cₗ − c`, every term in the body frame. Links excluded from gravity
//! (`mech:link_gravity`) count in `m` but not in `gravity_mass`.

use super::Model;
use nalgebra::{Matrix3, Point3, Vector3};

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

/// Sums link masses into their bodies (parallel-axis theorem for the inertia); `inertials`
/// and `no_gravity` are indexed like `model.links`.
pub(super) fn aggregate_mass(model: &mut Model, inertials: &[Inertial], no_gravity: &[bool]) {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{JointKind, ModelBuilder};
    use nalgebra::Isometry3;

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
}
