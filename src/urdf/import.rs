//! The standard URDF tree: links, joints, fixed-joint merging into bodies.
//!
//! Links joined by `fixed` joints form one rigid body whose frame is the frame of its topmost
//! link; `body_from_link` composes the fixed joint origins. The root link is welded to the
//! world (its frame is the world frame) unless a floating base is asked for.

use super::extensions;
use super::xml::{child, is_mech, Source};
use super::{ImportOptions, Loaded};
use crate::error::{Error, Result};
use crate::math::align_z;
use crate::model::{Body, BodyId, Joint, JointKind, Link, Model};
use nalgebra::{Isometry3, Matrix3, UnitQuaternion, Vector3};
use roxmltree::Node;
use std::collections::HashMap;

/// Mass properties of one link, in its link frame.
pub(super) struct LinkIn {
    pub(super) name: String,
    pub(super) mass: f64,
    pub(super) com: Vector3<f64>,
    pub(super) inertia: Matrix3<f64>,
}

/// The model under construction, shared with the extension readers.
pub(super) struct Builder {
    pub(super) model: Model,
    /// Link name → index in `model.links`.
    pub(super) link_index: HashMap<String, usize>,
    pub(super) link_in: Vec<LinkIn>,
    /// Links excluded from gravity.
    pub(super) no_gravity: Vec<usize>,
    pub(super) gravity_set: bool,
    pub(super) warnings: Vec<String>,
}

impl Builder {
    /// Body and `body_from_link` of a link named in `node`'s attribute `attr`; `world` names
    /// the fixed world frame even when the file declares no such link.
    pub(super) fn link_ref(
        &self,
        src: &Source,
        node: Node,
        attr: &str,
    ) -> Result<(Option<BodyId>, Isometry3<f64>)> {
        let name = src.req(node, attr)?;
        if name == "world" && !self.link_index.contains_key(name) {
            return Ok((None, Isometry3::identity()));
        }
        let i = self.link_index.get(name).ok_or_else(|| {
            src.error(
                node,
                format!("{} refers to an unknown link `{name}`", src.describe(node)),
            )
        })?;
        let l = &self.model.links[*i];
        Ok((l.body, l.body_from_link))
    }
}

/// Joint frame `J` with its z axis along `axis` (and x along the orthogonalized `axis2` for
/// a universal joint); the origin frame itself for joints without an axis.
pub(super) fn joint_axes(
    kind: JointKind,
    axis: Vector3<f64>,
    axis2: Vector3<f64>,
) -> UnitQuaternion<f64> {
    match kind {
        JointKind::Universal => {
            let x = (axis2 - axis * axis.dot(&axis2))
                .try_normalize(1e-9)
                .unwrap_or_else(|| align_z(&axis) * Vector3::x());
            let y = axis.cross(&x);
            let m = Matrix3::from_columns(&[x, y, axis]);
            UnitQuaternion::from_matrix(&m)
        }
        // No axis: J is the joint origin frame itself, so that spherical and floating joint
        // values are expressed in it.
        JointKind::Spherical
        | JointKind::Floating
        | JointKind::Fixed
        | JointKind::Distance { .. } => UnitQuaternion::identity(),
        _ => align_z(&axis),
    }
}

pub(super) fn repair_prefixes(
    text: &str,
    file: &str,
    warnings: &mut Vec<String>,
) -> Result<String> {
    if let Some(off) = text.find("<xacro:").or_else(|| text.find("${")) {
        let line = text[..off].matches('\n').count() as u32 + 1;
        let col = (off - text[..off].rfind('\n').map_or(0, |p| p + 1)) as u32 + 1;
        return Err(Error::Input {
            file: file.to_string(),
            line,
            col,
            message:
                "xacro macros are not expanded URDF: run `xacro FILE.urdf.xacro > FILE.urdf` first"
                    .into(),
        });
    }
    let mut out = text.to_string();
    for (prefix, uri) in [
        ("mech", super::xml::MECH_NS),
        ("drake", "http://drake.mit.edu"),
    ] {
        let used = out.contains(&format!("<{prefix}:"));
        let declared = out.contains(&format!("xmlns:{prefix}="));
        if used && !declared {
            if let Some(pos) = out.find("<robot") {
                let at = pos + "<robot".len();
                out.insert_str(at, &format!(" xmlns:{prefix}=\"{uri}\""));
                warnings.push(format!(
                    "{file}: the `{prefix}:` prefix is used but not declared; assumed xmlns:{prefix}=\"{uri}\""
                ));
            }
        }
    }
    Ok(out)
}

