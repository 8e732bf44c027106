//! URDF `<link>`s: mass properties (`<inertial>`, or the geometry's at a density) and the
//! `<visual>` / `<collision>` geometry, each in its link frame.
//!
//! An `<inertial>` at `origin = (R, c)` with tensor `I₀` gives the link-frame inertia
//! `R I₀ Rᵀ` about the centre of mass `c`.

use super::dom::Node;
use super::xml::{child, parse_f64, Source};
use crate::error::Result;
use crate::geometry::{Geometry, PackagePaths, ShapeKind};
use crate::model::{Inertial, LARGEST_LENGTH};
use nalgebra::{Matrix3, Vector3};

/// Mass properties and geometry of one link, in its link frame.
pub(super) struct LinkIn {
    pub(super) name: String,
    pub(super) inertial: Inertial,
    pub(super) has_inertial: bool,
    pub(super) visuals: Vec<Geometry>,
    pub(super) collisions: Vec<Geometry>,
}

/// The `<geometry>` of a `<visual>` or `<collision>`; `None` (with a warning) for a mesh that
/// is not found or a shape restpose does not know.
fn read_geometry(
    src: &Source,
    owner: Node,
    link: &str,
    packages: &PackagePaths,
    warnings: &mut Vec<String>,
) -> Result<Option<Geometry>> {
    let link_from_shape = src.frame(child(owner, "origin"))?;
    let Some(g) = child(owner, "geometry") else {
        return Ok(None);
    };
    let Some(s) = g.children().find(|c| c.is_element()) else {
        return Ok(None);
    };
    let positive = |attr: &str| -> Result<f64> {
        let v = src.f64_opt(s, attr)?.ok_or_else(|| {
            src.error(
                s,
                format!("link `{link}`: <{}> needs `{attr}`", s.tag_name().name()),
            )
        })?;
        if v < 0.0 {
            return Err(src.error(
                s,
                format!(
                    "link `{link}`: <{}> has a negative {attr} {v}",
                    s.tag_name().name()
                ),
            ));
        }
        src.within(s, attr, &[v], LARGEST_LENGTH)?;
        Ok(v)
    };
    let shape = match s.tag_name().name() {
        "box" => {
            let size = src
                .vec3_opt(s, "size")?
                .ok_or_else(|| src.error(s, format!("link `{link}`: <box> needs `size`")))?;
            if let Some(v) = size.iter().find(|v| **v < 0.0) {
                return Err(src.error(s, format!("link `{link}`: <box> has a negative size {v}")));
            }
            src.within(s, "size", size.as_slice(), LARGEST_LENGTH)?;
            ShapeKind::Box { size }
        }
        "cylinder" => ShapeKind::Cylinder {
            radius: positive("radius")?,
            length: positive("length")?,
        },
        "sphere" => ShapeKind::Sphere {
            radius: positive("radius")?,
        },
        "capsule" => ShapeKind::Capsule {
            radius: positive("radius")?,
            length: positive("length")?,
        },
        "mesh" => {
            let uri = src.req(s, "filename")?.to_string();
            let scale = mesh_scale(src, s, link, warnings)?;
            src.within(s, "scale", scale.as_slice(), LARGEST_LENGTH)?;
            let path = match packages.resolve(&uri) {
                Ok(p) => Some(p),
                Err(why) => {
                    warnings.push(src.warning(s, format!("link `{link}`: mesh not found: {why}")));
                    None
                }
            };
            ShapeKind::Mesh { uri, path, scale }
        }
        other => {
            warnings.push(src.warning(
                s,
                format!("link `{link}`: unknown geometry <{other}> ignored"),
            ));
            return Ok(None);
        }
    };
    Ok(Some(Geometry {
        link_from_shape,
        shape,
    }))
}

