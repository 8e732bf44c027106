//! The one table of joint kinds: each line binds a [`JointKind`] variant to its file. The
//! type names of files (URDF `<joint type>`, `<mech:loop_joint type>`, `<drake:joint type>`)
//! are read through it ([`joint_type`]), and every query of a kind dispatches through its
//! `match` ([`spec`]): static dispatch, one jump per call.

use super::{Declared, JointKind, Spec};

macro_rules! table {
    ($($variant:ident $({ $field:ident })? => $module:ident,)*) => {
        /// The description of `kind` (its file).
        pub(crate) fn spec(kind: &JointKind) -> &'static Spec {
            match kind {
                $(JointKind::$variant { .. } => &super::$module::SPEC,)*
            }
        }

        /// One of every kind, in table order (parameters zero; the importer reads them from
        /// the element, `urdf/edges.rs`).
        pub const KINDS: &[JointKind] = &[$(JointKind::$variant $({ $field: 0.0 })?,)*];
    };
}

// The table: one line per kind.
table! {
    Revolute => revolute,
    Continuous => continuous,
    Prismatic => prismatic,
    Fixed => fixed,
    Floating => floating,
    Planar => planar,
    Spherical => spherical,
    Universal => universal,
    Cylindrical => cylindrical,
    Screw { pitch } => screw,
    Distance { length } => distance,
    PointOnLine => point_on_line,
}

/// A type name and the kind it reads as.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointType {
    /// The `type` string.
    pub name: &'static str,
    /// The kind it reads as (parameters zero).
    pub kind: JointKind,
    /// Where files may use the name.
    pub declared: Declared,
}

/// Every type name of every kind, in table order.
pub fn joint_types() -> impl Iterator<Item = JointType> {
    KINDS.iter().flat_map(|kind| {
        kind.spec().names.iter().map(|n| JointType {
            name: n.name,
            kind: *kind,
            declared: n.declared,
        })
    })
}

/// The kind of the type name `name`, if there is one.
pub fn joint_type(name: &str) -> Option<JointType> {
    joint_types().find(|t| t.name == name)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::joint::{Row, MAX_SCALAR_COORDINATES};

    /// Every kind's line is complete: a name that reads back as that kind, names unique and
    /// declared somewhere, one name per row, as many units as its longest value list, the
    /// angles among its scalar coordinates, a thread row only without a closed form.
    #[test]
    fn every_kind_is_described_completely() {
        // One line per variant.
        for (i, a) in KINDS.iter().enumerate() {
            let same = |b: &JointKind| std::mem::discriminant(a) == std::mem::discriminant(b);
            assert!(!KINDS[..i].iter().any(same), "{} twice", a.name());
        }
        for k in KINDS {
            let s = k.spec();
            let t = joint_type(k.name()).unwrap();
            assert_eq!(
                std::mem::discriminant(&t.kind),
                std::mem::discriminant(k),
                "{}",
                k.name()
            );
            assert_eq!(s.rows.len(), s.row_names.len(), "{}", k.name());
            let n = k.scalar_coordinates();
            assert!(n <= MAX_SCALAR_COORDINATES);
            for dof in n..MAX_SCALAR_COORDINATES + 1 {
                assert!(!k.is_angle(dof), "{} dof {dof}", k.name());
            }
            if n > 0 {
                assert_eq!(k.value_counts(), &[n]);
                assert_eq!(s.units.len(), n, "{}", k.name());
            }
            assert_eq!(
                s.units.len(),
                k.value_counts().iter().copied().max().unwrap_or(0),
                "{}",
                k.name()
            );
            if s.closed_form {
                assert!(!s.rows.contains(&Row::Thread), "{}", k.name());
            }
            assert_eq!(k.has_limits(), n > 0 && *k != JointKind::Continuous);
        }
        let types: Vec<JointType> = joint_types().collect();
        for (i, a) in types.iter().enumerate() {
            assert!(types[..i].iter().all(|b| b.name != a.name), "{}", a.name);
            let d = a.declared;
            assert!(
                d.urdf || d.loop_joint || d.drake,
                "{} is declared nowhere",
                a.name
            );
        }
        assert_eq!(JointKind::Spherical.name(), "spherical");
        assert_eq!(joint_type("ball").unwrap().kind, JointKind::Spherical);
        assert!(JointKind::Planar.is_angle(2) && !JointKind::Planar.is_angle(0));
        assert!(!JointKind::Prismatic.is_angle(0));
    }
}