fn joint_kind(src: &Source, node: Node, ty: &str, warnings: &mut Vec<String>) -> Result<JointKind> {
    Ok(match ty {
        "revolute" => JointKind::Revolute,
        "continuous" => JointKind::Continuous,
        "prismatic" => JointKind::Prismatic,
        "fixed" => JointKind::Fixed,
        "floating" => JointKind::Floating,
        "planar" => JointKind::Planar,
        "spherical" => JointKind::Spherical,
        "ball" => {
            let p = src.doc.text_pos_at(node.range().start);
            warnings.push(format!(
                "{}:{}:{}: {} has type \"ball\", read as \"spherical\"",
                src.file,
                p.row,
                p.col,
                src.describe(node)
            ));
            JointKind::Spherical
        }
        other => {
            return Err(src.error(
                node,
                format!("{} has an unknown type \"{other}\"", src.describe(node)),
            ))
        }
    })
}

fn read_link(src: &Source, node: Node) -> Result<LinkIn> {
    let name = src.req(node, "name")?.to_string();
    let mut l = LinkIn {
        name,
        mass: 0.0,
        com: Vector3::zeros(),
        inertia: Matrix3::zeros(),
    };
    if let Some(inertial) = child(node, "inertial") {
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
            l.mass = mass;
        }
        l.com = origin.translation.vector;
        if let Some(i) = child(inertial, "inertia") {
            let g = |a: &str| src.f64_or(i, a, 0.0);
            let local = Matrix3::new(
                g("ixx")?,
                g("ixy")?,
                g("ixz")?,
                g("ixy")?,
                g("iyy")?,
                g("iyz")?,
                g("ixz")?,
                g("iyz")?,
                g("izz")?,
            );
            let r = origin.rotation.to_rotation_matrix();
            l.inertia = r.matrix() * local * r.matrix().transpose();
        }
    }
    Ok(l)
}

struct JointIn<'a> {
    node: Node<'a, 'a>,
    name: String,
    kind: JointKind,
    parent: String,
    child: String,
    origin: Isometry3<f64>,
    axis: Vector3<f64>,
    limits: Option<[f64; 2]>,
}

fn read_joint<'a>(
    src: &Source,
    node: Node<'a, 'a>,
    warnings: &mut Vec<String>,
) -> Result<JointIn<'a>> {
    let name = src.req(node, "name")?.to_string();
    let kind = joint_kind(src, node, src.req(node, "type")?, warnings)?;
    let link_of = |tag: &str| -> Result<String> {
        let c = child(node, tag)
            .ok_or_else(|| src.error(node, format!("joint `{name}` has no <{tag}> element")))?;
        Ok(src.req(c, "link")?.to_string())
    };
    let limits = match child(node, "limit") {
        Some(l) => {
            let lo = src.f64_opt(l, "lower")?;
            let hi = src.f64_opt(l, "upper")?;
            match (lo, hi) {
                (None, None) => None,
                (lo, hi) => Some([lo.unwrap_or(0.0), hi.unwrap_or(0.0)]),
            }
        }
        None => None,
    };
    Ok(JointIn {
        node,
        kind,
        parent: link_of("parent")?,
        child: link_of("child")?,
        origin: src.frame(child(node, "origin"))?,
        axis: src.axis(child(node, "axis"), node, Vector3::x())?,
        limits,
        name,
    })
}

