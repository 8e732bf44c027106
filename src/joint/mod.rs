//! Joint kinds, one file each (Pinocchio's `joint/`, rapier's one file per joint): a kind's
//! type names in files, its scalar coordinates read from the two joint frames, its constraint
//! rows `Φ = 0` as primitives, its relative motion `M(θ)` and the values read back from it,
//! how `<axis>` places its frame, what moves its child in joint space, its JSON units and its
//! entries in MuJoCo's and Pinocchio's configuration vectors. The layers above interpret
//! these descriptions: `jet::closed` and `constraints::joint` evaluate the rows with their
//! Jacobians and Hessians, `kinematics` the coordinates and the motion, `urdf` the names and
//! the frame, `export` the units and configurations.
//!
//! Adding a kind: one file here holding its `Spec` (`spec.rs`), its variant in [`JointKind`]
//! and one line in the table of `table.rs` (see `docs/development.md`).
//!
//! The frame `J` of a joint has its z axis along the joint axis (for a universal joint x is
//! the second axis; for a planar joint z is the plane normal). At zero displacement the two
//! `J` frames coincide; the motion of the child's `J` in the parent's `J` is given in each
//! kind's file.

mod kind;
mod spec;
mod table;

mod continuous;
mod cylindrical;
mod distance;
mod fixed;
mod floating;
mod planar;
mod point_on_line;
mod prismatic;
mod revolute;
mod screw;
mod spherical;
mod universal;

pub use kind::JointKind;
pub(crate) use kind::MAX_SCALAR_COORDINATES;
pub use spec::{Declared, Name};
pub(crate) use spec::{Entry, Frame, Pattern, Read, Row, Spec, TreeMotion, ALL, V};
pub(crate) use table::spec;
pub use table::{joint_type, joint_types, JointType, KINDS};
