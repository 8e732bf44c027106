//! From the document to the model: the import pipeline, as calls on a [`ModelBuilder`].
//!
//! Text repair ([`super::text`]), the `mech:` schema check ([`super::schema`]), links and
//! their geometry ([`super::links`]), named frames, the joint graph ([`super::edges`]), its
//! spanning tree and bodies ([`super::tree`]), joint placement (here), then the extension
//! elements ([`super::extensions`], [`super::foreign`]); the builder validates and sums the
//! links' mass into their bodies.
//!
//! Joint placement: a joint's frame `J` in its parent body is
//! `body_from_link(parent) · origin · R_axis`, in its child body
//! `body_from_link(child) · child_origin · R_axis`, with `R_axis` turning z onto the axis.
//! The root link is welded to the world (its frame is the world frame) unless a floating base
//! is asked for.

use super::dom::Node;
use super::edges::{self, Declaration, Edge, FrameMap, Frames, DRAKE_NS};
use super::extensions;
use super::links::read_link;
use super::xml::{is_mech, Source};
use super::{ImportOptions, Loaded};
use crate::error::Result;
use crate::geometry::PackagePaths;
use crate::joint::Frame;
use crate::math::align_z;
use crate::model::{BodyId, Joint, JointId, JointKind, ModelBuilder};
use crate::names::NameMap;
use crate::state::State;
use nalgebra::{Isometry3, Matrix3, UnitQuaternion, Vector3};

