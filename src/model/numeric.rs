//! Numeric validation of a built model: every number finite and within a range that f64
//! arithmetic on it cannot overflow, stiffnesses not negative.
//!
//! Bounds (SI): masses, inertias, stiffnesses, forces, torques and preloads `|x| ≤ 10¹⁵`;
//! lengths and positions `|x| ≤ 10⁹ m`; gravity `‖g‖ ≤ 10⁴ m/s²`; joint values
//! `|θ| ≤ 10⁹`; the points springs, loads and contacts act at, shape sizes (not negative) and
//! placements, screw pitches and distance lengths are lengths. Energies are then at most about 10²⁴ J·10⁹, far from overflow, and a mass of
//! 10³⁰⁸ kg (which gave `NaN` energies and a "stable" verdict) is refused at load.

use super::{ForceLaw, Model};
use crate::Error;

/// Largest magnitude of a mass \[kg\], inertia \[kg m²\], stiffness, force or torque.
pub const LARGEST_MAGNITUDE: f64 = 1e15;
/// Largest magnitude of a length or position \[m\] and of a joint value.
pub const LARGEST_LENGTH: f64 = 1e9;
/// Largest gravity \[m/s²\].
pub const LARGEST_GRAVITY: f64 = 1e4;

/// The description of the element a number belongs to, formatted only for an error.
type El<'a> = &'a dyn Fn() -> String;

fn within(element: El, name: &str, attribute: &str, value: f64, bound: f64) -> Result<(), Error> {
    if value.is_finite() && value.abs() <= bound {
        Ok(())
    } else {
        Err(Error::InvalidNumber {
            element: element(),
            name: name.into(),
            attribute: attribute.into(),
            value,
            why: format!("is outside the accepted range [−{bound:e}, {bound:e}]"),
        })
    }
}

fn law(element: El, name: &str, law: &ForceLaw) -> Result<(), Error> {
    match law {
        ForceLaw::Linear { stiffness, preload } => {
            within(element, name, "stiffness", *stiffness, LARGEST_MAGNITUDE)?;
            within(element, name, "preload", *preload, LARGEST_MAGNITUDE)?;
            if *stiffness < 0.0 {
                return Err(Error::InvalidNumber {
                    element: element(),
                    name: name.into(),
                    attribute: "stiffness".into(),
                    value: *stiffness,
                    why: "is negative (a spring with negative stiffness has no rest pose \
                          to find)"
                        .into(),
                });
            }
            Ok(())
        }
        ForceLaw::Table { points, .. } => {
            for &(d, f) in points {
                within(element, name, "deflection", d, LARGEST_LENGTH)?;
                within(element, name, "force", f, LARGEST_MAGNITUDE)?;
            }
            Ok(())
        }
    }
}

/// The first size of `shape` that is negative or beyond [`LARGEST_LENGTH`]: `(attribute,
/// value)`; `None` when every size is usable.
pub(crate) fn bad_size(shape: &crate::geometry::ShapeKind) -> Option<(&'static str, f64)> {
    use crate::geometry::ShapeKind;
    let sizes: Vec<(&'static str, f64)> = match shape {
        ShapeKind::Box { size } => size.iter().map(|&v| ("size", v)).collect(),
        ShapeKind::Sphere { radius } => vec![("radius", *radius)],
        ShapeKind::Cylinder { radius, length } | ShapeKind::Capsule { radius, length } => {
            vec![("radius", *radius), ("length", *length)]
        }
        ShapeKind::Mesh { scale, .. } => {
            return scale
                .iter()
                .find(|v| !(v.is_finite() && v.abs() <= LARGEST_LENGTH))
                .map(|&v| ("scale", v))
        }
    };
    sizes
        .into_iter()
        .find(|(_, v)| !(*v >= 0.0 && *v <= LARGEST_LENGTH))
}

/// A placement (shape frame, joint frame): its translation within [`LARGEST_LENGTH`] and its
/// rotation finite.
fn placement(
    element: El,
    name: &str,
    attribute: &str,
    frame: &nalgebra::Isometry3<f64>,
) -> Result<(), Error> {
    for x in frame.translation.vector.iter() {
        within(element, name, attribute, *x, LARGEST_LENGTH)?;
    }
    for x in frame.rotation.coords.iter() {
        within(element, name, attribute, *x, 1.0 + 1e-9)?;
    }
    Ok(())
}

