//! The `mech:` extension elements (`urn:urdf-mech:1`) and URDF `<mimic>`.
//!
//! Loop joints and frames are part of the joint graph ([`super::edges`]); here: gravity,
//! springs, joint springs, loads, efforts, locks and initial values. Command-line locks and
//! initial values override the file's.

use super::dom::Node;
use super::import::Builder;
use super::xml::{child, Source};
use super::ImportOptions;
use crate::error::Result;
use crate::model::{
    ContactSettings, Effort, ForceLaw, Friction, Ground, Initial, JointId, JointSpring, Load, Lock,
    Mimic, Spring, SpringEnd, SpringMode,
};
use nalgebra::Vector3;

fn force_law(src: &Source, node: Node, what: &dyn std::fmt::Display) -> Result<ForceLaw> {
    let stiffness = src.f64_opt(node, "stiffness")?;
    let preload = src.f64_or(node, "preload", 0.0)?;
    match (child(node, "force_deflection"), stiffness) {
        (Some(fd), None) => {
            let extrapolate = fd.attribute("extrapolate").unwrap_or("linear");
            let (extrapolate_linear, bounded) = match extrapolate {
                "linear" => (true, false),
                "clamp" => (false, false),
                "error" => (false, true),
                other => {
                    return Err(src.error(
                        fd,
                        format!("{what}: extrapolate=\"{other}\" is not linear, clamp or error"),
                    ))
                }
            };
            if let Some(i) = fd.attribute("interpolation") {
                if i != "linear" {
                    return Err(src.error(
                        fd,
                        format!("{what}: interpolation=\"{i}\" is not supported (only linear)"),
                    ));
                }
            }
            let mut points = Vec::new();
            for p in fd
                .children()
                .filter(|c| c.is_element() && c.tag_name().name() == "point")
            {
                let d = src
                    .f64_opt(p, "deflection")?
                    .ok_or_else(|| src.error(p, format!("{what}: <point> needs `deflection`")))?;
                let f = src
                    .f64_opt(p, "force")?
                    .ok_or_else(|| src.error(p, format!("{what}: <point> needs `force`")))?;
                if let Some(&(last, _)) = points.last() {
                    if d <= last {
                        return Err(src.error(
                            p,
                            format!(
                                "{what}: deflections must increase strictly ({d} after {last})"
                            ),
                        ));
                    }
                }
                points.push((d, f + preload));
            }
            if points.len() < 2 {
                return Err(src.error(
                    fd,
                    format!("{what}: <force_deflection> needs at least two <point> rows"),
                ));
            }
            Ok(ForceLaw::Table {
                points,
                extrapolate_linear,
                bounded,
            })
        }
        (Some(fd), Some(_)) => Err(src.error(
            fd,
            format!("{what}: give either `stiffness` or <force_deflection>, not both"),
        )),
        (None, Some(k)) => Ok(ForceLaw::Linear {
            stiffness: k,
            preload,
        }),
        (None, None) => Err(src.error(
            node,
            format!("{what} needs `stiffness` or <force_deflection>"),
        )),
    }
}

/// A joint coordinate named by `joint` and `dof` attributes.
fn joint_coord(src: &Source, node: Node, b: &Builder) -> Result<(JointId, usize)> {
    let name = src.req(node, "joint")?;
    let id = b.model.joint_id(name).ok_or_else(|| {
        src.error(
            node,
            format!("{} refers to an unknown joint `{name}`", src.describe(node)),
        )
    })?;
    let dof = src.f64_or(node, "dof", 0.0)?;
    let kind = b.model.partial().joints[id.0].kind;
    let n = kind.scalar_coordinates();
    if dof < 0.0 || dof.fract() != 0.0 || dof as usize >= n {
        return Err(src.error(
            node,
            format!("{}: joint `{name}` ({}) has {n} addressable coordinate(s); dof {dof} is out of range", src.describe(node), kind.name()),
        ));
    }
    Ok((id, dof as usize))
}

