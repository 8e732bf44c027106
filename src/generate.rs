//! Generated benchmark and test mechanisms, as URDF text.
//!
//! `chain(n, planar)`: `n` slender links (0.2 m, 1 kg, centre of mass at mid-length along x)
//! hanging from the world in a line along x, joined by revolute joints with torsional springs
//! `k_i = 10 (n − i)²` N m/rad on joint `i` (about ten times the gravity torque per radian of
//! the links it carries, so the chain sags about 0.1 rad per joint). Joint axes alternate between y and z
//! (spatial chain), or are all y (planar chain, gravity in its plane). Gravity `0 0 −9.81`.
//!
//! `rope(n)`: `n` links of 0.05 m and 0.05 kg (1 kg/m) joined by revolute joints about y with
//! a bending spring of 2 N m/rad each (reference straight), a sphere of radius 0.01 m at the
//! end of each link (its contact with the ground `mech:ground`, z = 0), hung from the world at
//! height `H = m · 0.05 cos 0.3 + 0.01`, `m = ⌈n/3⌉`: it starts with `m` links hanging straight,
//! 0.3 rad from the vertical, and the rest lying straight along +x on the ground (gaps 0 at the
//! start: those contacts are active from the start, and the ones near the bend lift off). A
//! vertical start would be degenerate: a straight chain between two heights it spans exactly.

use std::fmt::Write;

/// A generated mechanism family.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Family {
    /// N-link spatial pendulum chain with joint springs (alternating joint axes).
    Chain,
    /// N-link planar chain (all axes parallel) with joint springs.
    PlanarChain,
    /// Ladder of N closed four-bar loops.
    Ladder,
    /// N-link planar rope hanging from the world onto the ground (sphere contacts).
    Rope,
}

/// URDF text of a mechanism of `family` with `n` links (chains) or loops (ladder).
pub fn family(family: Family, n: usize) -> String {
    match family {
        Family::Chain => chain(n, false),
        Family::PlanarChain => chain(n, true),
        Family::Ladder => ladder(n),
        Family::Rope => rope(n),
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

/// URDF text of an `n`-link rope hanging from the world onto the ground (module docs).
pub fn rope(n: usize) -> String {
    let (l, r) = (0.05, 0.01);
    let (m, slant) = (n.div_ceil(3), 0.3f64);
    let h = m as f64 * l * slant.cos() + r;
    let mut s = String::new();
    let _ = writeln!(s, "<?xml version=\"1.0\"?>");
    let _ = writeln!(s, "<robot name=\"rope{n}\" xmlns:mech=\"urn:urdf-mech:1\">");
    let _ = writeln!(s, "  <link name=\"world\"/>");
    for i in 0..n {
        let _ = writeln!(
            s,
            "  <link name=\"link{i}\"><inertial><origin xyz=\"{} 0 0\"/><mass value=\"0.05\"/><inertia ixx=\"1e-6\" ixy=\"0\" ixz=\"0\" iyy=\"1.1e-5\" iyz=\"0\" izz=\"1.1e-5\"/></inertial><collision><origin xyz=\"{l} 0 0\"/><geometry><sphere radius=\"{r}\"/></geometry></collision></link>",
            l / 2.0
        );
    }
    for i in 0..n {
        let (parent, origin) = if i == 0 {
            ("world".to_string(), format!("0 0 {h}"))
        } else {
            (format!("link{}", i - 1), format!("{l} 0 0"))
        };
        let _ = writeln!(
            s,
            "  <joint name=\"joint{i}\" type=\"continuous\"><parent link=\"{parent}\"/><child link=\"link{i}\"/><origin xyz=\"{origin}\"/><axis xyz=\"0 1 0\"/></joint>"
        );
        let _ = writeln!(
            s,
            "  <mech:joint_spring joint=\"joint{i}\" stiffness=\"2\" reference=\"0\"/>"
        );
    }
    // Hanging 0.3 rad off the vertical (a turn of +π/2 about y takes +x to −z), then lying
    // along +x.
    let down = std::f64::consts::FRAC_PI_2 - slant;
    let _ = writeln!(s, "  <mech:initial joint=\"joint0\" value=\"{down}\"/>");
    if m < n {
        let _ = writeln!(
            s,
            "  <mech:initial joint=\"joint{m}\" value=\"{}\"/>",
            -down
        );
    }
    let _ = writeln!(s, "  <mech:ground/>");
    let _ = writeln!(s, "  <mech:gravity xyz=\"0 0 -9.81\"/>");
    let _ = writeln!(s, "</robot>");
    s
}
