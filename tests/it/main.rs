//! The integration tests, one crate (the shared helpers of `common` are compiled once),
//! one module per topic. `regressions/` holds one file per fixed bug, named
//! `issue_<n>_<what>.rs`, each opening with a paragraph on the bug.

mod angles;
mod architecture;
mod builder;
mod cli;
mod common;
mod contact;
mod degenerate;
mod engineering;
mod formats;
mod friction;
mod golden;
mod importer;
mod importer_fuzz;
mod input_errors;
mod meshes;
mod mode_animation;
mod obstacle;
mod paper_pendulum;
mod properties;
mod readme;
mod real_robots;
mod regressions;
mod robots;
mod servo;
mod sparse;
mod stability_listing;
mod stand;
mod stdout_outputs;
mod verify;
#[cfg(feature = "viewer")]
mod viewer;
mod write_back;
#[cfg(feature = "xacro")]
mod xacro;
