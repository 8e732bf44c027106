//! From the document to the model: links, the joint graph and its spanning tree, bodies.
//!
//! URDF `<joint>`s, `<drake:joint>`s and the loop elements (`mech:loop_joint`, `<loop_joint>`,
//! `<drake:ball_constraint>`) form one graph. The spanning tree grows from the root link along
//! URDF and Drake joints first; a link they do not reach is reached through a loop element
//! whose parent is already placed, which then becomes a tree edge. Every other edge closes a
//! loop. Links joined by URDF `fixed` tree joints form one rigid body whose frame is the frame
//! of its topmost link; `body_from_link` composes the fixed joint origins. The root link is
//! welded to the world (its frame is the world frame) unless a floating base is asked for.

use super::edges::{self, Edge, Frames, Source_, DRAKE_NS};
use super::extensions;
use super::xml::{child, is_mech, Source};
use super::{ImportOptions, Loaded};
use crate::error::{Error, Result};
use crate::geometry::{Geometry, PackagePaths, ShapeKind};
use crate::math::align_z;
use crate::model::{Body, BodyId, Joint, JointKind, Link, Model};
use nalgebra::{Isometry3, Matrix3, UnitQuaternion, Vector3};
use roxmltree::Node;
use std::collections::HashMap;

/// Mass properties and geometry of one link, in its link frame.
pub(super) struct LinkIn {
    pub(super) name: String,
    pub(super) mass: f64,
    pub(super) com: Vector3<f64>,
    pub(super) inertia: Matrix3<f64>,
    pub(super) has_inertial: bool,
    pub(super) visuals: Vec<Geometry>,
    pub(super) collisions: Vec<Geometry>,
}

