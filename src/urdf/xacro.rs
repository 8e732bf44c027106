//! xacro input: a `.xacro` file is expanded to URDF text in-process by the `xacro-rs` crate
//! (macros, properties, conditionals, `$(arg)`, `$(find)`, `load_yaml`), then imported like
//! any URDF.
//!
//! `$(find NAME)` resolves, in order, to the directory given as `packages` (`--package
//! NAME=DIR`), then the way ROS would (`RUST_XACRO_PACKAGE_MAP`, `ROS_PACKAGE_PATH`, a
//! `package.xml` named `NAME` above the file). The same directories resolve the expanded
//! URDF's `package://NAME/…` meshes.
//!
//! Errors of the expansion name the xacro file (and the macro and include stack that
//! `xacro-rs` reports); an error in the expanded URDF names the xacro file with the line and
//! column in the expanded text, and says so.

use crate::error::{Error, Result};
use std::path::{Path, PathBuf};
use xacro_rs::extensions::{ExtensionHandler, FindExtension, OptEnvExtension};
use xacro_rs::XacroProcessor;

/// Whether `path` names a xacro file (`*.xacro`), or `text` declares the xacro namespace.
pub fn is_xacro(path: &Path, text: &str) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("xacro"))
        || text.contains("xmlns:xacro=")
}

/// `$(find NAME)` through the user's `NAME=DIR` list; other names go to the next handler.
struct GivenPackages(Vec<(String, PathBuf)>);

impl ExtensionHandler for GivenPackages {
    fn resolve(
        &self,
        command: &str,
        args_raw: &str,
    ) -> std::result::Result<Option<String>, Box<dyn std::error::Error>> {
        if command != "find" {
            return Ok(None);
        }
        let name = args_raw.trim();
        Ok(self
            .0
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, d)| std::path::absolute(d).unwrap_or_else(|_| d.clone()))
            .map(|d| d.display().to_string()))
    }

    fn as_any(&self) -> &dyn std::any::Any {
        self
    }
}

/// The URDF text that the xacro file at `path` expands to with the arguments `args`
/// (`NAME:=VALUE` pairs) and the package directories `packages`.
///
/// # Errors
/// [`Error::Io`] if the file cannot be read, [`Error::Input`] naming the file when the
/// expansion fails (unknown macro or property, a bad expression, an include or `$(find)` that
/// cannot be resolved), with `xacro-rs`'s message and its macro and include stack.
pub fn expand(
    path: &Path,
    args: &[(String, String)],
    packages: &[(String, PathBuf)],
) -> Result<String> {
    if let Err(cause) = std::fs::metadata(path) {
        return Err(Error::Io {
            path: path.display().to_string(),
            cause,
        });
    }
    // Literal defaults of the top file's `<xacro:arg>`s, for the arguments that the user
    // did not give: `xacro-rs` evaluates `<robot name="$(arg name)">` before it reads the
    // `<xacro:arg name="name" default="ur"/>` below it, which python xacro accepts.
    let mut args = args.to_vec();
    for (name, default) in literal_arg_defaults(path) {
        if !args.iter().any(|(n, _)| *n == name) {
            args.push((name, default));
        }
    }
    // As python xacro: tolerant of duplicate macro parameters and unusual namespace URIs,
    // ROS units (`!degrees`) in YAML.
    XacroProcessor::builder()
        .with_args(args.into_iter().collect())
        .with_extension(Box::new(GivenPackages(packages.to_vec())))
        .with_extension(Box::new(FindExtension::new()))
        .with_extension(Box::new(OptEnvExtension::new()))
        .with_compat_all()
        .with_ros_yaml_units()
        .build()
        .run(path)
        .map_err(|e| {
            let text = e.to_string();
            let mut message = String::from("xacro expansion failed: ");
            message.push_str(text.trim_end());
            if text.contains("find") || text.contains("package") {
                message.push_str(&format!(" ({})", crate::geometry::UNKNOWN_PACKAGE_HINT));
            }
            Error::Input {
                file: path.display().to_string(),
                line: 1,
                col: 1,
                message,
            }
        })
}

/// Renames an importer error located in the expanded text of `path`: the position is in the
/// expansion, which the message says.
pub(crate) fn locate(e: Error, path: &Path) -> Error {
    match e {
        Error::Input {
            line, col, message, ..
        } => Error::Input {
            file: format!("{} (expanded)", path.display()),
            line,
            col,
            message: format!(
                "{message} (line and column of the URDF the xacro file expands to; see it with \
                 `xacro-rs {} > expanded.urdf`)",
                path.display()
            ),
        },
        e => e,
    }
}

/// `(name, default)` of each `<xacro:arg>` child of the root of the file at `path` whose
/// default is literal (no `$(…)` or `${…}`).
fn literal_arg_defaults(path: &Path) -> Vec<(String, String)> {
    let Ok(text) = std::fs::read_to_string(path) else {
        return Vec::new();
    };
    let Ok(doc) = roxmltree::Document::parse(&text) else {
        return Vec::new();
    };
    doc.root_element()
        .children()
        .filter(|n| {
            n.tag_name().name() == "arg"
                && n.tag_name()
                    .namespace()
                    .is_some_and(|u| u.contains("xacro"))
        })
        .filter_map(|n| Some((n.attribute("name")?, n.attribute("default")?)))
        .filter(|(_, d)| !d.contains("$(") && !d.contains("${"))
        .map(|(n, d)| (n.to_string(), d.to_string()))
        .collect()
}
