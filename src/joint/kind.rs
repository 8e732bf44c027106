//! The [`JointKind`] enum and its queries, answered from each kind's [`super::Spec`] through
//! the one table of `table.rs`.

use super::Spec;

/// Largest number of scalar coordinates of any joint kind (planar: `x, y, θ`).
pub(crate) const MAX_SCALAR_COORDINATES: usize = 3;

/// Joint type (each variant's file under `src/joint/` describes it).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum JointKind {
    /// Rotation about z, limited.
    Revolute,
    /// Rotation about z, unlimited.
    Continuous,
    /// Translation along z.
    Prismatic,
    /// No relative motion.
    Fixed,
    /// Six degrees of freedom, no constraint.
    Floating,
    /// Translation in the x-y plane and rotation about z.
    Planar,
    /// Rotation about a common point.
    Spherical,
    /// Rotation about z of the parent and x of the child.
    Universal,
    /// Rotation about and translation along z.
    Cylindrical,
    /// Rotation about z coupled to translation along z: `d = pitch θ`.
    Screw {
        /// Pitch \[m/rad\].
        pitch: f64,
    },
    /// The two joint origins stay `length` apart (massless rod).
    Distance {
        /// Rod length \[m\].
        length: f64,
    },
    /// The child's joint origin stays on the parent's z line.
    PointOnLine,
}

impl JointKind {
    /// The description of this kind (its file under `src/joint/`).
    pub(crate) fn spec(&self) -> &'static Spec {
        super::spec(self)
    }

    /// The type name used in URDF and in the result JSON (the first of its names).
    pub fn name(&self) -> &'static str {
        self.spec().names[0].name
    }

    /// Number of scalar joint coordinates that springs, efforts, locks and initial values can
    /// address (`dof` index): 1 for revolute, continuous, prismatic and screw; 2 for universal
    /// and cylindrical; 3 for planar; 0 otherwise.
    pub fn scalar_coordinates(&self) -> usize {
        self.spec().coordinates.len()
    }

    /// Whether `<limit lower upper>` bounds coordinate 0 of a joint of this kind (every kind
    /// with a scalar coordinate but continuous, which has no position limits).
    pub fn has_limits(&self) -> bool {
        self.spec().has_limits
    }

    /// Whether scalar coordinate `dof` is an angle \[rad\] (otherwise a length \[m\]). Angles
    /// are real numbers, never wrapped into (−π, π].
    pub fn is_angle(&self, dof: usize) -> bool {
        self.spec().coordinates.get(dof).is_some_and(|c| c.angle)
    }

    /// The numbers of values a pose may give for a joint of this kind: its scalar coordinates,
    /// or for a spherical joint a rotation vector (3) or a quaternion `[w, x, y, z]` (4), for a
    /// floating joint `[x, y, z, rx, ry, rz]` (6) or `[x, y, z, w, qx, qy, qz]` (7).
    pub fn value_counts(&self) -> &'static [usize] {
        self.spec().value_counts
    }

    /// Number of values of a joint of this kind in the result JSON (`joints.*.position`, see
    /// [`crate::state::State::joint_values`]): its scalar coordinates, or 4 (a spherical
    /// joint's quaternion), 7 (a floating joint's translation and quaternion).
    pub fn position_len(&self) -> usize {
        self.spec().units.len()
    }

    /// The kind's one parameter (a screw's pitch \[m/rad\], a distance joint's length \[m\]),
    /// 0 for the kinds without one.
    pub(crate) fn parameter(&self) -> f64 {
        match *self {
            JointKind::Screw { pitch } => pitch,
            JointKind::Distance { length } => length,
            _ => 0.0,
        }
    }
}
