//! Joint-like elements as edges of the joint graph: URDF `<joint>`, `<drake:joint>`,
//! `<mech:loop_joint>`, a foreign `<loop_joint>` and `<drake:ball_constraint>`.
//!
//! Each edge places its joint frame `J` on both sides: `origin` is `J` in the parent link
//! frame, `child_origin` is `J` in the child link frame (identity for tree joints, whose child
//! link frame is `J` at zero displacement). An endpoint may also be a `mech:frame` (folded into
//! the origin) or the undeclared `world`.

use super::dom::Node;
use super::limits::{limits, urdf_limits};
use super::xml::{child, Source};
use crate::error::Result;
use crate::joint::Frame;
use crate::model::{joint_type, JointKind};
use crate::names::NameMap;
use nalgebra::{Isometry3, Vector3};

/// The namespace URI Drake uses for its URDF extensions.
pub(super) const DRAKE_NS: &str = "http://drake.mit.edu";

/// Where an edge comes from, which decides its preference for the spanning tree.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Declaration {
    /// URDF `<joint>`: a tree edge; fixed ones weld links into one body.
    Urdf,
    /// `<drake:joint>`: a tree edge of another type.
    Drake,
    /// A loop element: a loop closure unless the spanning tree needs it.
    Loop,
}

/// One edge of the joint graph.
pub(super) struct Edge<'a> {
    pub(super) node: Node<'a, 'a>,
    pub(super) name: String,
    pub(super) kind: JointKind,
    /// Parent and child link indices (`None`: the undeclared world).
    pub(super) parent: Option<usize>,
    pub(super) child: Option<usize>,
    pub(super) parent_link: String,
    pub(super) child_link: String,
    pub(super) origin: Isometry3<f64>,
    pub(super) child_origin: Isometry3<f64>,
    pub(super) axis: Vector3<f64>,
    pub(super) axis2: Vector3<f64>,
    pub(super) limits: Option<[f64; 2]>,
    pub(super) source: Declaration,
    /// `<child_origin auto="initial"/>`: computed so the joint holds at the initial guess.
    pub(super) auto_child_origin: bool,
}

/// Link names and named frames: name → (link index or world, link_from_frame).
pub(super) struct Frames<'a> {
    pub(super) links: &'a NameMap<String, usize>,
    pub(super) frames: FrameMap,
}

impl Frames<'_> {
    /// Resolves a link or frame name at `node`.
    pub(super) fn resolve(
        &self,
        src: &Source,
        node: Node,
        name: &str,
    ) -> Result<(Option<usize>, Isometry3<f64>)> {
        resolve(self.links, &self.frames, src, node, name)
    }
}

/// Named frames: name → (link index or world, link_from_frame).
pub(super) type FrameMap = NameMap<String, (Option<usize>, Isometry3<f64>)>;

/// Resolves a link or frame name at `node`: a link, a `mech:frame`, or the world.
pub(super) fn resolve(
    links: &NameMap<String, usize>,
    frames: &FrameMap,
    src: &Source,
    node: Node,
    name: &str,
) -> Result<(Option<usize>, Isometry3<f64>)> {
    if let Some(&i) = links.get(name) {
        return Ok((Some(i), Isometry3::identity()));
    }
    if let Some(f) = frames.get(name) {
        return Ok(*f);
    }
    if name == "world" {
        return Ok((None, Isometry3::identity()));
    }
    Err(src.error(
        node,
        format!(
            "{} refers to an unknown link or frame `{name}`",
            src.describe(node)
        ),
    ))
}

/// The effort limit `<limit effort>` of a joint element (absent, unreadable or not positive:
/// none; urdfdom requires it but many files write 0).
pub(super) fn effort_limit(src: &Source, node: Node) -> Option<f64> {
    let l = child(node, "limit")?;
    src.f64_opt(l, "effort")
        .ok()
        .flatten()
        .filter(|e| *e > 0.0 && e.is_finite())
}

