//! What can go wrong reading geometry, as values (the importer turns them into warnings or
//! located errors with the link's name).

use super::package::UNKNOWN_PACKAGE_HINT;
use super::MAX_MESH_BYTES;
use std::path::PathBuf;

/// A geometry that cannot be read or used.
#[derive(Clone, Debug, PartialEq)]
pub enum GeometryError {
    /// A mesh file that does not exist.
    Missing {
        /// The path looked at.
        path: PathBuf,
    },
    /// A `package://` or `model://` package with no such file in any place looked in.
    UnknownPackage {
        /// The package name.
        package: String,
        /// The file inside the package.
        file: String,
        /// The package directories tried (the first four).
        tried: Vec<String>,
    },
    /// A mesh file that cannot be read or parsed.
    Read {
        /// The file.
        path: PathBuf,
        /// The reader's message.
        message: String,
    },
    /// A mesh path that is not a regular file.
    NotAFile {
        /// The path.
        path: PathBuf,
    },
    /// A mesh file larger than [`MAX_MESH_BYTES`].
    TooLarge {
        /// The file.
        path: PathBuf,
        /// Its size \[bytes\].
        bytes: u64,
    },
    /// A mesh file without triangles.
    NoTriangles {
        /// The file.
        path: PathBuf,
    },
    /// A mesh whose URI was not resolved to a file at import.
    MeshNotFound {
        /// The URI as written.
        uri: String,
    },
    /// Points that span no convex hull (parry3d).
    NoHull {
        /// The mesh file they come from, if any.
        path: Option<PathBuf>,
        /// parry3d's reason.
        reason: String,
    },
    /// A mesh parry3d refuses as a triangle mesh.
    BadMesh {
        /// The file.
        path: PathBuf,
        /// parry3d's reason.
        reason: String,
    },
    /// Mass properties asked of no shape.
    NoGeometry,
    /// Geometry whose mass is not positive and finite \[kg\].
    NotPositiveMass {
        /// The mass found.
        mass: f64,
    },
}

impl GeometryError {
    /// A reading error of `path`.
    pub(crate) fn read(path: &std::path::Path, e: &dyn std::fmt::Display) -> Self {
        GeometryError::Read {
            path: path.to_path_buf(),
            message: e.to_string(),
        }
    }
}

impl std::fmt::Display for GeometryError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            GeometryError::Missing { path } => write!(f, "`{}` does not exist", path.display()),
            GeometryError::UnknownPackage {
                package,
                file,
                tried,
            } => write!(
                f,
                "package `{package}` has no `{file}` (looked in {}, …; {UNKNOWN_PACKAGE_HINT})",
                tried.join(", ")
            ),
            GeometryError::Read { path, message } => write!(f, "{}: {message}", path.display()),
            GeometryError::NotAFile { path } => {
                write!(f, "{}: not a regular file", path.display())
            }
            GeometryError::TooLarge { path, bytes } => write!(
                f,
                "{}: the mesh has {bytes} bytes, more than the {MAX_MESH_BYTES} bytes (256 MiB) restpose reads",
                path.display()
            ),
            GeometryError::NoTriangles { path } => write!(f, "{}: no triangles", path.display()),
            GeometryError::MeshNotFound { uri } => write!(f, "mesh `{uri}` was not found"),
            GeometryError::NoHull { path, reason } => {
                if let Some(p) = path {
                    write!(f, "{}: ", p.display())?;
                }
                write!(f, "no convex hull ({reason})")
            }
            GeometryError::BadMesh { path, reason } => {
                write!(f, "{}: {reason}", path.display())
            }
            GeometryError::NoGeometry => write!(f, "no geometry"),
            GeometryError::NotPositiveMass { mass } => write!(
                f,
                "geometry gives a mass of {mass} kg (is the mesh closed and outward-facing?)"
            ),
        }
    }
}

impl std::error::Error for GeometryError {}

impl From<GeometryError> for String {
    fn from(e: GeometryError) -> Self {
        e.to_string()
    }
}