pub(super) fn read(
    src: &Source,
    ext: &[Node],
    urdf_joints: &[(JointId, Node)],
    b: &mut Builder,
    options: &ImportOptions,
) -> Result<()> {
    // URDF mimic.
    for &(id, node) in urdf_joints {
        if let Some(m) = child(node, "mimic") {
            let target = src.req(m, "joint")?;
            let name = b
                .model
                .joint(id)
                .map(|j| j.name.clone())
                .ok_or_else(|| src.error(m, "mimic on an unknown joint"))?;
            // urdfdom loads a mimic of a missing joint, and a mimic on or of a joint without a
            // scalar coordinate: the joint is then independent.
            let Some(reference) = b.model.joint_id(target) else {
                let w = src.warning(
                    m,
                    format!(
                        "joint `{name}` mimics an unknown joint `{target}`; <mimic> ignored (the joint is independent)"
                    ),
                );
                b.warnings.push(w);
                continue;
            };
            if let Some((jid, role)) = [(id, "mimicking"), (reference, "mimicked")]
                .into_iter()
                .find(|(jid, _)| b.model.partial().joints[jid.0].kind.scalar_coordinates() == 0)
            {
                let j = &b.model.partial().joints[jid.0];
                let w = src.warning(
                    m,
                    format!(
                        "{role} joint `{}` ({}) has no scalar coordinate; <mimic> ignored",
                        j.name,
                        j.kind.name()
                    ),
                );
                b.warnings.push(w);
                continue;
            }
            let multiplier = src.f64_or(m, "multiplier", 1.0)?;
            let offset = src.f64_or(m, "offset", 0.0)?;
            src.within(
                m,
                "multiplier",
                &[multiplier],
                crate::model::LARGEST_MAGNITUDE,
            )?;
            src.within(m, "offset", &[offset], crate::model::LARGEST_LENGTH)?;
            b.model.add_mimic(Mimic {
                joint: id,
                reference,
                multiplier,
                offset,
            });
        }
    }
    // Mimic cycles: the first mimic (in order) whose joint its reference leads back to.
    if let Some(cur) =
        super::mimic::first_on_cycle(b.model.mimics(), b.model.partial().joints.len())
    {
        let name = &b.model.partial().joints[cur.0].name;
        let node = urdf_joints.iter().find(|(j, _)| *j == cur).map(|(_, n)| *n);
        let at = node
            .and_then(|n| child(n, "mimic"))
            .or(node)
            .unwrap_or(ext.first().copied().unwrap_or(src.doc.root_element()));
        return Err(src.error(at, format!("mimic cycle through joint `{name}`")));
    }
    let mut locks: Vec<Lock> = Vec::new();
    let mut initial: Vec<Initial> = Vec::new();
    for &n in ext {
        // Described only when a message needs it (most files need none).
        let what = src.described(n);
        match n.tag_name().name() {
            "gravity" => {
                let g = src
                    .vec3_opt(n, "xyz")?
                    .ok_or_else(|| src.error(n, "<mech:gravity> needs `xyz`"))?;
                b.model.set_gravity(g);
                b.gravity_set = true;
            }
            "link_gravity" => {
                let name = src.req(n, "link")?;
                let i = *b.link_index.get(name).ok_or_else(|| {
                    src.error(
                        n,
                        format!("<mech:link_gravity> refers to an unknown link `{name}`"),
                    )
                })?;
                if !src.bool_opt(n, "enabled")?.unwrap_or(true) {
                    b.model.exclude_from_gravity(i);
                }
            }
            "spring" => {
                let name = src.req(n, "name")?.to_string();
                let ends: Vec<Node> = n
                    .children()
                    .filter(|c| c.is_element() && c.tag_name().name() == "end")
                    .collect();
                if ends.len() != 2 {
                    return Err(src.error(
                        n,
                        format!(
                            "spring `{name}` needs exactly two <end> elements, found {}",
                            ends.len()
                        ),
                    ));
                }
                let mut se = Vec::new();
                for e in ends {
                    let (body, bfl) = b.link_ref(src, e, "link")?;
                    let p = bfl
                        * nalgebra::Point3::from(src.position_or(e, "xyz", Vector3::zeros())?);
                    se.push(SpringEnd {
                        body,
                        point: p.coords,
                    });
                }
                let free_length = src
                    .f64_opt(n, "free_length")?
                    .ok_or_else(|| src.error(n, format!("spring `{name}` needs `free_length`")))?;
                if free_length < 0.0 {
                    return Err(src.error(
                        n,
                        format!("spring `{name}` has a negative free length {free_length} m"),
                    ));
                }
                let mode = match n.attribute("mode").unwrap_or("both") {
                    "both" => SpringMode::Both,
                    "tension" => SpringMode::Tension,
                    "compression" => SpringMode::Compression,
                    other => {
                        return Err(src.error(
                            n,
                            format!(
                            "spring `{name}`: mode=\"{other}\" is not both, tension or compression"
                        ),
                        ))
                    }
                };
                let law = force_law(src, n, &format!("spring `{name}`"))?;
                let ends = [se[0].clone(), se[1].clone()];
                if let Some(w) = super::foreign::coincident_ends(&name, &ends) {
                    b.warnings.push(src.warning(n, w));
                }
                b.model.add_spring(Spring {
                    name,
                    ends,
                    free_length,
                    law,
                    mode,
                });
            }
            "joint_spring" => {
                let (joint, dof) = joint_coord(src, n, b)?;
                let law = force_law(src, n, &what)?;
                let reference = src.f64_or(n, "reference", 0.0)?;
                b.model.push_joint_spring(JointSpring {
                    joint,
                    dof,
                    reference,
                    law,
                });
            }
            "force" => {
                let name = src.req(n, "name")?.to_string();
                if n.attribute("frame").is_some_and(|f| f != "world") {
                    return Err(src.error(n, format!(
                        "force `{name}`: frame=\"{}\" makes a follower load, which has no potential energy; restpose minimizes energy and accepts only world-frame (dead) loads",
                        n.attribute("frame").unwrap_or_default()
                    )));
                }
                let torque = src.vec3_or(n, "torque", Vector3::zeros())?;
                if torque != Vector3::zeros() {
                    return Err(src.error(n, format!(
                        "force `{name}`: a constant world-frame torque on a body that rotates in 3-D does path-dependent work (no potential energy); use <mech:joint_effort> for a torque about a joint axis, or a pair of forces"
                    )));
                }
                let (body, bfl) = b.link_ref(src, n, "link")?;
                let point =
                    bfl * nalgebra::Point3::from(src.position_or(n, "xyz", Vector3::zeros())?);
                let force = src.vec3_or(n, "force", Vector3::zeros())?;
                if let Some(body) = body {
                    b.model.add_load(Load {
                        name,
                        body,
                        point: point.coords,
                        force,
                    });
                }
            }
            "joint_effort" => {
                let (joint, dof) = joint_coord(src, n, b)?;
                let value = src
                    .f64_opt(n, "value")?
                    .ok_or_else(|| src.error(n, format!("{what} needs `value`")))?;
                b.model.add_effort(Effort { joint, dof, value });
            }
            "obstacle" => {
                let name = src.req(n, "link")?;
                let i = *b.link_index.get(name).ok_or_else(|| {
                    src.error(n, format!("{what} refers to an unknown link `{name}`"))
                })?;
                b.model
                    .add_obstacle(i)
                    .map_err(|e| src.error(n, e.to_string()))?;
            }
            "base" => {
                let pose = src.frame(Some(n))?;
                b.model.set_base_pose(pose);
            }
            "ground" => {
                let name = n.attribute("name").unwrap_or("floor");
                let origin = src.position_or(n, "xyz", Vector3::zeros())?;
                let normal = src.position_or(n, "normal", Vector3::z())?;
                b.model
                    .add_ground(name, origin, normal)
                    .map_err(|e| src.error(n, e.to_string()))?;
            }
            "contact" => {
                let name = src.req(n, "link")?;
                let i = *b.link_index.get(name).ok_or_else(|| {
                    src.error(n, format!("{what} refers to an unknown link `{name}`"))
                })?;
                let friction = match n.attribute("friction") {
                    None => None,
                    Some("none") => Some(Friction::None),
                    Some("stick") => Some(Friction::Stick),
                    Some(other) => {
                        return Err(src.error(
                            n,
                            format!("{what}: friction=\"{other}\" is not none or stick"),
                        ))
                    }
                };
                let mu = src.f64_opt(n, "mu")?;
                if mu.is_some_and(|m| m < 0.0) {
                    return Err(src.error(n, format!("{what}: mu must not be negative")));
                }
                let touches = src.bool_opt(n, "enabled")?.unwrap_or(true);
                b.model
                    .set_contact(i, touches, ContactSettings { friction, mu });
            }
            "lock" => {
                let (joint, dof) = joint_coord(src, n, b)?;
                locks.push(Lock {
                    joint,
                    dof,
                    value: src.f64_opt(n, "value")?,
                });
            }
            "initial" => {
                let list = n
                    .attribute("value")
                    .map(|v| v.split_whitespace().count())
                    .unwrap_or(0);
                if list > 1 {
                    // restpose's extension: the whole coordinate vector of the joint, as in the
                    // result JSON (a quaternion w x y z for a spherical joint).
                    let name = src.req(n, "joint")?;
                    let joint = b.model.joint_id(name).ok_or_else(|| {
                        src.error(n, format!("{what} refers to an unknown joint `{name}`"))
                    })?;
                    let kind = b.model.partial().joints[joint.0].kind;
                    let expected = kind.position_len();
                    if list != expected || n.attribute("dof").is_some() {
                        return Err(src.error(n, format!(
                            "{what}: joint `{name}` ({}) takes {expected} values in a list `value` without `dof`, got {list}",
                            kind.name()
                        )));
                    }
                    let values: Vec<f64> = n
                        .attribute("value")
                        .unwrap_or_default()
                        .split_whitespace()
                        .map(super::xml::parse_f64)
                        .collect::<Option<_>>()
                        .ok_or_else(|| {
                            src.error(n, format!("{what}: `value` must be finite numbers"))
                        })?;
                    for (dof, value) in values.into_iter().enumerate() {
                        initial.push(Initial { joint, dof, value });
                    }
                } else {
                    let (joint, dof) = joint_coord(src, n, b)?;
                    let value = src
                        .f64_opt(n, "value")?
                        .ok_or_else(|| src.error(n, format!("{what} needs `value`")))?;
                    initial.push(Initial { joint, dof, value });
                }
            }
            _ => {}
        }
    }
    if !b.gravity_set {
        b.model.set_gravity(options.gravity);
    }
    if options.base_pose.is_some() || options.base_orientation.is_some() {
        if !super::base::has_floating_root(b.model.partial()) {
            let robot = src.doc.root_element();
            return Err(src.error(robot, super::base::NO_FLOATING_ROOT));
        }
        match (options.base_pose, options.base_orientation) {
            (Some(pose), _) => b.model.set_base_pose(pose),
            (None, Some(r)) => b.model.set_base_orientation(r),
            (None, None) => {}
        }
    }
    let default = Ground::default();
    if options.ground
        && !b
            .model
            .grounds()
            .iter()
            .any(|g| g.origin == default.origin && g.normal == default.normal)
    {
        b.model
            .add_ground(default.name, default.origin, default.normal)?;
    }
    let resolve = |name: &str, dof: usize, what: &str| -> Result<JointId> {
        let id = b
            .model
            .joint_id(name)
            .ok_or_else(|| b.model.partial().unknown_joint(what, name))?;
        let n = b.model.partial().joints[id.0].kind.scalar_coordinates();
        if dof >= n {
            return Err(crate::error::Error::CoordinateOutOfRange {
                at: b.model.partial().joints[id.0].source.clone().map(Box::new),
                what: what.into(),
                joint: name.into(),
                kind: b.model.partial().joints[id.0].kind.name().into(),
                dof,
                count: n,
            });
        }
        Ok(id)
    };
    b.file_start = (locks.clone(), initial.clone());
    for (name, dof, value) in &options.locks {
        let id = resolve(name, *dof, "lock")?;
        locks.retain(|l| !(l.joint == id && l.dof == *dof));
        locks.push(Lock {
            joint: id,
            dof: *dof,
            value: *value,
        });
    }
    // The reference pose (SRDF state, pose file, `@REF`) starts the joints the file does not
    // (`mech:initial`, e.g. a written rest); `--initial` overrides both; scalar joints only.
    let from_file: Vec<JointId> = initial.iter().map(|l| l.joint).collect();
    for (name, value) in &super::servo::starts(options) {
        let Some(id) = b.model.joint_id(name) else {
            continue;
        };
        let scalar = b.model.partial().joints[id.0].kind.scalar_coordinates() == 1;
        if !scalar || from_file.contains(&id) {
            continue;
        }
        initial.retain(|l| !(l.joint == id && l.dof == 0));
        initial.push(Initial {
            joint: id,
            dof: 0,
            value: *value,
        });
    }
    for (name, dof, value) in &options.initial {
        let id = resolve(name, *dof, "initial value")?;
        initial.retain(|l| !(l.joint == id && l.dof == *dof));
        initial.push(Initial {
            joint: id,
            dof: *dof,
            value: *value,
        });
    }
    for l in locks {
        b.model.add_lock(l);
    }
    for i in initial {
        b.model.add_initial(i);
    }
    Ok(())
}
