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
//! - `plots/potential_energy`, `plots/gradient_norm`: on the `iteration` timeline;
//! - the `mode` timeline: the softest mode shape as an oscillation about the rest pose.

mod read;
mod record;

pub use read::{read_recording, RecordingSummary};
pub use record::write_recording;