pub(super) fn import(text: &str, file: &str, options: &ImportOptions) -> Result<Loaded> {
    let mut warnings = Vec::new();
    let text = repair_prefixes(text, file, &mut warnings)?;
    let popts = roxmltree::ParsingOptions {
        allow_dtd: true,
        ..Default::default()
    };
    let doc = roxmltree::Document::parse_with_options(&text, popts).map_err(|e| {
        let p = e.pos();
        Error::Input {
            file: file.to_string(),
            line: p.row,
            col: p.col,
            message: format!("not well-formed XML: {e}"),
        }
    })?;
    let src = Source { file, doc: &doc };
    let robot = doc.root_element();
    if robot.tag_name().name() != "robot" {
        return Err(src.error(
            robot,
            format!(
                "the root element is <{}>, not <robot>",
                robot.tag_name().name()
            ),
        ));
    }
    let mut link_nodes = Vec::new();
    let mut joint_nodes = Vec::new();
    let mut ext = Vec::new();
    let mut ignored = Vec::new();
    for c in robot.children().filter(|c| c.is_element()) {
        let name = c.tag_name().name();
        if is_mech(c) {
            ext.push(c);
        } else if c.tag_name().namespace().is_none() && name == "link" {
            link_nodes.push(c);
        } else if c.tag_name().namespace().is_none() && name == "joint" {
            joint_nodes.push(c);
        } else if !matches!(
            name,
            "material" | "transmission" | "gazebo" | "ros2_control"
        ) {
            let p = doc.text_pos_at(c.range().start);
            ignored.push(format!("{}:{} <{}>", p.row, p.col, name));
        }
    }

    // Links.
    let mut link_in = Vec::new();
    let mut link_index: HashMap<String, usize> = HashMap::new();
    for &n in &link_nodes {
        let l = read_link(&src, n)?;
        if link_index.insert(l.name.clone(), link_in.len()).is_some() {
            return Err(src.error(n, format!("duplicate link name `{}`", l.name)));
        }
        link_in.push(l);
    }
    if link_in.is_empty() {
        return Err(src.error(robot, "the robot has no <link>"));
    }

    // URDF joints and the tree.
    let mut joints_in = Vec::new();
    let mut joint_names: HashMap<String, ()> = HashMap::new();
    let mut parent_joint: Vec<Option<usize>> = vec![None; link_in.len()];
    let mut children: Vec<Vec<usize>> = vec![Vec::new(); link_in.len()];
    for &n in &joint_nodes {
        let j = read_joint(&src, n, &mut warnings)?;
        if joint_names.insert(j.name.clone(), ()).is_some() {
            return Err(src.error(n, format!("duplicate joint name `{}`", j.name)));
        }
        let find = |l: &str, role: &str| {
            link_index.get(l).copied().ok_or_else(|| {
                src.error(
                    n,
                    format!("joint `{}` refers to an unknown {role} link `{l}`", j.name),
                )
            })
        };
        let p = find(&j.parent, "parent")?;
        let c = find(&j.child, "child")?;
        if p == c {
            return Err(src.error(
                n,
                format!("joint `{}` joins link `{}` to itself", j.name, j.parent),
            ));
        }
        if let Some(other) = parent_joint[c] {
            return Err(src.error(
                n,
                format!(
                    "link `{}` is the child of two joints (`{}` and `{}`); close loops with mech:loop_joint",
                    j.child, joints_in.get(other).map_or("?", |o: &JointIn| o.name.as_str()), j.name
                ),
            ));
        }
        parent_joint[c] = Some(joints_in.len());
        children[p].push(joints_in.len());
        joints_in.push(j);
    }
    let roots: Vec<usize> = (0..link_in.len())
        .filter(|&i| parent_joint[i].is_none())
        .collect();
    if roots.len() > 1 {
        return Err(src.error(
            link_nodes[roots[1]],
            format!(
                "second root link `{}` (the tree already has root `{}`): every link but the root must be the child of a <joint>",
                link_in[roots[1]].name, link_in[roots[0]].name
            ),
        ));
    }
    let Some(&root) = roots.first() else {
        return Err(src.error(robot, "the URDF joints form a cycle: no root link"));
    };

    // Walk the tree: groups of links welded by fixed joints.
    let mut group: Vec<Option<usize>> = vec![None; link_in.len()];
    let mut body_from_link = vec![Isometry3::identity(); link_in.len()];
    let mut group_root: Vec<usize> = vec![root];
    group[root] = Some(0);
    let mut stack = vec![root];
    while let Some(l) = stack.pop() {
        for &ji in &children[l] {
            let j = &joints_in[ji];
            let c = link_index[&j.child];
            if j.kind == JointKind::Fixed {
                group[c] = group[l];
                body_from_link[c] = body_from_link[l] * j.origin;
            } else {
                group[c] = Some(group_root.len());
                group_root.push(c);
            }
            stack.push(c);
        }
    }
    if let Some(l) = (0..link_in.len()).find(|&l| group[l].is_none()) {
        return Err(src.error(
            link_nodes[l],
            format!("link `{}` is on a cycle of URDF joints", link_in[l].name),
        ));
    }
    // Group 0 is the world unless the base floats.
    let ground = !options.floating_base;
    let body_of_group = |g: usize| -> Option<BodyId> {
        if ground {
            g.checked_sub(1).map(BodyId)
        } else {
            Some(BodyId(g))
        }
    };
    let mut model = Model {
        name: robot.attribute("name").unwrap_or("robot").to_string(),
        bodies: Vec::new(),
        links: Vec::new(),
        joints: Vec::new(),
        springs: Vec::new(),
        joint_springs: Vec::new(),
        loads: Vec::new(),
        efforts: Vec::new(),
        locks: Vec::new(),
        mimics: Vec::new(),
        initial: Vec::new(),
        gravity: options.gravity,
        length_scale: 1.0,
    };
    for (g, &rl) in group_root.iter().enumerate() {
        if body_of_group(g).is_some() {
            model.bodies.push(Body {
                name: link_in[rl].name.clone(),
                mass: 0.0,
                com: Vector3::zeros(),
                inertia: Matrix3::zeros(),
                gravity_mass: 0.0,
                gravity_com: Vector3::zeros(),
            });
        }
    }
    for (i, l) in link_in.iter().enumerate() {
        let g = group[i].unwrap_or(0);
        model.links.push(Link {
            name: l.name.clone(),
            body: body_of_group(g),
            body_from_link: body_from_link[i],
        });
    }

    // Joints.
    for j in &joints_in {
        let p = link_index[&j.parent];
        let c = link_index[&j.child];
        let rot = joint_axes(j.kind, j.axis, Vector3::y());
        let frame_p = body_from_link[p] * j.origin * Isometry3::from_parts(Default::default(), rot);
        let frame_c = body_from_link[c] * Isometry3::from_parts(Default::default(), rot);
        let merged = j.kind == JointKind::Fixed;
        model.joints.push(Joint {
            name: j.name.clone(),
            kind: j.kind,
            parent_link: j.parent.clone(),
            child_link: j.child.clone(),
            bodies: [model.links[p].body, model.links[c].body],
            body_from_joint: [frame_p, frame_c],
            tree: true,
            merged,
            limits: j.limits,
        });
    }

    let mut b = Builder {
        model,
        link_index,
        link_in,
        no_gravity: Vec::new(),
        gravity_set: false,
        warnings,
    };
    extensions::read(
        &src,
        &ext,
        &joints_in
            .iter()
            .map(|j| (j.name.clone(), j.node))
            .collect::<Vec<_>>(),
        &mut b,
        options,
    )?;
    finish_mass(&mut b);
    b.model.length_scale = length_scale(&b.model);
    Ok(Loaded {
        model: b.model,
        warnings: b.warnings,
        ignored,
    })
}