/// A mesh's `scale`: three factors; more are ignored (with a warning, as several exporters
/// write four), one is a uniform scale (with a warning).
fn mesh_scale(
    src: &Source,
    s: Node,
    link: &str,
    warnings: &mut Vec<String>,
) -> Result<Vector3<f64>> {
    let Some(text) = s.attribute("scale") else {
        return Ok(Vector3::new(1.0, 1.0, 1.0));
    };
    let v: Option<Vec<f64>> = text.split_whitespace().map(parse_f64).collect();
    match v.as_deref() {
        Some([x, y, z]) => Ok(Vector3::new(*x, *y, *z)),
        Some([x, y, z, ..]) => {
            warnings.push(src.warning(
                s,
                format!("link `{link}`: mesh scale=\"{text}\" has more than 3 components; the first three are used"),
            ));
            Ok(Vector3::new(*x, *y, *z))
        }
        Some([k]) => {
            warnings.push(src.warning(
                s,
                format!("link `{link}`: mesh scale=\"{text}\" has one component; read as a uniform scale"),
            ));
            Ok(Vector3::new(*k, *k, *k))
        }
        _ => Err(src.error(
            s,
            format!("link `{link}`: mesh attribute `scale` = \"{text}\" must be 3 finite numbers"),
        )),
    }
}

/// Reads one `<link>`; with `density`, a link without `<inertial>` gets the mass properties of
/// its collision (else visual) geometry.
pub(super) fn read_link(
    src: &Source,
    node: Node,
    packages: &PackagePaths,
    density: Option<f64>,
    warnings: &mut Vec<String>,
) -> Result<LinkIn> {
    let name = src.req(node, "name")?.to_string();
    let inertial = child(node, "inertial");
    let mut l = LinkIn {
        has_inertial: inertial.is_some(),
        visuals: Vec::new(),
        collisions: Vec::new(),
        name,
        inertial: Inertial::massless(),
    };
    for c in node.children().filter(|c| c.is_element()) {
        let g = match c.tag_name().name() {
            "visual" | "collision" => read_geometry(src, c, &l.name, packages, warnings)?,
            _ => None,
        };
        if let Some(g) = g {
            if c.tag_name().name() == "visual" {
                l.visuals.push(g);
            } else {
                l.collisions.push(g);
            }
        }
    }
    if let Some(inertial) = inertial {
        let origin = src.frame(child(inertial, "origin"))?;
        if let Some(m) = child(inertial, "mass") {
            let mass = src.f64_opt(m, "value")?.ok_or_else(|| {
                src.error(m, format!("link `{}`: <mass> is missing `value`", l.name))
            })?;
            if mass < 0.0 {
                return Err(src.error(
                    m,
                    format!("link `{}` has a negative mass {mass} kg", l.name),
                ));
            }
            l.inertial.mass = mass;
        }
        l.inertial.com = origin.translation.vector;
        if let Some(i) = child(inertial, "inertia") {
            let g = |a: &str| src.f64_or(i, a, 0.0);
            // Each attribute read once, in the order the symmetric matrix lists them.
            let (xx, xy, xz) = (g("ixx")?, g("ixy")?, g("ixz")?);
            let (yy, yz, zz) = (g("iyy")?, g("iyz")?, g("izz")?);
            let local = Matrix3::new(xx, xy, xz, xy, yy, yz, xz, yz, zz);
            let r = origin.rotation.to_rotation_matrix();
            l.inertial.inertia = r.matrix() * local * r.matrix().transpose();
            if let Some(why) = inertia_problem(&local, l.inertial.mass) {
                warnings.push(src.warning(
                    i,
                    format!("link `{}`: the inertia tensor is not physically valid ({why}); statics does not use it", l.name),
                ));
            }
        }
    }
    if let (Some(density), false) = (density, l.has_inertial) {
        let shapes = if l.collisions.is_empty() {
            &l.visuals
        } else {
            &l.collisions
        };
        if !shapes.is_empty() {
            match crate::geometry::mass_properties(shapes, density) {
                Ok(g) => {
                    for (uri, u) in &g.open_meshes {
                        warnings.push(src.warning(
                            node,
                            format!(
                                "link `{}`: mesh `{uri}` is not closed: the volume it encloses \
                                 changes by up to {:.2} % with the point it is measured from, \
                                 and so does the mass --inertia-from-geometry gives the link \
                                 (close the mesh, or give the link an <inertial>)",
                                l.name,
                                100.0 * u
                            ),
                        ));
                    }
                    l.inertial = Inertial {
                        mass: g.mass,
                        com: g.com,
                        inertia: g.inertia,
                    };
                }
                Err(why) => warnings.push(src.warning(
                    node,
                    format!("link `{}`: no mass from geometry: {why}", l.name),
                )),
            }
        }
    }
    Ok(l)
}

