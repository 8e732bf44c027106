//! Link geometry (URDF `<visual>` / `<collision>`), mesh files, contact points, convex hulls
//! and signed distances, and mass properties computed from geometry with parry3d. This is the
//! one place that converts parry (glam) types. Errors are [`GeometryError`] values.
//!
//! Mesh URIs are resolved in this order: `package://PKG/…` and `model://PKG/…` through a
//! `--package PKG=DIR` option, then `ROS_PACKAGE_PATH` (`DIR/PKG`) and `AMENT_PREFIX_PATH`
//! (`DIR/share/PKG`), then by walking up from the URDF's folder (its absolute path) for a
//! folder named `PKG`;
//! `file://` and plain paths are taken as they are (relative to the URDF's folder). STL, OBJ
//! and COLLADA meshes are read with `mesh-loader`.
//!
//! Mass properties for `--inertia-from-geometry ρ`: each shape's mass `ρ V`, centre of mass
//! and inertia (parry3d), moved to the link frame and summed with the parallel-axis theorem.
//!
//! - `shape`: the shapes; `package`: mesh URIs to files; `mesh`: mesh files to triangles and
//!   convex hulls; `hull`: a convex hull's closest points and normals (obstacles);
//!   `surface`: the signed distance to a shape's surface (closest point and normal, the
//!   obstacles' gap rows); `curvature`: its Hessian;
//!   `contact`: the contact points of a collision shape; `distance`: parry3d's signed
//!   distances (independent checks); `mass`: mass properties; `closure`: whether a mesh is
//!   closed enough to enclose a volume; `error`: what can go wrong.

mod closure;
mod contact;
mod curvature;
mod distance;
mod error;
mod hull;
mod mass;
mod mesh;
mod package;
mod shape;
mod surface;

pub use closure::{volume_uncertainty, OPEN_MESH_TOLERANCE};
pub use contact::{contact_points, CYLINDER_RIM_POINTS};
pub(crate) use curvature::curvature;
pub use distance::{parry_cylinder_signed_distance, parry_signed_distance};
pub use error::GeometryError;
pub use hull::Hull;
pub use mass::{mass_properties, GeometryMass};
pub use mesh::{convex_hull, convex_hull_of, load_mesh, Triangles, Triangles3, MAX_MESH_BYTES};
pub use package::{PackagePaths, UNKNOWN_PACKAGE_HINT};
pub use shape::{Geometry, ShapeKind};
pub(crate) use surface::tangent_plane;
