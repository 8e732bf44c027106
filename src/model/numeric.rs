//! Numeric validation of a built model: every number finite and within a range that f64
//! arithmetic on it cannot overflow, stiffnesses not negative.
//!
//! Bounds (SI): masses, inertias, stiffnesses, forces, torques and preloads `|x| ≤ 10¹⁵`;
//! lengths and positions `|x| ≤ 10⁹ m`; gravity `‖g‖ ≤ 10⁴ m/s²`; joint values
//! `|θ| ≤ 10⁹`. Energies are then at most about 10²⁴ J·10⁹, far from overflow, and a mass of
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
        for j in &self.joints {
            let e = || format!("joint `{}`", j.name);
            for f in &j.body_from_joint {
                for x in f.translation.vector.iter() {
                    within(&e, &j.name, "origin", *x, LARGEST_LENGTH)?;
                }
            }
        }
        for s in &self.springs {
            let e = || format!("spring `{}`", s.name);
            within(&e, &s.name, "free_length", s.free_length, LARGEST_LENGTH)?;
            law(&e, &s.name, &s.law)?;
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