/// A link's principal moments below `m r²` with this `r` \[m\] (its mass within a
/// micrometre) are a point mass's zeros: exporters write a point mass's tensor as entries of
/// 10⁻²⁰ – 10⁻³⁵ kg m² of either sign (icub-models), which is no invalid inertia.
const POINT_MASS_RADIUS: f64 = 1e-6;

/// Why an inertia tensor is not physically valid (a principal moment negative, or one larger
/// than the sum of the other two, beyond `max(10⁻⁹ |I|, m (1 µm)²)`), if it is not.
fn inertia_problem(i: &Matrix3<f64>, mass: f64) -> Option<String> {
    let Some(eig) = nalgebra::SymmetricEigen::try_new(*i, f64::EPSILON, 1000) else {
        return Some("its eigenvalues cannot be computed".into());
    };
    // nalgebra's result checked as module `solver::eigen` checks it (dimforge/nalgebra#1109;
    // `urdf` is below `solver`): `I v_k = λ_k v_k` and `VᵀV = 1`, to 10⁻⁹ of `|I|`.
    let (e, v) = (eig.eigenvalues, eig.eigenvectors);
    let residual = (i * v - v * Matrix3::from_diagonal(&e)).amax();
    let orthonormal = (v.transpose() * v - Matrix3::identity()).amax();
    if !(residual <= 1e-9 * i.amax() && orthonormal <= 1e-9) {
        return Some(format!(
            "its eigendecomposition fails its check (residual {residual:.3e}, orthonormality \
             {orthonormal:.3e})"
        ));
    }
    let tol = (1e-9 * e.amax())
        .max(mass * POINT_MASS_RADIUS * POINT_MASS_RADIUS)
        .max(f64::MIN_POSITIVE);
    if e.min() < -tol {
        return Some(format!("principal moment {:.3e} < 0", e.min()));
    }
    for k in 0..3 {
        if e[k] > e[(k + 1) % 3] + e[(k + 2) % 3] + tol {
            return Some(format!(
                "principal moment {:.3e} exceeds the sum of the other two",
                e[k]
            ));
        }
    }
    None
}

#[cfg(test)]
mod inertia_tests {
    use super::*;
    use nalgebra::UnitQuaternion;

    /// Principal moments `d` turned by `r`: `R diag(d) Rᵀ`.
    fn turned(d: [f64; 3], r: &UnitQuaternion<f64>) -> Matrix3<f64> {
        let m = r.to_rotation_matrix();
        m.matrix() * Matrix3::from_diagonal(&Vector3::from(d)) * m.matrix().transpose()
    }

    /// Tensors at the edges of validity, turned: a rod (moments 1, 1, 0), equal moments, a
    /// point mass's rounding (10⁻²⁰ – 10⁻³⁵ of either sign), a flat plate (1, 1, 2), moments
    /// 10⁻⁶ beside 10³; and invalid ones just beyond the tolerance.
    #[test]
    fn decisions_at_the_edges_hold_in_any_orientation() {
        let turns = [
            UnitQuaternion::identity(),
            UnitQuaternion::from_euler_angles(0.3, -1.1, 2.0),
            UnitQuaternion::from_euler_angles(1e-9, 0.0, 0.7),
        ];
        for r in &turns {
            for (d, mass, valid) in [
                ([1.0, 1.0, 0.0], 1.0, true),
                ([1.0, 1.0, 1.0], 1.0, true),
                ([1e-20, -1e-35, 3e-21], 1.0, true),
                ([1.0, 1.0, 2.0], 1.0, true),
                ([1e3, 1e-6, 1e3], 1.0, true),
                ([1.0, 1.0, 2.0 + 1e-6], 1.0, false),
                ([1.0, 1.0, -1e-6], 1.0, false),
                ([1e3, 1e3, 2e3 * (1.0 + 1e-6)], 1.0, false),
            ] {
                let got = inertia_problem(&turned(d, r), mass);
                assert_eq!(got.is_none(), valid, "{d:?} turned {r}: {got:?}");
            }
        }
        assert!(inertia_problem(&Matrix3::from_element(f64::NAN), 1.0).is_some());
    }
}
