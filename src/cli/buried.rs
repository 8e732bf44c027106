//! Bodies that rest inside a ground. Only links with contact points touch the grounds
//! (docs/contact.md), so a body without any may pass through a ground plane at a true rest of
//! the model (a robot whose contacts are on its feet only can hang its trunk below them).
//! A body is reported when its centre of mass `c` lies inside a ground of origin `o` and
//! outward normal `n`: depth `d = n · (o − c) > 0`.

use restpose::{Model, State};

/// One body inside one ground.
pub(crate) struct Buried {
    /// The body's name (its link).
    pub body: String,
    /// The ground's name.
    pub ground: String,
    /// Depth of the centre of mass below the ground plane \[m\].
    pub depth: f64,
}

/// The bodies without contact points whose centre of mass is inside a ground, each with its
/// deepest ground, in body order.
pub(crate) fn buried(model: &Model, state: &State) -> Vec<Buried> {
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
            out.push(Buried {
                body: body.name.clone(),
                ground: g.name.clone(),
                depth,
            });
        }
    }
    out
}
