//! `impl JointKind` in one place: its type name (URDF and the result JSON, from the one table
//! of type names in `joint_types.rs`), how many values each kind takes and which of its
//! coordinates are angles.

use super::JointKind;

/// Largest number of scalar coordinates of any joint kind (planar: `x, y, θ`).
pub(crate) const MAX_SCALAR_COORDINATES: usize = 3;

impl JointKind {
    /// The type name used in URDF and in the result JSON (its first line in
    /// [`super::JOINT_TYPES`]).
    pub fn name(&self) -> &'static str {
        super::joint_types::name_of(self)
    }

    /// Number of scalar joint coordinates that springs, efforts, locks and initial values can
    /// address (`dof` index): 1 for revolute, continuous, prismatic and screw; 2 for universal
    /// and cylindrical; 3 for planar; 0 otherwise.
    pub fn scalar_coordinates(&self) -> usize {
        match self {
            JointKind::Revolute
            | JointKind::Continuous
            | JointKind::Prismatic
            | JointKind::Screw { .. } => 1,
            JointKind::Universal | JointKind::Cylindrical => 2,
            JointKind::Planar => 3,
            _ => 0,
        }
    }

    /// Whether `<limit lower upper>` bounds coordinate 0 of a joint of this kind (every kind
    /// with a scalar coordinate but continuous, which has no position limits).
    pub fn has_limits(&self) -> bool {
        self.scalar_coordinates() > 0 && *self != JointKind::Continuous
    }

    /// Whether scalar coordinate `dof` is an angle \[rad\] (otherwise a length \[m\]). Angles
    /// are real numbers, never wrapped into (−π, π].
    pub fn is_angle(&self, dof: usize) -> bool {
        matches!(
            (self, dof),
            (
                JointKind::Revolute | JointKind::Continuous | JointKind::Screw { .. },
                0
            ) | (JointKind::Cylindrical, 0)
                | (JointKind::Universal, 0 | 1)
                | (JointKind::Planar, 2)
        )
    }

    /// The numbers of values a pose may give for a joint of this kind: its scalar coordinates,
    /// or for a spherical joint a rotation vector (3) or a quaternion `[w, x, y, z]` (4), for a
    /// floating joint `[x, y, z, rx, ry, rz]` (6) or `[x, y, z, w, qx, qy, qz]` (7).
    pub fn value_counts(&self) -> &'static [usize] {
        match self {
            JointKind::Spherical => &[3, 4],
            JointKind::Floating => &[6, 7],
            k => match k.scalar_coordinates() {
                1 => &[1],
                2 => &[2],
                3 => &[3],
                _ => &[0],
            },
        }
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// One of every kind (the unit tests' list: add a new kind here).
    pub(crate) const KINDS: [JointKind; 12] = [
        JointKind::Revolute,
        JointKind::Continuous,
        JointKind::Prismatic,
        JointKind::Fixed,
        JointKind::Floating,
        JointKind::Planar,
        JointKind::Spherical,
        JointKind::Universal,
        JointKind::Cylindrical,
        JointKind::Screw { pitch: 0.01 },
        JointKind::Distance { length: 1.0 },
        JointKind::PointOnLine,
    ];

    #[test]
    fn angles_are_scalar_coordinates_and_counts_agree() {
        for k in KINDS {
            let n = k.scalar_coordinates();
            assert!(n <= MAX_SCALAR_COORDINATES);
            for dof in n..MAX_SCALAR_COORDINATES + 1 {
                assert!(!k.is_angle(dof), "{} dof {dof}", k.name());
            }
            if n > 0 {
                assert_eq!(k.value_counts(), &[n]);
            }
        }
        assert!(!JointKind::Prismatic.is_angle(0));
        assert!(JointKind::Planar.is_angle(2) && !JointKind::Planar.is_angle(0));
    }
}