/// The import context shared with the extension readers: the model builder and the names
/// it resolves.
pub(super) struct Builder {
    pub(super) model: ModelBuilder,
    /// Link name → index in the model's links.
    pub(super) link_index: NameMap<String, usize>,
    /// `mech:frame` name → (link index or world, link_from_frame).
    pub(super) frames: FrameMap,
    pub(super) gravity_set: bool,
    pub(super) warnings: Vec<String>,
    /// The file's own locks and initial values (`mech:lock`, `mech:initial`), before the
    /// command line's overrides: the start at which `<child_origin auto>` frames are placed.
    pub(super) file_start: (Vec<crate::model::Lock>, Vec<crate::model::Initial>),
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
        let (link, link_from_frame) =
            edges::resolve(&self.link_index, &self.frames, src, node, name)?;
        Ok(match link.and_then(|i| self.model.link(i)) {
            Some(l) => (l.body, l.body_from_link * link_from_frame),
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
    match kind.spec().frame {
        Frame::TwoAxes => {
            let x = (axis2 - axis * axis.dot(&axis2))
                .try_normalize(1e-9)
                .unwrap_or_else(|| align_z(&axis) * Vector3::x());
            let y = axis.cross(&x);
            let m = Matrix3::from_columns(&[x, y, axis]);
            UnitQuaternion::from_matrix(&m)
        }
        // No axis: J is the joint origin frame itself, so that spherical and floating joint
        // values are expressed in it.
        Frame::Origin => UnitQuaternion::identity(),
        Frame::Axis => align_z(&axis),
    }
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
    let mut repaired = None;
    let doc = super::text::parse(text, file, &mut warnings, &mut repaired)?;
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
    super::schema::check(&src, robot, &mut warnings)?;
    // Sized for every child element (no regrowth copies on large files).
    let children = robot.children().filter(|c| c.is_element()).count();
    let mut link_nodes = Vec::with_capacity(children);
    let mut joint_nodes = Vec::with_capacity(children);
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
    let mut link_in = Vec::with_capacity(link_nodes.len());
    let mut link_index: NameMap<String, usize> = NameMap::default();
    link_index.reserve(link_nodes.len());
    for &n in &link_nodes {
        let l = read_link(&src, n, &packages, options.inertia_density, &mut warnings)?;
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
        frames: NameMap::default(),
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
    let mut edges: Vec<Edge> = Vec::with_capacity(joint_nodes.len() + loop_nodes.len());
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
    let frames_map = std::mem::take(&mut frames.frames);
    let mut names: NameMap<&str, ()> = NameMap::default();
    names.reserve(edges.len());
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
        if e.source != Declaration::Loop {
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

    let tree = super::tree::spanning_tree(&edges, link_in.len(), root);
    if let Some(l) = (0..link_in.len()).find(|&l| !tree.reached[l]) {
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
    let groups = super::tree::group_links(&edges, &tree, link_in.len(), root);

    // Bodies (group 0, the root's, is the world unless the base floats) and links.
    let floating = options.floating_base;
    let mut model = ModelBuilder::new(robot.attribute("name").unwrap_or("robot"));
    model.reserve(groups.group_root.len(), link_in.len(), edges.len());
    model.set_gravity(options.gravity);
    let mut body_ids: Vec<Option<BodyId>> = Vec::with_capacity(groups.group_root.len());
    for (g, &rl) in groups.group_root.iter().enumerate() {
        body_ids.push((g > 0 || floating).then(|| model.add_body(link_in[rl].name.clone())));
    }
    let body_of = |l: usize| -> Option<BodyId> {
        if groups.world_welded[l] {
            None
        } else {
            body_ids[groups.group[l]]
        }
    };
    for (i, l) in link_in.into_iter().enumerate() {
        model.add_link(
            l.name,
            body_of(i),
            groups.body_from_link[i],
            l.inertial,
            l.visuals,
            l.collisions,
        );
        model.set_link_source(i, src.location(link_nodes[i]));
    }

    // Joints, in document order by kind of element.
    let mut auto_child = Vec::new();
    // URDF joints (for their <mimic>), by id.
    let mut urdf_joints: Vec<(JointId, Node)> = Vec::with_capacity(joint_nodes.len());
    for (k, e) in edges.into_iter().enumerate() {
        let place = |l: Option<usize>| {
            l.map_or((None, Isometry3::identity()), |l| {
                (body_of(l), groups.body_from_link[l])
            })
        };
        let (pb, pf) = place(e.parent);
        let (cb, cf) = place(e.child);
        let tree_edge = tree.in_tree[k];
        let merged = tree_edge && e.source == Declaration::Urdf && e.kind == JointKind::Fixed;
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
        let id = model.push_joint(Joint {
            name: e.name,
            kind: e.kind,
            parent_link: e.parent_link,
            child_link: e.child_link,
            bodies: [pb, cb],
            body_from_joint: [pf * e.origin * rot, cf * e.child_origin * rot],
            tree: tree_edge,
            merged,
            limits: e.limits,
            effort_limit: super::edges::effort_limit(&src, e.node),
            source: Some(src.location(e.node)),
        });
        if e.auto_child_origin {
            auto_child.push(id);
        }
        if e.source == Declaration::Urdf {
            urdf_joints.push((id, e.node));
        }
    }

    let mut b = Builder {
        model,
        link_index,
        frames: frames_map,
        gravity_set: false,
        warnings,
        file_start: Default::default(),
    };
    extensions::read(&src, &ext, &urdf_joints, &mut b, options)?;
    super::foreign::read(&src, &drake_nodes, &gazebo_nodes, &mut b)?;
    super::servo::add(&mut b, options)?;
    if !auto_child.is_empty() {
        // The child's joint frame that makes the joint hold at the file's initial guess: a
        // `--initial` or `--lock` of the command line chooses a start or a held value, and
        // does not move the joint in its links (`verify`, which has neither, then reads the
        // same mechanism).
        let mut own = b.model.partial().clone();
        let (locks, initial) = b.file_start.clone();
        (own.locks, own.initial) = (locks.into(), initial.into());
        let start = State::initial(&own);
        for &ji in &auto_child {
            let Some(j) = b.model.joint(ji) else { continue };
            let pose =
                |body: Option<BodyId>| body.map_or(Isometry3::identity(), |x| start.body_pose(x));
            let world_from_j = pose(j.bodies[0]) * j.body_from_joint[0];
            let f = pose(j.bodies[1]).inverse() * world_from_j;
            b.model.set_child_frame(ji, f);
        }
    }
    let model = b
        .model
        .build()
        .map_err(|e| locate_invalid(&src, robot, e))?;
    Ok(Loaded {
        model,
        warnings: b.warnings,
        ignored,
    })
}

/// Places a [`crate::Error::InvalidNumber`] of the built model at its element in the file: the
/// element named by it (a `name`, `joint` or `link` attribute), at its child element named
/// like the attribute when it has one (`<mass>`, `<inertia>`), else at `<robot>`. An
/// [`crate::Error::Model`] is placed by [`locate_model`].
fn locate_invalid(src: &Source, robot: Node, e: crate::Error) -> crate::Error {
    if let crate::Error::Model(message) = &e {
        return locate_model(src, robot, message);
    }
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
                .any(|a| n.attribute(a) == Some(name.as_str()))
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

/// Places a builder's message about an element (`link `arm` is selected for contact but has
/// no <collision> geometry`, `spring `s` …`) at that element: the first ``KIND `NAME` `` of
/// the message names it; a link's contact problem is placed at its `<mech:contact>`.
fn locate_model(src: &Source, robot: Node, message: &str) -> crate::Error {
    let mut parts = message.splitn(3, '`');
    let (head, name) = (parts.next().unwrap_or(""), parts.next().unwrap_or(""));
    let kind = head.split_whitespace().last().unwrap_or("");
    let tags: &[&str] = match kind {
        "link" if message.contains("contact") => &["contact", "link"],
        "link" => &["link", "obstacle"],
        "spring" => &["spring", "linear_spring_damper"],
        "joint" | "on" => &["joint", "loop_joint", "joint_spring", "joint_effort"],
        "load" => &["force"],
        "ground" => &["ground"],
        _ => &[],
    };
    let named = |n: &Node| {
        n.is_element()
            && !name.is_empty()
            && ["name", "joint", "link"]
                .iter()
                .any(|a| n.attribute(a) == Some(name))
    };
    let node = tags
        .iter()
        .find_map(|t| {
            robot
                .descendants()
                .find(|n| named(n) && n.tag_name().name() == *t)
        })
        .or_else(|| robot.descendants().find(|n| named(n)))
        .unwrap_or(robot);
    src.error(node, message.to_string())
}
