//! The joint a constraint row belongs to, and where that joint is declared: errors raised after
//! import (assembly, inconsistent redundant rows) name `file:line:col` of the joint's element.
//!
//! Row names are `joint.row` (`pos_x`, `lock[0]`, `mimic`, …) or `body.normalization`; a
//! joint row's suffix never contains a dot, so the joint is the name before the last dot.

use super::{JointId, Model};
use crate::error::JointSite;

impl Model {
    /// The joint `id` and its element in the input file.
    pub fn joint_site(&self, id: JointId) -> Option<JointSite> {
        self.joints.get(id.0).map(|j| JointSite {
            kind: "joint",
            joint: j.name.clone(),
            at: j.source.clone(),
        })
    }

    /// The file the model was read from (`None` for a model built in code).
    pub fn source_file(&self) -> Option<String> {
        let links = self.links.iter().filter_map(|l| l.source.as_ref());
        let joints = self.joints.iter().filter_map(|j| j.source.as_ref());
        links.chain(joints).next().map(|s| s.file.clone())
    }

    /// The joint of the constraint row named `row`, or the link of a contact point's row
    /// (`link.contact[k]@ground`); `None` for a normalization row or a name that is no joint
    /// or contact row of this model.
    pub fn row_site(&self, row: &str) -> Option<JointSite> {
        if let Some((link, _)) = row
            .split_once('@')
            .and_then(|(head, _)| head.rsplit_once(".contact["))
        {
            let l = self.link(link)?;
            return Some(JointSite {
                kind: "link",
                joint: l.name.clone(),
                at: l.source.clone(),
            });
        }
        let (joint, suffix) = row.rsplit_once('.')?;
        if suffix == "normalization" {
            return None;
        }
        self.joint_site(self.joint_id(joint)?)
    }
}

#[cfg(test)]
mod tests {
    use crate::error::SourceLocation;
    use crate::model::{JointKind, ModelBuilder};
    use nalgebra::{Isometry3, Matrix3, Vector3};

    #[test]
    fn rows_name_their_joint_and_its_place() {
        let mut b = ModelBuilder::new("m");
        let body = b.add_rigid_body("a.b", 1.0, Vector3::zeros(), Matrix3::identity());
        let id = b.add_joint(
            "j.1",
            JointKind::Revolute,
            None,
            Isometry3::identity(),
            Some(body),
            Isometry3::identity(),
        );
        b.set_joint_source(
            id,
            SourceLocation {
                file: "m.urdf".into(),
                line: 7,
                col: 3,
                element: "joint".into(),
            },
        );
        let m = b.build().unwrap();
        let site = m.row_site("j.1.pos_x").unwrap();
        assert_eq!(site.to_string(), "m.urdf:7:3: joint `j.1` (joint)");
        assert_eq!(m.row_site("j.1.lock[0]"), Some(site));
        assert_eq!(m.row_site("a.b.normalization"), None);
        assert_eq!(m.row_site("nothing.pos_x"), None);
    }
}
