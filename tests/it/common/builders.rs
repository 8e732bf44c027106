//! Mechanisms built in code with `restpose::model::ModelBuilder` (no URDF text): a pendulum,
//! the generated chain, a planar four-bar closed by a loop joint, and short-hands for the
//! coordinate inputs. `tests/it/builder.rs` checks that each solves exactly as the URDF it
//! replaces.
#![allow(dead_code)]

use nalgebra::{Isometry3, Matrix3, Unit, Vector3};
use restpose::model::{
    axis_frame, BodyId, ForceLaw, Initial, JointId, JointKind, Lock, ModelBuilder,
};

/// A diagonal inertia \[kg m²\].
pub(crate) fn inertia(ixx: f64, iyy: f64, izz: f64) -> Matrix3<f64> {
    Matrix3::from_diagonal(&Vector3::new(ixx, iyy, izz))
}

/// A linear law `F = k δ`.
pub(crate) fn linear(stiffness: f64) -> ForceLaw {
    ForceLaw::Linear {
        stiffness,
        preload: 0.0,
    }
}

/// Holds coordinate 0 of `joint` at `value`.
pub(crate) fn lock(b: &mut ModelBuilder, joint: JointId, value: f64) {
    b.add_lock(Lock {
        joint,
        dof: 0,
        value: Some(value),
    });
}

/// Starts coordinate `dof` of `joint` at `value`.
pub(crate) fn initial(b: &mut ModelBuilder, joint: JointId, dof: usize, value: f64) {
    b.add_initial(Initial { joint, dof, value });
}

/// A joint of `kind` about `axis` at `origin` in the parent, whose child's frame is the joint
/// frame at zero displacement (a URDF `<joint>`).
pub(crate) fn hinge(
    b: &mut ModelBuilder,
    name: &str,
    kind: JointKind,
    parent: Option<BodyId>,
    origin: Isometry3<f64>,
    axis: Unit<Vector3<f64>>,
    child: BodyId,
) -> JointId {
    let rotation = axis_frame(Isometry3::identity(), &axis);
    b.add_joint(
        name,
        kind,
        parent,
        axis_frame(origin, &axis),
        Some(child),
        rotation,
    )
}

/// A pendulum named `name`: body `bar` (`mass` at `com`, `inertia` about it) on joint
/// `pivot` of `kind` about z at the world origin.
pub(crate) fn pendulum(
    name: &str,
    kind: JointKind,
    mass: f64,
    com: Vector3<f64>,
    inertia: Matrix3<f64>,
) -> (ModelBuilder, JointId) {
    let mut b = ModelBuilder::new(name);
    let bar = b.add_rigid_body("bar", mass, com, inertia);
    let pivot = hinge(
        &mut b,
        "pivot",
        kind,
        None,
        Isometry3::identity(),
        Vector3::z_axis(),
        bar,
    );
    (b, pivot)
}

/// `restpose::generate::chain(n, planar)` built in code: links `link{i}` (0.2 m, 1 kg at
/// mid-length), continuous joints `joint{i}` about y (alternating with z unless planar) with
/// springs `10 (n − i)²` N m/rad about 0, gravity −z.
pub(crate) fn chain(n: usize, planar: bool) -> (ModelBuilder, Vec<JointId>) {
    let name = format!("{}chain{n}", if planar { "planar_" } else { "" });
    let mut b = ModelBuilder::new(name);
    let mut joints = Vec::new();
    let mut parent = None;
    for i in 0..n {
        let link = b.add_rigid_body(
            format!("link{i}"),
            1.0,
            Vector3::new(0.1, 0.0, 0.0),
            inertia(1e-4, 3.4e-3, 3.4e-3),
        );
        let x = if i == 0 { 0.0 } else { 0.2 };
        let axis = if planar || i % 2 == 0 {
            Vector3::y_axis()
        } else {
            Vector3::z_axis()
        };
        let j = hinge(
            &mut b,
            &format!("joint{i}"),
            JointKind::Continuous,
            parent,
            Isometry3::translation(x, 0.0, 0.0),
            axis,
            link,
        );
        b.add_joint_spring(j, 0, linear(10.0 * ((n - i) * (n - i)) as f64), 0.0);
        joints.push(j);
        parent = Some(link);
    }
    b.set_gravity(Vector3::new(0.0, 0.0, -9.81));
    (b, joints)
}

/// A planar four-bar in the x-y plane, gravity −y: ground 1 m from the crank pivot (origin)
/// to the rocker pivot, crank `a`, coupler `b`, rocker `c` (masses at mid-length, joints
/// `crank_j`, `coupler_j`, `rocker_j` about z), closed by the revolute loop joint `close`
/// from the coupler's end to the rocker's end; assembled at crank angle `t` (`None` if the
/// loop cannot close there), with a crank spring of stiffness `k` about `t`.
pub(crate) fn four_bar(
    [a, b, c]: [f64; 3],
    t: f64,
    masses: [f64; 3],
    k: f64,
) -> Option<(ModelBuilder, [JointId; 4])> {
    let (bx, by) = (a * t.cos(), a * t.sin());
    let (ex, ey) = (1.0 - bx, -by);
    let d = (ex * ex + ey * ey).sqrt();
    if d >= b + c || d <= (b - c).abs() {
        return None;
    }
    let along = (b * b - c * c + d * d) / (2.0 * d);
    let h = (b * b - along * along).sqrt();
    let (cx, cy) = (
        bx + along * ex / d - h * ey / d,
        by + along * ey / d + h * ex / d,
    );
    let coupler_angle = (cy - by).atan2(cx - bx);
    let rocker_angle = cy.atan2(cx - 1.0);
    let mut m = ModelBuilder::new("fourbar");
    let bar = |m: &mut ModelBuilder, name: &str, mass: f64, len: f64| {
        m.add_rigid_body(
            name,
            mass,
            Vector3::new(len / 2.0, 0.0, 0.0),
            Matrix3::identity(),
        )
    };
    // Bodies in the order the URDF importer's breadth-first tree gives them.
    let crank = bar(&mut m, "crank", masses[0], a);
    let rocker = bar(&mut m, "rocker", masses[2], c);
    let coupler = bar(&mut m, "coupler", masses[1], b);
    let z = Vector3::z_axis();
    let at = |x: f64| Isometry3::translation(x, 0.0, 0.0);
    let crank_j = hinge(
        &mut m,
        "crank_j",
        JointKind::Continuous,
        None,
        at(0.0),
        z,
        crank,
    );
    let coupler_j = hinge(
        &mut m,
        "coupler_j",
        JointKind::Continuous,
        Some(crank),
        at(a),
        z,
        coupler,
    );
    let rocker_j = hinge(
        &mut m,
        "rocker_j",
        JointKind::Continuous,
        None,
        at(1.0),
        z,
        rocker,
    );
    let close = m.add_loop_joint(
        "close",
        JointKind::Revolute,
        Some(coupler),
        axis_frame(at(b), &z),
        Some(rocker),
        axis_frame(at(c), &z),
    );
    initial(&mut m, crank_j, 0, t);
    initial(&mut m, coupler_j, 0, coupler_angle - t);
    initial(&mut m, rocker_j, 0, rocker_angle);
    m.add_joint_spring(crank_j, 0, linear(k), t);
    m.set_gravity(Vector3::new(0.0, -9.81, 0.0));
    Some((m, [crank_j, coupler_j, rocker_j, close]))
}