/// The axis of a URDF joint. Fixed, floating and spherical joints have none: urdfdom does not
/// read it, so whatever is written there (often `0 0 0` from CAD exporters) is ignored, with a
/// warning when it could not have been an axis.
fn urdf_axis(
    src: &Source,
    node: Node,
    kind: JointKind,
    warnings: &mut Vec<String>,
) -> Result<Vector3<f64>> {
    let a = child(node, "axis");
    if kind.spec().frame == Frame::Origin {
        if let Some(a) = a {
            if src.axis(Some(a), node, Vector3::x()).is_err() {
                warnings.push(src.warning(
                    a,
                    format!(
                        "{} ({}) has no axis; its <axis xyz=\"{}\"> is ignored",
                        src.describe(node),
                        kind.name(),
                        a.attribute("xyz").unwrap_or_default()
                    ),
                ));
            }
        }
        return Ok(Vector3::x());
    }
    src.axis(a, node, Vector3::x())
}

/// A resolved endpoint: link index (or world), link_from_frame, the name as written.
type End = (Option<usize>, Isometry3<f64>, String);

/// Parent and child of a joint with `<parent link>` / `<child link>` children.
fn ends(src: &Source, node: Node, frames: &Frames, name: &str) -> Result<[End; 2]> {
    let side = |tag: &str| -> Result<End> {
        let c = child(node, tag)
            .ok_or_else(|| src.error(node, format!("joint `{name}` has no <{tag}> element")))?;
        let l = src.req(c, "link")?;
        let (i, f) = frames.resolve(src, c, l)?;
        Ok((i, f, l.to_string()))
    };
    Ok([side("parent")?, side("child")?])
}

/// The kind of a URDF `<joint type>`, from the one table of type names
/// ([`crate::joint`], column `urdf`); `ball` is read as `spherical` with a
/// warning.
pub(super) fn urdf_kind(
    src: &Source,
    node: Node,
    ty: &str,
    warnings: &mut Vec<String>,
) -> Result<JointKind> {
    let Some(t) = joint_type(ty).filter(|t| t.declared.urdf) else {
        return Err(src.error(
            node,
            format!("{} has an unknown type \"{ty}\"", src.describe(node)),
        ));
    };
    if t.kind.name() != t.name {
        warnings.push(src.warning(
            node,
            format!(
                "{} has type \"{ty}\", read as \"{}\"",
                src.describe(node),
                t.kind.name()
            ),
        ));
    }
    Ok(t.kind)
}

/// A URDF `<joint>` (tree edge).
pub(super) fn urdf_joint<'a>(
    src: &Source,
    node: Node<'a, 'a>,
    frames: &Frames,
    warnings: &mut Vec<String>,
) -> Result<Edge<'a>> {
    let name = src.req(node, "name")?.to_string();
    let kind = urdf_kind(src, node, src.req(node, "type")?, warnings)?;
    let [(parent, pf, parent_link), (child_i, cf, child_link)] = ends(src, node, frames, &name)?;
    let mut lim = urdf_limits(src, node, kind, warnings)?;
    if kind == JointKind::Continuous && lim.take().is_some_and(|[lo, hi]| lo != 0.0 || hi != 0.0) {
        warnings.push(src.warning(
            node,
            format!(
                "{}: a continuous joint has no position limits; <limit lower upper> ignored",
                src.describe(node)
            ),
        ));
    }
    Ok(Edge {
        node,
        kind,
        parent,
        child: child_i,
        parent_link,
        child_link,
        origin: pf * src.frame(child(node, "origin"))?,
        child_origin: cf,
        axis: urdf_axis(src, node, kind, warnings)?,
        axis2: Vector3::y(),
        limits: lim,
        source: Declaration::Urdf,
        auto_child_origin: false,
        name,
    })
}