/// The model under construction, shared with the extension readers.
pub(super) struct Builder {
    pub(super) model: Model,
    /// Link name → index in `model.links`.
    pub(super) link_index: HashMap<String, usize>,
    /// `mech:frame` name → (link index or world, link_from_frame).
    pub(super) frames: HashMap<String, (Option<usize>, Isometry3<f64>)>,
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
        let frames = Frames {
            links: &self.link_index,
            frames: self.frames.clone(),
        };
        let (link, link_from_frame) = frames.resolve(src, node, name)?;
        Ok(match link {
            Some(i) => {
                let l = &self.model.links[i];
                (l.body, l.body_from_link * link_from_frame)
            }
            None => (None, link_from_frame),
        })
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

/// The xacro hint.
const XACRO: &str =
    "xacro macros are not expanded URDF: run `xacro FILE.urdf.xacro > FILE.urdf` first";

/// Declares an undeclared `mech:` or `drake:` prefix (with a warning) and refuses xacro, by
/// parsing: a prefix only counts where the XML parser meets it, not in comments.
pub(super) fn repair_prefixes(
    text: &str,
    file: &str,
    warnings: &mut Vec<String>,
) -> Result<String> {
    let mut out = text.to_string();
    let popts = roxmltree::ParsingOptions {
        allow_dtd: true,
        ..Default::default()
    };
    for _ in 0..3 {
        let (prefix, pos) = match roxmltree::Document::parse_with_options(&out, popts) {
            Err(roxmltree::Error::UnknownNamespace(prefix, pos)) => (prefix, pos),
            Err(_) => return Ok(out),
            Ok(doc) => {
                for n in doc.descendants().filter(|n| n.is_element()) {
                    let xacro = n
                        .tag_name()
                        .namespace()
                        .is_some_and(|u| u.contains("xacro"));
                    if xacro || n.attributes().any(|a| a.value().contains("${")) {
                        let p = doc.text_pos_at(n.range().start);
                        return Err(Error::Input {
                            file: file.to_string(),
                            line: p.row,
                            col: p.col,
                            message: XACRO.into(),
                        });
                    }
                }
                return Ok(out);
            }
        };
        let uri = match prefix.as_str() {
            "mech" => super::xml::MECH_NS,
            "drake" => super::edges::DRAKE_NS,
            "xacro" => {
                return Err(Error::Input {
                    file: file.to_string(),
                    line: pos.row,
                    col: pos.col,
                    message: XACRO.into(),
                })
            }
            _ => return Ok(out),
        };
        let Some(at) = out.find("<robot").map(|p| p + "<robot".len()) else {
            return Ok(out);
        };
        out.insert_str(at, &format!(" xmlns:{prefix}=\"{uri}\""));
        warnings.push(format!("{file}: the `{prefix}:` prefix is used but not declared; assumed xmlns:{prefix}=\"{uri}\""));
    }
    Ok(out)
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
        Ok(v)
    };
    let shape = match s.tag_name().name() {
        "box" => {
            let size = src
                .vec3_opt(s, "size")?
                .ok_or_else(|| src.error(s, format!("link `{link}`: <box> needs `size`")))?;
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
            let scale = src.vec3_or(s, "scale", Vector3::new(1.0, 1.0, 1.0))?;
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

fn read_link(
    src: &Source,
    node: Node,
    packages: &PackagePaths,
    warnings: &mut Vec<String>,
) -> Result<LinkIn> {
    let name = src.req(node, "name")?.to_string();
    let mut l = LinkIn {
        has_inertial: child(node, "inertial").is_some(),
        visuals: Vec::new(),
        collisions: Vec::new(),
        name,
        mass: 0.0,
        com: Vector3::zeros(),
        inertia: Matrix3::zeros(),
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
            if let Some(why) = inertia_problem(&local) {
                warnings.push(src.warning(
                    i,
                    format!("link `{}`: the inertia tensor is not physically valid ({why}); statics does not use it", l.name),
                ));
            }
        }
    }
    Ok(l)
}

/// Why an inertia tensor is not physically valid (a principal moment negative, or one larger
/// than the sum of the other two), if it is not.
fn inertia_problem(i: &Matrix3<f64>) -> Option<String> {
    let Some(e) = nalgebra::SymmetricEigen::try_new(*i, f64::EPSILON, 1000).map(|e| e.eigenvalues)
    else {
        return Some("its eigenvalues cannot be computed".into());
    };
    let tol = 1e-9 * e.amax().max(f64::MIN_POSITIVE);
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

pub(super) fn import(
    text: &str,
    file: &str,
    urdf_dir: Option<std::path::PathBuf>,
    options: &ImportOptions,
) -> Result<Loaded> {
    let packages = PackagePaths {
        explicit: options.packages.clone(),
        urdf_dir,
    };
    let mut warnings = Vec::new();
    let text = repair_prefixes(text, file, &mut warnings)?;
    let doc = super::xml::parse_document(&text, file)?;
    let src = Source::new(file, &doc);
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
    let mut loop_nodes = Vec::new();
    let mut drake_nodes = Vec::new();
    let mut gazebo_nodes = Vec::new();
    let mut ext = Vec::new();
    let mut ignored = Vec::new();
    for c in robot.children().filter(|c| c.is_element()) {
        let name = c.tag_name().name();
        let ns = c.tag_name().namespace();
        if is_mech(c) {
            ext.push(c);
        } else if ns == Some(DRAKE_NS) {
            drake_nodes.push(c);
        } else if ns.is_none() && name == "link" {
            link_nodes.push(c);
        } else if ns.is_none() && name == "joint" {
            joint_nodes.push(c);
        } else if ns.is_none() && name == "loop_joint" {
            loop_nodes.push(c);
        } else if ns.is_none() && name == "gazebo" {
            gazebo_nodes.push(c);
        } else if !matches!(name, "material" | "transmission" | "ros2_control") {
            let (row, col) = src.pos(c);
            ignored.push(format!("{row}:{col} <{name}>"));
        }
    }

    // Links and named frames.
    let mut link_in = Vec::new();
    let mut link_index: HashMap<String, usize> = HashMap::new();
    for &n in &link_nodes {
        let mut l = read_link(&src, n, &packages, &mut warnings)?;
        if let (Some(density), false) = (options.inertia_density, l.has_inertial) {
            let shapes = if l.collisions.is_empty() {
                &l.visuals
            } else {
                &l.collisions
            };
            if !shapes.is_empty() {
                match crate::geometry::mass_properties(shapes, density) {
                    Ok((m, c, i)) => (l.mass, l.com, l.inertia) = (m, c, i),
                    Err(why) => {
                        warnings.push(src.warning(
                            n,
                            format!("link `{}`: no mass from geometry: {why}", l.name),
                        ));
                    }
                }
            }
        }
        if link_index.insert(l.name.clone(), link_in.len()).is_some() {
            return Err(src.error(n, format!("duplicate link name `{}`", l.name)));
        }
        link_in.push(l);
    }
    if link_in.is_empty() {
        return Err(src.error(robot, "the robot has no <link>"));
    }
    let mut frames = Frames {
        links: &link_index,
        frames: HashMap::new(),
    };
    for &n in ext.iter().filter(|n| n.tag_name().name() == "frame") {
        let name = src.req(n, "name")?;
        let base = src.req(n, "link")?;
        let (link, f) = frames.resolve(&src, n, base)?;
        if link_index.contains_key(name) || frames.frames.contains_key(name) {
            return Err(src.error(
                n,
                format!("frame `{name}` has the name of another link or frame"),
            ));
        }
        frames
            .frames
            .insert(name.to_string(), (link, f * src.frame(Some(n))?));
    }

    // The joint graph, URDF and Drake joints first.
    let mut edges: Vec<Edge> = Vec::new();
    for &n in &joint_nodes {
        edges.push(edges::urdf_joint(&src, n, &frames, &mut warnings)?);
    }
    for &n in drake_nodes
        .iter()
        .filter(|n| n.tag_name().name() == "joint")
    {
        edges.push(edges::drake_joint(&src, n, &frames)?);
    }
    for &n in ext.iter().filter(|n| n.tag_name().name() == "loop_joint") {
        edges.push(edges::mech_loop_joint(&src, n, &frames)?);
    }
    for &n in &loop_nodes {
        edges.push(edges::foreign_loop_joint(&src, n, &frames)?);
    }
    for (k, &n) in drake_nodes
        .iter()
        .filter(|n| n.tag_name().name() == "ball_constraint")
        .enumerate()
    {
        edges.push(edges::drake_ball_constraint(&src, n, &frames, k)?);
    }
    for &n in drake_nodes.iter().filter(|n| {
        !matches!(
            n.tag_name().name(),
            "joint" | "ball_constraint" | "linear_spring_damper"
        )
    }) {
        let (row, col) = src.pos(n);
        ignored.push(format!("{row}:{col} <drake:{}>", n.tag_name().name()));
    }
    let frames_map = frames.frames.clone();
    let mut names: HashMap<&str, ()> = HashMap::new();
    let mut preferred_parent: Vec<Option<usize>> = vec![None; link_in.len()];
    for (k, e) in edges.iter().enumerate() {
        if names.insert(e.name.as_str(), ()).is_some() {
            return Err(src.error(e.node, format!("duplicate joint name `{}`", e.name)));
        }
        if e.parent == e.child {
            return Err(src.error(
                e.node,
                format!(
                    "joint `{}` joins link `{}` to itself",
                    e.name, e.parent_link
                ),
            ));
        }
        if e.source != Source_::Loop {
            let Some(c) = e.child else {
                return Err(src.error(
                    e.node,
                    format!(
                        "joint `{}` has the world as its child; swap parent and child",
                        e.name
                    ),
                ));
            };
            if let Some(other) = preferred_parent[c] {
                return Err(src.error(
                    e.node,
                    format!(
                        "link `{}` is the child of two joints (`{}` and `{}`); close loops with mech:loop_joint",
                        e.child_link, edges[other].name, e.name
                    ),
                ));
            }
            preferred_parent[c] = Some(k);
        }
    }
    let candidates: Vec<usize> = (0..link_in.len())
        .filter(|&i| preferred_parent[i].is_none())
        .collect();
    let Some(&root) = candidates
        .iter()
        .find(|&&i| link_in[i].name == "world")
        .or(candidates.first())
    else {
        return Err(src.error(robot, "the URDF joints form a cycle: no root link"));
    };

    // Spanning tree: breadth first from the root (and the undeclared world), preferred edges
    // first, then loop elements whose parent is placed.
    let mut reached = vec![false; link_in.len()];
    let mut tree_order: Vec<usize> = Vec::new();
    reached[root] = true;
    let mut queue: std::collections::VecDeque<Option<usize>> =
        [None, Some(root)].into_iter().collect();
    loop {
        while let Some(l) = queue.pop_front() {
            for (k, e) in edges.iter().enumerate() {
                if e.source != Source_::Loop && e.parent == l {
                    if let Some(c) = e.child.filter(|&c| !reached[c]) {
                        reached[c] = true;
                        tree_order.push(k);
                        queue.push_back(Some(c));
                    }
                }
            }
        }
        let next = edges.iter().enumerate().find(|(k, e)| {
            e.source == Source_::Loop
                && !tree_order.contains(k)
                && e.parent.is_none_or(|p| reached[p])
                && e.child.is_some_and(|c| !reached[c])
        });
        match next {
            Some((k, e)) => {
                let c = e.child.unwrap_or(root);
                reached[c] = true;
                tree_order.push(k);
                queue.push_back(Some(c));
            }
            None => break,
        }
    }
    if let Some(l) = (0..link_in.len()).find(|&l| !reached[l]) {
        let message = if preferred_parent[l].is_none() {
            format!(
                "second root link `{}` (the tree already has root `{}`): every link but the root must be the child of a <joint> or be reached through a loop joint",
                link_in[l].name, link_in[root].name
            )
        } else {
            format!(
                "link `{}` is on a cycle of URDF joints, not connected to the root `{}`",
                link_in[l].name, link_in[root].name
            )
        };
        return Err(src.error(link_nodes[l], message));
    }

    // Bodies: groups of links welded by URDF fixed tree joints. Group 0 holds the root.
    let mut group: Vec<usize> = vec![0; link_in.len()];
    let mut body_from_link = vec![Isometry3::identity(); link_in.len()];
    let mut group_root: Vec<usize> = vec![root];
    let mut world_welded = vec![false; link_in.len()];
    for &k in &tree_order {
        let e = &edges[k];
        let Some(c) = e.child else { continue };
        if e.source == Source_::Urdf && e.kind == JointKind::Fixed {
            match e.parent {
                Some(p) => {
                    group[c] = group[p];
                    body_from_link[c] = body_from_link[p] * e.origin;
                    world_welded[c] = world_welded[p];
                }
                None => {
                    group[c] = 0;
                    body_from_link[c] = e.origin;
                    world_welded[c] = true;
                }
            }
        } else {
            group[c] = group_root.len();
            group_root.push(c);
        }
    }
    let floating = options.floating_base;
    let body_of = |l: usize| -> Option<BodyId> {
        if world_welded[l] || (!floating && group[l] == 0) {
            None
        } else if floating {
            Some(BodyId(group[l]))
        } else {
            Some(BodyId(group[l] - 1))
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
        joint_names: Default::default(),
    };
    for (g, &rl) in group_root.iter().enumerate() {
        if g > 0 || floating {
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
        model.links.push(Link {
            name: l.name.clone(),
            body: body_of(i),
            body_from_link: body_from_link[i],
            visuals: l.visuals.clone(),
            collisions: l.collisions.clone(),
        });
    }

    // Joints, in document order by kind of element.
    let mut auto_child = Vec::new();
    for (k, e) in edges.iter().enumerate() {
        let place = |l: Option<usize>| {
            l.map_or((None, Isometry3::identity()), |l| {
                (body_of(l), body_from_link[l])
            })
        };
        let (pb, pf) = place(e.parent);
        let (cb, cf) = place(e.child);
        let tree = tree_order.contains(&k);
        let merged = tree && e.source == Source_::Urdf && e.kind == JointKind::Fixed;
        if !merged && pb == cb {
            return Err(src.error(
                e.node,
                format!(
                    "joint `{}` joins body `{}` to itself (links `{}` and `{}` are welded)",
                    e.name, e.parent_link, e.parent_link, e.child_link
                ),
            ));
        }
        let rot = Isometry3::from_parts(Default::default(), joint_axes(e.kind, e.axis, e.axis2));
        if e.auto_child_origin {
            auto_child.push(model.joints.len());
        }
        model.joints.push(Joint {
            name: e.name.clone(),
            kind: e.kind,
            parent_link: e.parent_link.clone(),
            child_link: e.child_link.clone(),
            bodies: [pb, cb],
            body_from_joint: [pf * e.origin * rot, cf * e.child_origin * rot],
            tree,
            merged,
            limits: e.limits,
        });
    }

    model.index_names();
    let urdf_joints: Vec<(String, Node)> = edges
        .iter()
        .filter(|e| e.source == Source_::Urdf)
        .map(|e| (e.name.clone(), e.node))
        .collect();
    let mut b = Builder {
        model,
        link_index: link_index.clone(),
        frames: frames_map,
        link_in,
        no_gravity: Vec::new(),
        gravity_set: false,
        warnings,
    };
    extensions::read(&src, &ext, &urdf_joints, &mut b, options)?;
    super::foreign::read(&src, &drake_nodes, &gazebo_nodes, &mut b)?;
    if !auto_child.is_empty() {
        // The child's joint frame that makes the joint hold at the initial guess.
        let start = crate::solver::initial_state(&b.model);
        for &ji in &auto_child {
            let j = &b.model.joints[ji];
            let pose =
                |body: Option<BodyId>| body.map_or(Isometry3::identity(), |x| start.body_pose(x));
            let world_from_j = pose(j.bodies[0]) * j.body_from_joint[0];
            let f = pose(j.bodies[1]).inverse() * world_from_j;
            b.model.joints[ji].body_from_joint[1] = f;
        }
    }
    finish_mass(&mut b);
    b.model.length_scale = length_scale(&b.model);
    b.model
        .check_numbers()
        .map_err(|e| locate_invalid(&src, robot, e))?;
    Ok(Loaded {
        model: b.model,
        warnings: b.warnings,
        ignored,
    })
}

/// Places a [`crate::Error::InvalidNumber`] of the built model at its element in the file: the
/// element named by it (a `name`, `joint` or `link` attribute), at its child element named
/// like the attribute when it has one (`<mass>`, `<inertia>`), else at `<robot>`.
fn locate_invalid(src: &Source, robot: Node, e: crate::Error) -> crate::Error {
    let crate::Error::InvalidNumber {
        name, attribute, ..
    } = &e
    else {
        return e;
    };
    let named = |n: &Node| {
        n.is_element()
            && !name.is_empty()
            && ["name", "joint", "link"]
                .iter()
                .any(|a| n.attribute(*a) == Some(name.as_str()))
    };
    let element = robot
        .descendants()
        .find(|n| named(n) && n.has_attribute(attribute.as_str()))
        .or_else(|| robot.descendants().find(|n| named(n)));
    let node = element
        .and_then(|n| {
            n.descendants()
                .find(|c| c.is_element() && c.tag_name().name() == attribute.as_str())
        })
        .or(element)
        .unwrap_or(robot);
    src.error(node, e.to_string())
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
