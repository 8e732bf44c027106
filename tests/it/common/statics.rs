//! Newton–Euler statics of a tree standing on its contacts, computed here from the bodies'
//! masses and poses, the joints' frames and the reported contact forces: an equilibrium check
//! independent of the solver's partition and multipliers.
//!
//! For every revolute or continuous tree joint with axis `a` through `o` (world), the moments
//! about the axis of the gravity of the bodies beyond it and of the contact forces on them,
//! plus the joint's servo torque `−k (θ − θ_ref)`, vanish:
//! `Σ_b ((c_b − o) × m_b g)·a + Σ_c ((p_c − o) × f_c)·a + τ_servo = 0`; and for the floating
//! mechanism as a whole, `Σ m_b g + Σ f_c = 0` and `Σ c_b × m_b g + Σ p_c × f_c = 0`.

use nalgebra::{Point3, Vector3};
use restpose::state::State;
use restpose::{Model, Report};

/// The largest imbalance `(joint torque [N m], base force [N], base moment [N m])`.
pub(crate) fn imbalance(model: &Model, state: &State, report: &Report) -> (f64, f64, f64) {
    let g = model.gravity();
    let bodies = model.bodies();
    let com = |b: usize| {
        (state.body_pose(model.body_ids().nth(b).unwrap()) * Point3::from(bodies[b].gravity_com))
            .coords
    };
    // Contact forces by body: (point, force).
    let mut forces: Vec<(usize, Vector3<f64>, Vector3<f64>)> = Vec::new();
    for c in &report.contacts {
        let body = model.link(&c.link).unwrap().body.unwrap().index();
        let f = Vector3::from(c.normal_world) * c.normal_force + Vector3::from(c.tangential_force);
        forces.push((body, Vector3::from(c.point_world), f));
    }
    // Tree edges between bodies.
    let edges: Vec<(usize, usize)> = model
        .joints()
        .iter()
        .filter(|j| j.tree && !j.merged)
        .filter_map(|j| match j.bodies {
            [Some(p), Some(c)] => Some((p.index(), c.index())),
            _ => None,
        })
        .collect();
    let beyond = |parent: usize, child: usize| {
        let mut set = vec![child];
        let mut k = 0;
        while k < set.len() {
            let b = set[k];
            for &(p, c) in &edges {
                for (x, y) in [(p, c), (c, p)] {
                    if x == b && y != parent && !set.contains(&y) {
                        set.push(y);
                    }
                }
            }
            k += 1;
        }
        set
    };
    let mut torque: f64 = 0.0;
    for (id, j) in model.joints().iter().enumerate() {
        let [Some(p), Some(c)] = j.bodies else {
            continue;
        };
        if !j.tree || j.merged || j.kind.scalar_coordinates() != 1 || !j.kind.is_angle(0) {
            continue;
        }
        let frame = state.body_pose(c) * j.body_from_joint[1];
        let (o, a) = (frame.translation.vector, frame.rotation * Vector3::z());
        let set = beyond(p.index(), c.index());
        let mut m = 0.0;
        for &b in &set {
            m += (com(b) - o).cross(&(g * bodies[b].gravity_mass)).dot(&a);
        }
        for (b, x, f) in &forces {
            if set.contains(b) {
                m += (x - o).cross(f).dot(&a);
            }
        }
        let theta = state.joint(model, &j.name).unwrap()[0];
        for s in model.servos().iter().filter(|s| s.joint.index() == id) {
            m += s.torque(theta);
        }
        torque = torque.max(m.abs());
    }
    let (mut force, mut moment) = (Vector3::zeros(), Vector3::zeros());
    for b in 0..bodies.len() {
        force += g * bodies[b].gravity_mass;
        moment += com(b).cross(&(g * bodies[b].gravity_mass));
    }
    for (_, x, f) in &forces {
        force += f;
        moment += x.cross(f);
    }
    (torque, force.norm(), moment.norm())
}
