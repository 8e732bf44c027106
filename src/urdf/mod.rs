//! The input boundary: URDF text (with the `mech:` extensions of `docs/urdf-extensions.md`) to a
//! validated [`Model`]. Nothing else in the crate sees XML.
//!
//! The file is read into a compact document (module `dom`) that keeps the position of every
//! element, so that each error names `FILE:LINE:COLUMN` and the element: plain XML (ASCII, no
//! references, DTD or CDATA: what URDF files are) by a one-pass reader (module `lean`),
//! anything else, and every malformed file, by `roxmltree`, whose errors are the ones
//! reported. The standard URDF tree and the extension elements are read in one pass; the
//! spanning tree is the URDF `<joint>` tree, and every `mech:loop_joint` closes a loop.

mod base;
mod byte_class;
mod dom;
mod dom_convert;
#[cfg(test)]
mod dom_tests;
mod edges;
mod extensions;
mod foreign;
mod import;
mod lean;
mod limits;
mod lines;
mod links;
mod mimic;
mod number;
mod relocate;
mod schema;
mod servo;
mod text;
mod tree;
mod write_back;
#[cfg(feature = "xacro")]
pub mod xacro;
mod xml;

pub use relocate::relocated;
pub use servo::{srdf_state, ServoRequest};
pub use text::{read_file as read_text, MAX_DEPTH, MAX_FILE_BYTES};
pub use write_back::with_initial_pose;

#[cfg(doc)]
use crate::error::Error;
use crate::error::Result;
use crate::model::Model;
use nalgebra::Vector3;
use std::path::Path;

/// Options of the importer (the CLI maps its flags onto these).
#[derive(Clone, Debug)]
pub struct ImportOptions {
    /// Gravity used when the file has no `mech:gravity` \[m/s²\] (default `0 0 −9.81`).
    pub gravity: Vector3<f64>,
    /// Leave the root link free (6 degrees of freedom) instead of welding it to the world.
    pub floating_base: bool,
    /// Locks `(joint, dof, value)` that override `mech:lock` (`None` = the initial value).
    pub locks: Vec<(String, usize, Option<f64>)>,
    /// Initial values `(joint, dof, value)` that override `mech:initial`.
    pub initial: Vec<(String, usize, f64)>,
    /// `--package NAME=DIR`: where `package://NAME/…` meshes live.
    pub packages: Vec<(String, std::path::PathBuf)>,
    /// `--inertia-from-geometry DENSITY` \[kg/m³\]: links without `<inertial>` get the mass
    /// properties of their collision geometry (or visual, if none) at this density.
    pub inertia_density: Option<f64>,
    /// Add the default ground plane (z = 0, +z up) unless the file declares that plane.
    pub ground: bool,
    /// Start pose of the root link in the world when the base floats; overrides `mech:base`.
    pub base_pose: Option<nalgebra::Isometry3<f64>>,
    /// Start orientation of the root link when the base floats and `base_pose` is not given
    /// (`--base-rpy` alone); overrides `mech:base`. Its position is found by the ground start
    /// (the lowest contact point on the ground; without grounds, the world origin).
    pub base_orientation: Option<nalgebra::UnitQuaternion<f64>>,
    /// Position servos (`--servo`), applied in order after the file's own elements.
    pub servos: Vec<ServoRequest>,
    /// Reference pose of the servos `(joint, value)` (`--servo-reference`, an SRDF
    /// `group_state`): a servo without its own reference holds its joint at this value, and
    /// the joint starts there unless the file gives it a `mech:initial` (the file's start is
    /// kept: a rest pose written by `--write-urdf` starts at that rest);
    /// [`ImportOptions::initial`] overrides both.
    pub servo_reference: Vec<(String, f64)>,
    /// `--xacro-arg NAME:=VALUE`: arguments of a xacro file (feature `xacro`).
    pub xacro_args: Vec<(String, String)>,
}

impl Default for ImportOptions {
    fn default() -> Self {
        ImportOptions {
            gravity: Vector3::new(0.0, 0.0, -9.81),
            floating_base: false,
            locks: Vec::new(),
            initial: Vec::new(),
            packages: Vec::new(),
            inertia_density: None,
            ground: false,
            base_pose: None,
            base_orientation: None,
            servos: Vec::new(),
            servo_reference: Vec::new(),
            xacro_args: Vec::new(),
        }
    }
}

/// A loaded model with what the importer has to say about it.
#[derive(Clone, Debug)]
pub struct Loaded {
    /// The model.
    pub model: Model,
    /// Warnings (repaired input, ignored content that may matter).
    pub warnings: Vec<String>,
    /// Foreign elements that were ignored, as `LINE:COL <name>`.
    pub ignored: Vec<String>,
}

/// Reads a URDF file, or a xacro file (`*.xacro`, or a file declaring the xacro namespace)
/// expanded first when the feature `xacro` is on (module `xacro`).
///
/// # Errors
/// [`Error::Io`] if the file cannot be read, [`Error::Input`] (with line and column) if it is
/// not a valid restpose URDF, larger than [`MAX_FILE_BYTES`] or nested deeper than
/// [`MAX_DEPTH`].
pub fn load_file(path: impl AsRef<Path>, options: &ImportOptions) -> Result<Loaded> {
    let path = path.as_ref();
    let text = text::read_file(path)?;
    let dir = path.parent().map(|d| {
        if d.as_os_str().is_empty() {
            std::path::PathBuf::from(".")
        } else {
            d.to_path_buf()
        }
    });
    #[cfg(feature = "xacro")]
    if xacro::is_xacro(path, &text) {
        let expanded = xacro::expand(path, &options.xacro_args, &options.packages)?;
        let file = path.display().to_string();
        let mut loaded =
            import::import(&expanded, &file, dir, options).map_err(|e| xacro::locate(e, path))?;
        // Positions in warnings are in the expansion too.
        for w in &mut loaded.warnings {
            if let Some(rest) = w.strip_prefix(&format!("{file}:")) {
                *w = format!("{file} (expanded):{rest}");
            }
        }
        return Ok(loaded);
    }
    import::import(&text, &path.display().to_string(), dir, options)
}

/// The text of the URDF file at `path`: a xacro file (feature `xacro`) is expanded with the
/// options' `xacro_args` and `packages`, as [`load_file`] does.
///
/// # Errors
/// As [`load_file`], for reading and expanding.
pub fn read_urdf_text(path: impl AsRef<Path>, options: &ImportOptions) -> Result<String> {
    let path = path.as_ref();
    let text = text::read_file(path)?;
    #[cfg(feature = "xacro")]
    if xacro::is_xacro(path, &text) {
        return xacro::expand(path, &options.xacro_args, &options.packages);
    }
    let _ = options;
    Ok(text)
}

/// Reads URDF text; `file` names it in error messages; relative mesh paths are taken from the
/// current folder.
///
/// # Errors
/// [`Error::Input`] (with line and column) if the text is not a valid restpose URDF.
///
/// # Example
/// ```
/// let urdf = r#"<robot name="r"><link name="base"/><link name="arm">
///   <inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>
/// </link><joint name="j" type="revolute"><parent link="base"/><child link="arm"/>
///   <axis xyz="0 0 1"/></joint></robot>"#;
/// let loaded = restpose::urdf::load_str(urdf, "arm.urdf", &Default::default()).unwrap();
/// assert_eq!(loaded.model.bodies().len(), 1);
/// ```
pub fn load_str(text: &str, file: &str, options: &ImportOptions) -> Result<Loaded> {
    import::import(text, file, None, options)
}
