//! Bodies that rest inside a ground. Only links with contact points touch the grounds
//! (docs/contact.md), so a body without any may pass through a ground plane at a true rest of
//! the model (a robot whose contacts are on its feet only can hang its trunk below them).
//! A body is reported when its centre of mass `c` lies inside a ground of origin `o` and
//! outward normal `n`: depth `d = n · (o − c) > 0` (the result JSON's `buried_bodies`, and a
//! warning of `analyze`).

use crate::model::Model;
use crate::state::State;
use serde::Serialize;

/// One body whose centre of mass is inside a ground.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BuriedBody {
    /// The body's name (its first link).
    pub body: String,
    /// The ground's name.
    pub ground: String,
    /// Depth of the centre of mass below the ground plane, `n · (o − c)` \[m\] (positive).
    pub depth: f64,
}

/// The bodies without contact points whose centre of mass is inside a ground at `state`,
/// each with its deepest ground, deepest first (ties in body order).
pub fn buried_bodies(model: &Model, state: &State) -> Vec<BuriedBody> {
    let touching: std::collections::HashSet<usize> = model
        .contact_points()
        .iter()
        .map(|p| p.body.index())
        .collect();
    let mut out = Vec::new();
    for (id, body) in model.body_ids().zip(model.bodies()) {
        if touching.contains(&id.index()) {
            continue;
        }
        let c = state.body_pose(id) * nalgebra::Point3::from(body.com);
        let deepest = model
            .grounds()
            .iter()
            .map(|g| (g, g.normal.dot(&(g.origin - c.coords))))
            .filter(|(_, d)| *d > 0.0)
            .max_by(|a, b| a.1.total_cmp(&b.1));
        if let Some((g, depth)) = deepest {
            out.push(BuriedBody {
                body: body.name.clone(),
                ground: g.name.clone(),
                depth,
            });
        }
    }
    out.sort_by(|x, y| y.depth.total_cmp(&x.depth));
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::urdf::{load_str, ImportOptions};

    /// A floating trunk without collision geometry (centre of mass 0.1 m above its origin)
    /// and a leg with a sphere on a hinge, under two grounds at z = 1 and z = 0.5: the trunk
    /// is reported 0.9 m inside the deeper plane `high`; the leg, which has a contact point,
    /// is not; with the grounds below the trunk nothing is.
    #[test]
    fn a_body_without_contact_points_below_a_ground_is_reported_with_its_depth() {
        let robot = |grounds: &str| {
            format!(
                r#"<robot name="r" xmlns:mech="urn:urdf-mech:1">
  <link name="trunk"><inertial><origin xyz="0 0 0.1"/><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <link name="leg"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>
    <collision><origin xyz="0 0 -0.3"/><geometry><sphere radius="0.01"/></geometry></collision></link>
  <joint name="hip" type="revolute"><parent link="trunk"/><child link="leg"/><axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  {grounds}
</robot>"#
            )
        };
        let options = ImportOptions {
            floating_base: true,
            ..Default::default()
        };
        let text = robot(
            r#"<mech:ground name="high" xyz="0 0 1"/><mech:ground name="low" xyz="0 0 0.5"/>"#,
        );
        let model = load_str(&text, "r.urdf", &options).unwrap().model;
        let state = State::initial(&model);
        let buried = buried_bodies(&model, &state);
        assert_eq!(buried.len(), 1, "{buried:?}");
        assert_eq!(
            (buried[0].body.as_str(), buried[0].ground.as_str()),
            ("trunk", "high")
        );
        assert!((buried[0].depth - 0.9).abs() < 1e-12, "{}", buried[0].depth);
        let text = robot(r#"<mech:ground xyz="0 0 -1"/>"#);
        let model = load_str(&text, "r.urdf", &options).unwrap().model;
        assert!(buried_bodies(&model, &State::initial(&model)).is_empty());
    }
}
