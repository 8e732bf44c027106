//! A rerun recording of a solve: the mechanism at rest, how the minimizer got there, and the
//! forces that hold it (feature `viewer`; every rerun type stays in this module).
//!
//! Entities:
//! - `world/robot/<root>/<child>/…`: one entity per link, nested along the spanning tree, with
//!   the link's transform relative to its parent link on the `iteration` timeline; each link's
//!   `visual_<k>` children carry its shapes (box, cylinder, sphere, capsule, mesh) and
//!   `joint_<name>` an arrow along the joint axis;
//! - `world/com/<body>`: centres of mass; `world/springs/<name>`: line strips, red in tension,
//!   blue in compression, grey when slack; `world/loads/<name>` and `world/gravity`: arrows;
//!   `world/reactions/<joint>`: reaction forces at the rest pose (arrows scaled so the largest
//!   is one characteristic length);
//! - `world/grounds/<name>`: ground planes with a grid; `world/contacts/points` and
//!   `world/contacts/forces`: contact points coloured by state and the ground's force on each
//!   (scaled so the largest is one characteristic length); `world/stops/<joint>`: joints
//!   resting on a stop, labelled with the stop and its effort (their axis arrows are orange);
//! - `plots/potential_energy`, `plots/gradient_norm`: on the `iteration` timeline;
//! - the `mode` timeline: the poses it is given, e.g. the softest mode shape as an oscillation
//!   about the rest pose ([`solver::mode_animation`](crate::solver::mode_animation)).
//!
//! This module only formats what it is given: it computes no pose.

mod contact;
mod read;
mod record;
mod shapes;

pub use read::{read_recording, RecordingSummary};
pub use record::write_recording;
