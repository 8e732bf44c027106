//! Mesh URIs to files: `package://PKG/…` and `model://PKG/…` through the package directories
//! given, then `ROS_PACKAGE_PATH` (`DIR/PKG`) and `AMENT_PREFIX_PATH` (`DIR/share/PKG`), then
//! by walking up from the URDF's folder (its absolute path, so also above the working
//! directory) for a folder named `PKG`; `file://` and plain paths as they are (relative to the
//! URDF's folder).

use super::GeometryError;
use std::path::{Path, PathBuf};

/// The end of the message for a `package://` mesh that is not found: a front end that takes
/// package directories in another form (a command-line option) may replace it.
pub const UNKNOWN_PACKAGE_HINT: &str = "give the package's directory in the import options";

/// Where to look for `package://` and `model://` folders.
#[derive(Clone, Debug, Default)]
pub struct PackagePaths {
    /// Package directories given by the user: `(NAME, DIR)`.
    pub explicit: Vec<(String, PathBuf)>,
    /// The URDF's folder (`None` for text without a file).
    pub urdf_dir: Option<PathBuf>,
}

impl PackagePaths {
    /// Resolves a mesh URI to an existing file, or says where it looked.
    pub fn resolve(&self, uri: &str) -> Result<PathBuf, GeometryError> {
        let base = self.urdf_dir.clone().unwrap_or_else(|| PathBuf::from("."));
        let found = |p: PathBuf| {
            if p.is_file() {
                Ok(p)
            } else {
                Err(GeometryError::Missing { path: p })
            }
        };
        if let Some(rest) = uri.strip_prefix("file://") {
            let p = PathBuf::from(rest);
            return found(if p.is_absolute() { p } else { base.join(p) });
        }
        let Some(rest) = uri
            .strip_prefix("package://")
            .or_else(|| uri.strip_prefix("model://"))
        else {
            let p = PathBuf::from(uri);
            return found(if p.is_absolute() { p } else { base.join(p) });
        };
        let (pkg, rel) = rest.split_once('/').unwrap_or((rest, ""));
        let mut tried = Vec::new();
        let mut candidates: Vec<PathBuf> = self
            .explicit
            .iter()
            .filter(|(n, _)| n == pkg)
            .map(|(_, d)| d.clone())
            .collect();
        for var in ["ROS_PACKAGE_PATH", "AMENT_PREFIX_PATH"] {
            if let Ok(v) = std::env::var(var) {
                for d in std::env::split_paths(&v) {
                    candidates.push(if var == "AMENT_PREFIX_PATH" {
                        d.join("share").join(pkg)
                    } else {
                        d.join(pkg)
                    });
                }
            }
        }
        // Walk up from the folder's absolute, resolved path: a URDF named relative to the
        // working directory (`restpose analyze model.urdf` in the robot's own folder) must
        // still find the package folder above it, beyond the working directory.
        let start = if base.as_os_str().is_empty() {
            PathBuf::from(".")
        } else {
            base.clone()
        };
        let start = std::fs::canonicalize(&start)
            .or_else(|_| std::path::absolute(&start))
            .unwrap_or(start);
        let mut up: Option<&Path> = Some(start.as_path());
        while let Some(dir) = up {
            if dir.file_name().is_some_and(|n| n == pkg) {
                candidates.push(dir.to_path_buf());
            }
            candidates.push(dir.join(pkg));
            up = dir.parent();
        }
        for c in candidates {
            let p = c.join(rel);
            if p.is_file() {
                return Ok(p);
            }
            tried.push(c.display().to_string());
        }
        tried.truncate(4);
        Err(GeometryError::UnknownPackage {
            package: pkg.to_string(),
            file: rel.to_string(),
            tried,
        })
    }
}
