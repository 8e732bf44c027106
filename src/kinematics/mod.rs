//! Joint kinematics shared by the constraint equations and the forces: joint frames, joint
//! coordinates read on a continuous branch, as each kind's file under [`crate::joint`]
//! describes them.
//!
//! Layering: `math → model → kinematics → {constraints, forces} → state → solver`. Constraints
//! and forces both read joint coordinates from here and never from each other.
//!
//! A joint angle is `θ = θ_b + wrap(atan2(s, c) − θ_b)` for the branch reference `θ_b` of
//! [`Branches`]: a real number, continuous within π of `θ_b`, never wrapped into (−π, π].

mod branches;
mod coordinate;
mod frames;
mod joint_rate;
mod motion;
mod revolute_angle;

pub use branches::Branches;
pub(crate) use coordinate::{
    angle_value_and_spread, coordinate, coordinate_value, on_branch, vector,
};
pub(crate) use frames::{angle, frames};
pub(crate) use joint_rate::{wrench, JointAxis};
pub(crate) use motion::motion;
pub(crate) use revolute_angle::{revolute_first_order, RevoluteFirstOrder};
