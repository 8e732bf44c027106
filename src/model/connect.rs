//! Joining bodies in the builder: spanning-tree joints, loop joints, joint frames and limits.
//!
//! A joint's frame `J` is given in each of its two body frames; its z axis is the joint axis
//! ([`JointKind`]). [`axis_frame`] makes `J` from an origin and an axis the way URDF does:
//! `body_from_J = origin · R(z → axis)`, `R` the shortest rotation taking z onto the axis. At
//! zero joint displacement the two `J` frames coincide, so a tree joint places its child:
//! `world_from_child = world_from_parent · parent_from_J · motion(θ) · (child_from_J)⁻¹`.
//! Tree joints form a forest rooted at the world (a body that is no tree joint's child
//! floats); a loop joint adds its constraint rows between two bodies already placed.

use super::{BodyId, Joint, JointId, JointKind, Model, ModelBuilder};
use crate::error::SourceLocation;
use crate::math::align_z;
use nalgebra::{Isometry3, Unit, Vector3};

/// The joint frame `J` at `origin` with its z axis along `axis` (both in the body frame):
/// `origin · R(z → axis)`, as the URDF importer places `<origin>` and `<axis>`.
///
/// ```
/// use nalgebra::{Isometry3, Vector3};
/// let j = restpose::model::axis_frame(Isometry3::translation(1.0, 0.0, 0.0), &Vector3::y_axis());
/// assert!((j * Vector3::z() - Vector3::y()).norm() < 1e-15);
/// assert_eq!(j.translation.vector, Vector3::new(1.0, 0.0, 0.0));
/// ```
pub fn axis_frame(origin: Isometry3<f64>, axis: &Unit<Vector3<f64>>) -> Isometry3<f64> {
    origin * Isometry3::from_parts(Default::default(), align_z(axis))
}

impl ModelBuilder {
    /// Adds a spanning-tree joint between bodies (`None` = world) with its joint frame `J`
    /// given in each body frame (`J`'s z axis is the joint axis, see [`JointKind`]): the child
    /// is placed from the parent through it.
    pub fn add_joint(
        &mut self,
        name: impl Into<String>,
        kind: JointKind,
        parent: Option<BodyId>,
        parent_from_joint: Isometry3<f64>,
        child: Option<BodyId>,
        child_from_joint: Isometry3<f64>,
    ) -> JointId {
        let frames = [parent_from_joint, child_from_joint];
        self.add_joint_with(name.into(), kind, [parent, child], frames, true)
    }

    /// Adds a loop-closing joint: not a spanning-tree edge, its constraint rows close a loop
    /// between two bodies the tree already places (a four-bar's fourth joint). Start the
    /// mechanism near a closed pose with [`Self::add_initial`].
    pub fn add_loop_joint(
        &mut self,
        name: impl Into<String>,
        kind: JointKind,
        parent: Option<BodyId>,
        parent_from_joint: Isometry3<f64>,
        child: Option<BodyId>,
        child_from_joint: Isometry3<f64>,
    ) -> JointId {
        let frames = [parent_from_joint, child_from_joint];
        self.add_joint_with(name.into(), kind, [parent, child], frames, false)
    }

    /// A joint between `bodies` with its frame given in each body, in the tree or closing a
    /// loop.
    fn add_joint_with(
        &mut self,
        name: String,
        kind: JointKind,
        bodies: [Option<BodyId>; 2],
        body_from_joint: [Isometry3<f64>; 2],
        tree: bool,
    ) -> JointId {
        let joint = self.joint_between(name, kind, bodies);
        self.push_joint(Joint {
            body_from_joint,
            tree,
            ..joint
        })
    }

    /// A tree joint with identity frames, its link names those of its bodies.
    fn joint_between(&self, name: String, kind: JointKind, bodies: [Option<BodyId>; 2]) -> Joint {
        let link = |b: Option<BodyId>, m: &Model| {
            b.and_then(|b| m.bodies.get(b.0))
                .map_or_else(|| "world".to_string(), |b| b.name.clone())
        };
        Joint {
            name,
            kind,
            parent_link: link(bodies[0], &self.model),
            child_link: link(bodies[1], &self.model),
            bodies,
            body_from_joint: [Isometry3::identity(); 2],
            tree: true,
            merged: false,
            limits: None,
            effort_limit: None,
            source: None,
        }
    }

    /// Adds a joint given in full (loop closures: `tree: false`; welded fixed joints:
    /// `merged: true`).
    pub fn push_joint(&mut self, joint: Joint) -> JointId {
        let id = JointId(self.model.joints.len());
        self.joint_names.entry(joint.name.clone()).or_insert(id);
        self.model.joints.push(joint);
        id
    }

    /// Sets the position limits `[lower, upper]` of coordinate 0 of `joint` \[rad or m\]
    /// (enforced unless [`crate::Options::limits`] says otherwise; a continuous joint
    /// has none, whatever is set). `build` refuses `lower > upper`.
    pub fn set_limits(&mut self, joint: JointId, lower: f64, upper: f64) {
        if let Some(j) = self.model.joints.get_mut(joint.0) {
            j.limits = Some([lower, upper]);
        }
    }

    /// Records where joint `joint` is declared in the input file (named in later errors).
    pub fn set_joint_source(&mut self, joint: JointId, source: SourceLocation) {
        if let Some(j) = self.model.joints.get_mut(joint.0) {
            j.source = Some(source);
        }
    }

    /// Records where link `link` (an index of [`ModelBuilder::add_link`]) is declared.
    pub fn set_link_source(&mut self, link: usize, source: SourceLocation) {
        if let Some(l) = self.model.links.get_mut(link) {
            l.source = Some(source);
        }
    }

    /// Replaces the child-side joint frame of `joint` (a loop joint closed at the initial
    /// guess).
    pub fn set_child_frame(&mut self, joint: JointId, child_from_joint: Isometry3<f64>) {
        if let Some(j) = self.model.joints.get_mut(joint.0) {
            j.body_from_joint[1] = child_from_joint;
        }
    }
}
