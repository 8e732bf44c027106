//! The shapes of a link's `<visual>` and `<collision>` elements, in the link frame.

use nalgebra::{Isometry3, Vector3};
use std::path::PathBuf;

/// A geometric shape of a link.
#[derive(Clone, Debug, PartialEq)]
pub enum ShapeKind {
    /// Box with full edge lengths \[m\].
    Box {
        /// Edge lengths along x, y, z.
        size: Vector3<f64>,
    },
    /// Cylinder along z.
    Cylinder {
        /// Radius \[m\].
        radius: f64,
        /// Length \[m\].
        length: f64,
    },
    /// Sphere.
    Sphere {
        /// Radius \[m\].
        radius: f64,
    },
    /// Capsule along z (cylinder of `length` with hemispherical caps).
    Capsule {
        /// Radius \[m\].
        radius: f64,
        /// Length of the cylindrical part \[m\].
        length: f64,
    },
    /// Triangle mesh file.
    Mesh {
        /// The URI as written.
        uri: String,
        /// The file it resolved to (`None`: not found; the import warned).
        path: Option<PathBuf>,
        /// Scale factors.
        scale: Vector3<f64>,
    },
}

/// A shape placed in its link frame.
#[derive(Clone, Debug, PartialEq)]
pub struct Geometry {
    /// Shape frame in the link frame.
    pub link_from_shape: Isometry3<f64>,
    /// The shape.
    pub shape: ShapeKind,
}