/// A `<drake:joint type="ball|universal|planar|screw">` (tree edge). Drake's planar and screw
/// joints act about z unless an `<axis>` says otherwise; `drake:screw_thread_pitch` is in m
/// per revolution.
pub(super) fn drake_joint<'a>(
    src: &Source,
    node: Node<'a, 'a>,
    frames: &Frames,
) -> Result<Edge<'a>> {
    let name = src.req(node, "name")?.to_string();
    let ty = src.req(node, "type")?;
    let kind = match joint_type(ty).filter(|t| t.declared.drake).map(|t| t.kind) {
        Some(JointKind::Screw { .. }) => {
            let p = node
                .children()
                .find(|c| c.is_element() && c.tag_name().name() == "screw_thread_pitch")
                .ok_or_else(|| src.error(node, format!("drake joint `{name}`: a screw joint needs <drake:screw_thread_pitch value>")))?;
            let per_rev = src.length_opt(p, "value")?.ok_or_else(|| src.error(p, "<drake:screw_thread_pitch> needs `value`"))?;
            JointKind::Screw { pitch: per_rev / (2.0 * std::f64::consts::PI) }
        }
        Some(kind) => kind,
        None => {
            return Err(src.error(node, format!("drake joint `{name}` has type \"{ty}\"; drake:joint types are ball, universal, planar and screw (use <joint> for the others)")))
        }
    };
    let [(parent, pf, parent_link), (child_i, cf, child_link)] = ends(src, node, frames, &name)?;
    let default_axis = if matches!(kind, JointKind::Universal) {
        Vector3::x()
    } else {
        Vector3::z()
    };
    Ok(Edge {
        node,
        kind,
        parent,
        child: child_i,
        parent_link,
        child_link,
        origin: pf * src.frame(child(node, "origin"))?,
        child_origin: cf,
        axis: src.axis(child(node, "axis"), node, default_axis)?,
        axis2: Vector3::y(),
        limits: limits(src, node)?,
        source: Declaration::Drake,
        auto_child_origin: false,
        name,
    })
}

/// The kind of a `<mech:loop_joint type>` (the table [`crate::joint`], column
/// `loop_joint`), with its parameters.
fn loop_kind(src: &Source, node: Node) -> Result<JointKind> {
    let ty = src.req(node, "type")?;
    let Some(t) = joint_type(ty).filter(|t| t.declared.loop_joint) else {
        return Err(src.error(
            node,
            format!("{} has an unknown type \"{ty}\"", src.describe(node)),
        ));
    };
    // The parameters of the kinds that have some, from the element's attributes.
    Ok(match t.kind {
        JointKind::Screw { .. } => JointKind::Screw {
            pitch: src.length_opt(node, "pitch")?.unwrap_or(0.0),
        },
        JointKind::Distance { .. } => JointKind::Distance {
            length: match src.length_opt(node, "length")? {
                Some(l) if l >= 0.0 => l,
                Some(l) => {
                    return Err(src.error(
                        node,
                        format!(
                            "{}: a distance joint's `length` {l} is negative",
                            src.describe(node)
                        ),
                    ))
                }
                None => {
                    return Err(src.error(
                        node,
                        format!("{}: a distance joint needs `length`", src.describe(node)),
                    ))
                }
            },
        },
        kind => kind,
    })
}

/// A `<mech:loop_joint>`.
pub(super) fn mech_loop_joint<'a>(
    src: &Source,
    node: Node<'a, 'a>,
    frames: &Frames,
) -> Result<Edge<'a>> {
    let name = src.req(node, "name")?.to_string();
    let kind = loop_kind(src, node)?;
    let [(parent, pf, parent_link), (child_i, cf, child_link)] = ends(src, node, frames, &name)?;
    let co = child(node, "child_origin");
    let auto_child_origin = match co.and_then(|c| c.attribute("auto")) {
        None => false,
        Some("initial") => true,
        Some(other) => {
            return Err(src.error(co.unwrap_or(node), format!("loop joint `{name}`: <child_origin auto=\"{other}\"> (only \"initial\" is defined)")))
        }
    };
    if auto_child_origin && matches!(kind, JointKind::Distance { .. }) {
        return Err(src.error(co.unwrap_or(node), format!(
            "loop joint `{name}`: <child_origin auto> places the child's joint frame on the parent's, which a distance joint of nonzero length cannot use; give the child point"
        )));
    }
    let axis = src.axis(child(node, "axis"), node, Vector3::x())?;
    let axis2 = src.axis(child(node, "axis2"), node, Vector3::y())?;
    if kind == JointKind::Universal && axis.cross(&axis2).norm() < 1e-9 {
        return Err(src.error(node, format!("universal joint `{name}` has parallel axes")));
    }
    Ok(Edge {
        node,
        kind,
        parent,
        child: child_i,
        parent_link,
        child_link,
        origin: pf * src.frame(child(node, "origin"))?,
        child_origin: cf * src.frame(co.filter(|_| !auto_child_origin))?,
        axis,
        axis2,
        limits: limits(src, node)?,
        source: Declaration::Loop,
        auto_child_origin,
        name,
    })
}