impl Model {
    /// Checks every number of the model (see the module docs for the bounds).
    ///
    /// # Errors
    /// [`Error::InvalidNumber`] naming the first offending element and attribute.
    pub fn check_numbers(&self) -> Result<(), Error> {
        let g = self.gravity;
        for k in 0..3 {
            within(&|| "gravity".into(), "", "xyz", g[k], LARGEST_GRAVITY)?;
        }
        within(&|| "gravity".into(), "", "xyz", g.norm(), LARGEST_GRAVITY)?;
        for b in &self.bodies {
            let e = || format!("link `{}`", b.name);
            within(&e, &b.name, "mass", b.mass, LARGEST_MAGNITUDE)?;
            within(&e, &b.name, "mass", b.gravity_mass, LARGEST_MAGNITUDE)?;
            for x in b.inertia.iter() {
                within(&e, &b.name, "inertia", *x, LARGEST_MAGNITUDE)?;
            }
            for x in b.com.iter().chain(b.gravity_com.iter()) {
                within(&e, &b.name, "origin", *x, LARGEST_LENGTH)?;
            }
        }
        for l in &self.links {
            let e = || format!("link `{}`", l.name);
            placement(&e, &l.name, "origin", &l.body_from_link)?;
            for g in l.collisions.iter().chain(&l.visuals) {
                placement(&e, &l.name, "origin", &g.link_from_shape)?;
                if let Some((attribute, value)) = bad_size(&g.shape) {
                    return Err(Error::InvalidNumber {
                        element: e(),
                        name: l.name.clone(),
                        attribute: attribute.into(),
                        value,
                        why: format!(
                            "is negative or outside the accepted range [0, {LARGEST_LENGTH:e}]"
                        ),
                    });
                }
            }
        }
        for j in &self.joints {
            let e = || format!("joint `{}`", j.name);
            for f in &j.body_from_joint {
                placement(&e, &j.name, "origin", f)?;
            }
            match j.kind {
                super::JointKind::Screw { pitch } => {
                    within(&e, &j.name, "pitch", pitch, LARGEST_LENGTH)?
                }
                super::JointKind::Distance { length } => {
                    within(&e, &j.name, "length", length, LARGEST_LENGTH)?
                }
                _ => {}
            }
        }
        for m in &self.mimics {
            let name = &self.joint(m.joint).name;
            let e = || format!("mimic of `{name}`");
            within(&e, name, "multiplier", m.multiplier, LARGEST_MAGNITUDE)?;
            within(&e, name, "offset", m.offset, LARGEST_LENGTH)?;
        }
        for s in &self.springs {
            let e = || format!("spring `{}`", s.name);
            within(&e, &s.name, "free_length", s.free_length, LARGEST_LENGTH)?;
            for end in &s.ends {
                for x in end.point.iter() {
                    within(&e, &s.name, "xyz", *x, LARGEST_LENGTH)?;
                }
            }
            law(&e, &s.name, &s.law)?;
        }
        for o in &self.obstacles {
            let e = || format!("obstacle link `{}`", o.link);
            placement(&e, &o.link, "origin", &o.world_from_shape)?;
        }
        for g in &self.grounds {
            let e = || format!("ground `{}`", g.name);
            for x in g.origin.iter() {
                within(&e, &g.name, "xyz", *x, LARGEST_LENGTH)?;
            }
        }
        for js in &self.joint_springs {
            let name = &self.joint(js.joint).name;
            let e = || format!("joint spring on `{name}`");
            within(&e, name, "reference", js.reference, LARGEST_LENGTH)?;
            law(&e, name, &js.law)?;
        }
        for l in &self.loads {
            let e = || format!("load `{}`", l.name);
            for x in l.force.iter() {
                within(&e, &l.name, "force", *x, LARGEST_MAGNITUDE)?;
            }
            for x in l.point.iter() {
                within(&e, &l.name, "xyz", *x, LARGEST_LENGTH)?;
            }
        }
        for ef in &self.efforts {
            let name = &self.joint(ef.joint).name;
            within(
                &|| format!("effort on `{name}`"),
                name,
                "value",
                ef.value,
                LARGEST_MAGNITUDE,
            )?;
        }
        for l in &self.locks {
            let name = &self.joint(l.joint).name;
            if let Some(v) = l.value {
                within(
                    &|| format!("lock on `{name}`"),
                    name,
                    "value",
                    v,
                    LARGEST_LENGTH,
                )?;
            }
        }
        for i in &self.initial {
            let name = &self.joint(i.joint).name;
            within(
                &|| format!("initial value of `{name}`"),
                name,
                "value",
                i.value,
                LARGEST_LENGTH,
            )?;
        }
        Ok(())
    }
}
