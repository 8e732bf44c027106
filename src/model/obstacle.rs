//! Obstacles: collision shapes of world-fixed links that the moving links' contact points rest
//! on, as on a ground (`<mech:obstacle link="L"/>`): the data (link, placement, shape, a
//! mesh's convex hull). A contact point `x` (radius `ρ`) has the gap `g = d(x, S) − ρ`, `d`
//! the signed distance to the shape's surface; its tangent plane and curvature are geometry
//! (`geometry/surface.rs`, `geometry/curvature.rs`), which the methods here call with the
//! obstacle's placement.

use crate::geometry::Hull;
use crate::geometry::ShapeKind;
use nalgebra::{Isometry3, Matrix3, Vector3};

/// A convex shape fixed in the world.
#[derive(Clone, Debug, PartialEq)]
pub struct Obstacle {
    /// The world-fixed link it belongs to.
    pub link: String,
    /// The shape's frame in the world.
    pub world_from_shape: Isometry3<f64>,
    /// The shape (a box, a sphere, a capsule or a cylinder along z, or a mesh).
    pub shape: ShapeKind,
    /// A mesh's convex hull (`None` for the other shapes).
    pub hull: Option<Hull>,
}

impl Obstacle {
    /// The obstacle of `shape` placed at `world_from_shape`, part of the link `link`; a mesh
    /// is read and replaced by its convex hull.
    ///
    /// # Errors
    /// A message naming the mesh if it was not found, cannot be read or spans no volume.
    pub fn new(
        link: &str,
        world_from_shape: Isometry3<f64>,
        shape: &ShapeKind,
    ) -> Result<Self, String> {
        if let Some((attribute, value)) = super::numeric::bad_size(shape) {
            return Err(format!(
                "its {attribute} {value:e} is negative or larger than {:e} m",
                super::LARGEST_LENGTH
            ));
        }
        let hull = match shape {
            ShapeKind::Mesh {
                path: Some(path),
                scale,
                ..
            } => {
                let (points, faces) = crate::geometry::convex_hull(path, scale)?;
                Some(Hull::new(&points, &faces).map_err(|e| format!("{}: {e}", path.display()))?)
            }
            ShapeKind::Mesh {
                uri, path: None, ..
            } => return Err(format!("mesh `{uri}` was not found")),
            _ => None,
        };
        Ok(Self {
            link: link.to_string(),
            world_from_shape,
            shape: shape.clone(),
            hull,
        })
    }

    /// The closest point `c` of the surface to the world point `x` and the outward unit normal
    /// `n` there (world frame): `n·(x − c)` is the signed distance ([`crate::geometry`]).
    pub(crate) fn tangent_plane(&self, x: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
        crate::geometry::tangent_plane(&self.world_from_shape, &self.shape, self.hull.as_ref(), x)
    }

    /// The Hessian of the signed distance to the surface at the world point `x` (world
    /// frame; [`crate::geometry`]).
    pub(crate) fn curvature(&self, x: &Vector3<f64>) -> Matrix3<f64> {
        crate::geometry::curvature(&self.world_from_shape, &self.shape, x)
    }
}