/// Sums link masses into their bodies (parallel-axis theorem for the inertia).
fn finish_mass(b: &mut Builder) {
    let n = b.model.bodies.len();
    let mut m = vec![0.0; n];
    let mut mc = vec![Vector3::zeros(); n];
    let mut gm = vec![0.0; n];
    let mut gmc = vec![Vector3::zeros(); n];
    for (i, l) in b.link_in.iter().enumerate() {
        let link = &b.model.links[i];
        let Some(body) = link.body else { continue };
        let c = link.body_from_link * nalgebra::Point3::from(l.com);
        m[body.0] += l.mass;
        mc[body.0] += l.mass * c.coords;
        if !b.no_gravity.contains(&i) {
            gm[body.0] += l.mass;
            gmc[body.0] += l.mass * c.coords;
        }
    }
    for k in 0..n {
        let body = &mut b.model.bodies[k];
        body.mass = m[k];
        body.com = if m[k] > 0.0 {
            mc[k] / m[k]
        } else {
            Vector3::zeros()
        };
        body.gravity_mass = gm[k];
        body.gravity_com = if gm[k] > 0.0 {
            gmc[k] / gm[k]
        } else {
            Vector3::zeros()
        };
    }
    for (i, l) in b.link_in.iter().enumerate() {
        let link = &b.model.links[i];
        let Some(body) = link.body else { continue };
        let r = link.body_from_link.rotation.to_rotation_matrix();
        let c = (link.body_from_link * nalgebra::Point3::from(l.com)).coords
            - b.model.bodies[body.0].com;
        let parallel = l.mass * (Matrix3::identity() * c.dot(&c) - c * c.transpose());
        b.model.bodies[body.0].inertia +=
            r.matrix() * l.inertia * r.matrix().transpose() + parallel;
    }
}

/// Characteristic length: the largest offset of a joint frame, spring end or centre of mass
/// from its body origin (1 m if all are zero).
fn length_scale(model: &Model) -> f64 {
    let mut l: f64 = 0.0;
    for j in &model.joints {
        for f in &j.body_from_joint {
            l = l.max(f.translation.vector.norm());
        }
    }
    for b in &model.bodies {
        l = l.max(b.com.norm());
    }
    for s in &model.springs {
        for e in &s.ends {
            if e.body.is_some() {
                l = l.max(e.point.norm());
            }
        }
        l = l.max(s.free_length.abs());
    }
    if l > 0.0 {
        l
    } else {
        1.0
    }
}