/// A foreign `<loop_joint name type><link1 link xyz rpy/><link2 link xyz rpy/><axis/>`.
pub(super) fn foreign_loop_joint<'a>(
    src: &Source,
    node: Node<'a, 'a>,
    frames: &Frames,
) -> Result<Edge<'a>> {
    let name = src.req(node, "name")?.to_string();
    let kind = loop_kind(src, node)?;
    let side = |tag: &str| -> Result<End> {
        let c = child(node, tag).ok_or_else(|| {
            src.error(node, format!("loop joint `{name}` has no <{tag}> element"))
        })?;
        let l = src.req(c, "link")?;
        let (i, f) = frames.resolve(src, c, l)?;
        Ok((i, f * src.frame(Some(c))?, l.to_string()))
    };
    let (parent, origin, parent_link) = side("link1")?;
    let (child_i, child_origin, child_link) = side("link2")?;
    Ok(Edge {
        node,
        kind,
        parent,
        child: child_i,
        parent_link,
        child_link,
        origin,
        child_origin,
        axis: src.axis(child(node, "axis"), node, Vector3::x())?,
        axis2: Vector3::y(),
        limits: limits(src, node)?,
        source: Declaration::Loop,
        auto_child_origin: false,
        name,
    })
}

/// The child element `drake:{prefix}{suffix}` and its attribute `attr`.
pub(super) fn drake_part<'a>(
    src: &Source,
    node: Node<'a, 'a>,
    tag: &str,
    attr: &str,
) -> Result<(Node<'a, 'a>, &'a str)> {
    let c = node
        .children()
        .find(|c| c.is_element() && c.tag_name().name() == tag)
        .ok_or_else(|| {
            src.error(
                node,
                format!(
                    "<drake:{}> has no <drake:{tag}> element",
                    node.tag_name().name()
                ),
            )
        })?;
    Ok((c, src.req(c, attr)?))
}

/// A `<drake:ball_constraint>`: a spherical loop joint, parent A at `p_AP`, child B at `p_BQ`.
pub(super) fn drake_ball_constraint<'a>(
    src: &Source,
    node: Node<'a, 'a>,
    frames: &Frames,
    index: usize,
) -> Result<Edge<'a>> {
    let name = node
        .attribute("name")
        .map_or_else(|| format!("ball_constraint_{index}"), str::to_string);
    let point = |tag: &str| -> Result<Isometry3<f64>> {
        let (c, _) = drake_part(src, node, tag, "value")?;
        let p = src.position_or(c, "value", Vector3::zeros())?;
        Ok(Isometry3::translation(p.x, p.y, p.z))
    };
    let (na, a) = drake_part(src, node, "ball_constraint_body_A", "name")?;
    let (nb, b) = drake_part(src, node, "ball_constraint_body_B", "name")?;
    let (pa, fa) = frames.resolve(src, na, a)?;
    let (pb, fb) = frames.resolve(src, nb, b)?;
    Ok(Edge {
        node,
        kind: JointKind::Spherical,
        parent: pa,
        child: pb,
        parent_link: a.to_string(),
        child_link: b.to_string(),
        origin: fa * point("ball_constraint_p_AP")?,
        child_origin: fb * point("ball_constraint_p_BQ")?,
        axis: Vector3::x(),
        axis2: Vector3::y(),
        limits: None,
        source: Declaration::Loop,
        auto_child_origin: false,
        name,
    })
}
