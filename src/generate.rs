//! Generated benchmark and test mechanisms, as URDF text.
//!
//! `chain(n, planar)`: `n` slender links (0.2 m, 1 kg, centre of mass at mid-length along x)
//! hanging from the world in a line along x, joined by revolute joints with torsional springs
//! `k_i = 10 (n − i)²` N m/rad on joint `i` (about ten times the gravity torque per radian of
//! the links it carries, so the chain sags about 0.1 rad per joint). Joint axes alternate between y and z
//! (spatial chain), or are all y (planar chain, gravity in its plane). Gravity `0 0 −9.81`.

use std::fmt::Write;

/// A generated mechanism family.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum Family {
    /// N-link spatial pendulum chain with joint springs (alternating joint axes).
    Chain,
    /// N-link planar chain (all axes parallel) with joint springs.
    PlanarChain,
    /// Ladder of N closed four-bar loops.
    Ladder,
}

/// URDF text of a mechanism of `family` with `n` links (chains) or loops (ladder).
pub fn family(family: Family, n: usize) -> String {
    match family {
        Family::Chain => chain(n, false),
        Family::PlanarChain => chain(n, true),
        Family::Ladder => ladder(n),
    }
}

/// URDF text of an `n`-link pendulum chain with joint springs.
pub fn chain(n: usize, planar: bool) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "<?xml version=\"1.0\"?>");
    let _ = writeln!(
        s,
        "<robot name=\"{}chain{n}\" xmlns:mech=\"urn:urdf-mech:1\">",
        if planar { "planar_" } else { "" }
    );
    let _ = writeln!(s, "  <link name=\"world\"/>");
    for i in 0..n {
        let _ = writeln!(
            s,
            "  <link name=\"link{i}\"><inertial><origin xyz=\"0.1 0 0\"/><mass value=\"1\"/><inertia ixx=\"1e-4\" ixy=\"0\" ixz=\"0\" iyy=\"3.4e-3\" iyz=\"0\" izz=\"3.4e-3\"/></inertial></link>"
        );
    }
    for i in 0..n {
        let parent = if i == 0 {
            "world".to_string()
        } else {
            format!("link{}", i - 1)
        };
        let x = if i == 0 { 0.0 } else { 0.2 };
        let axis = if planar || i % 2 == 0 {
            "0 1 0"
        } else {
            "0 0 1"
        };
        let _ = writeln!(
            s,
            "  <joint name=\"joint{i}\" type=\"continuous\"><parent link=\"{parent}\"/><child link=\"link{i}\"/><origin xyz=\"{x} 0 0\"/><axis xyz=\"{axis}\"/></joint>"
        );
        let k = 10.0 * ((n - i) * (n - i)) as f64;
        let _ = writeln!(
            s,
            "  <mech:joint_spring joint=\"joint{i}\" stiffness=\"{k}\" reference=\"0\"/>"
        );
    }
    let _ = writeln!(s, "  <mech:gravity xyz=\"0 0 -9.81\"/>");
    let _ = writeln!(s, "</robot>");
    s
}

/// URDF text of a ladder of `n` closed four-bar loops hanging from the world, in the x-y plane
/// (gravity −y): level `k` has two posts (0.3 m, 1 kg) hanging from the rung above and a rung
/// (0.4 m, 1 kg) pinned to the left post and closed onto the right post by a revolute loop
/// joint, a parallelogram with one degree of freedom held by a torsional spring
/// `10 (n − k)` N m/rad on the left post. Each loop written with spatial revolute joints has
/// three redundant rows.
pub fn ladder(n: usize) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "<?xml version=\"1.0\"?>");
    let _ = writeln!(
        s,
        "<robot name=\"ladder{n}\" xmlns:mech=\"urn:urdf-mech:1\">"
    );
    let _ = writeln!(s, "  <link name=\"world\"/>");
    let inertial = |x: f64, y: f64| {
        format!("<inertial><origin xyz=\"{x} {y} 0\"/><mass value=\"1\"/><inertia ixx=\"7.5e-3\" ixy=\"0\" ixz=\"0\" iyy=\"1e-4\" iyz=\"0\" izz=\"7.5e-3\"/></inertial>")
    };
    for k in 0..n {
        let _ = writeln!(
            s,
            "  <link name=\"left{k}\">{}</link>",
            inertial(0.0, -0.15)
        );
        let _ = writeln!(
            s,
            "  <link name=\"right{k}\">{}</link>",
            inertial(0.0, -0.15)
        );
        let _ = writeln!(s, "  <link name=\"rung{k}\">{}</link>", inertial(0.2, 0.0));
        let above = if k == 0 {
            "world".to_string()
        } else {
            format!("rung{}", k - 1)
        };
        let joint = |name: String, parent: &str, child: String, x: f64, y: f64| {
            format!("  <joint name=\"{name}\" type=\"continuous\"><parent link=\"{parent}\"/><child link=\"{child}\"/><origin xyz=\"{x} {y} 0\"/><axis xyz=\"0 0 1\"/></joint>")
        };
        let _ = writeln!(
            s,
            "{}",
            joint(
                format!("hang_left{k}"),
                &above,
                format!("left{k}"),
                0.0,
                0.0
            )
        );
        let _ = writeln!(
            s,
            "{}",
            joint(
                format!("hang_right{k}"),
                &above,
                format!("right{k}"),
                0.4,
                0.0
            )
        );
        let _ = writeln!(
            s,
            "{}",
            joint(
                format!("rung_pin{k}"),
                &format!("left{k}"),
                format!("rung{k}"),
                0.0,
                -0.3
            )
        );
        let _ = writeln!(
            s,
            "  <mech:loop_joint name=\"close{k}\" type=\"revolute\"><parent link=\"rung{k}\"/><origin xyz=\"0.4 0 0\"/><child link=\"right{k}\"/><child_origin xyz=\"0 -0.3 0\"/><axis xyz=\"0 0 1\"/></mech:loop_joint>"
        );
        let _ = writeln!(
            s,
            "  <mech:joint_spring joint=\"hang_left{k}\" stiffness=\"{}\" reference=\"0.1\"/>",
            10.0 * (n - k) as f64
        );
    }
    let _ = writeln!(s, "  <mech:gravity xyz=\"0 -9.81 0\"/>");
    let _ = writeln!(s, "</robot>");
    s
}
