//! The joint kinds' type names: the one table from the `type` strings of files (URDF
//! `<joint type>`, `<mech:loop_joint type>`, `<drake:joint type>`) to [`JointKind`], and back
//! to the name the result JSON, the summary and the exports print ([`JointKind::name`]).
//!
//! Each kind's first line gives its name; a later line of the same kind is an alias (`ball`
//! for `spherical`). A kind with parameters (screw pitch, distance length) is listed with
//! zero parameters, which the importer reads from the element (`urdf/edges.rs`).

use super::JointKind;

/// Where a file may declare a joint of a type name.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Declared {
    /// A URDF `<joint type>` (a tree joint).
    pub urdf: bool,
    /// A `<mech:loop_joint type>` (a loop-closing joint).
    pub loop_joint: bool,
    /// A `<drake:joint type>` (Drake's extension).
    pub drake: bool,
}

/// One line of [`JOINT_TYPES`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointType {
    /// The `type` string.
    pub name: &'static str,
    /// The kind it reads as (parameters zero: module docs).
    pub kind: JointKind,
    /// Where files may use the name.
    pub declared: Declared,
}

const fn line(
    name: &'static str,
    kind: JointKind,
    urdf: bool,
    loop_joint: bool,
    drake: bool,
) -> JointType {
    JointType {
        name,
        kind,
        declared: Declared {
            urdf,
            loop_joint,
            drake,
        },
    }
}

/// Every joint type name (module docs). Columns: name, kind, accepted in a URDF `<joint>`, in
/// a `<mech:loop_joint>`, in a `<drake:joint>`.
#[rustfmt::skip]
pub const JOINT_TYPES: &[JointType] = &[
    line("revolute",      JointKind::Revolute,                  true,  true,  false),
    line("continuous",    JointKind::Continuous,                true,  true,  false),
    line("prismatic",     JointKind::Prismatic,                 true,  true,  false),
    line("fixed",         JointKind::Fixed,                     true,  true,  false),
    line("floating",      JointKind::Floating,                  true,  false, false),
    line("planar",        JointKind::Planar,                    true,  true,  true),
    line("spherical",     JointKind::Spherical,                 true,  true,  false),
    line("ball",          JointKind::Spherical,                 true,  true,  true),
    line("universal",     JointKind::Universal,                 false, true,  true),
    line("cylindrical",   JointKind::Cylindrical,               false, true,  false),
    line("screw",         JointKind::Screw { pitch: 0.0 },      false, true,  true),
    line("distance",      JointKind::Distance { length: 0.0 },  false, true,  false),
    line("point_on_line", JointKind::PointOnLine,               false, true,  false),
];

/// The line of the type name `name`, if there is one.
pub fn joint_type(name: &str) -> Option<&'static JointType> {
    JOINT_TYPES.iter().find(|t| t.name == name)
}

/// Whether two kinds are the same variant (parameters aside).
pub(crate) fn same_variant(a: &JointKind, b: &JointKind) -> bool {
    std::mem::discriminant(a) == std::mem::discriminant(b)
}

/// The name of a kind: its first line in [`JOINT_TYPES`].
pub(crate) fn name_of(kind: &JointKind) -> &'static str {
    JOINT_TYPES
        .iter()
        .find(|t| same_variant(&t.kind, kind))
        .map_or("unknown", |t| t.name)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every kind has a line, its name reads back as that kind, and names are unique.
    #[test]
    fn every_kind_has_a_name_that_reads_back() {
        for k in crate::model::joint_kind::tests::KINDS {
            let name = name_of(&k);
            assert_ne!(name, "unknown", "{k:?}");
            let t = joint_type(name).unwrap();
            assert!(same_variant(&t.kind, &k), "{name}");
        }
        for (i, a) in JOINT_TYPES.iter().enumerate() {
            assert!(
                JOINT_TYPES[..i].iter().all(|b| b.name != a.name),
                "{}",
                a.name
            );
            let d = a.declared;
            assert!(
                d.urdf || d.loop_joint || d.drake,
                "{} is declared nowhere",
                a.name
            );
        }
        assert_eq!(name_of(&JointKind::Spherical), "spherical");
        assert_eq!(joint_type("ball").unwrap().kind, JointKind::Spherical);
    }
}
