//! Generated benchmark and test mechanisms, as URDF text.
//!
//! `chain(n, planar)`: `n` slender links (0.2 m, 1 kg, centre of mass at mid-length along x)
//! hanging from the world in a line along x, joined by revolute joints with torsional springs
//! `k_i = 10 (n − i)²` N m/rad on joint `i` (about ten times the gravity torque per radian of
//! the links it carries, so the chain sags about 0.1 rad per joint). Joint axes alternate between y and z
//! (spatial chain), or are all y (planar chain, gravity in its plane). Gravity `0 0 −9.81`.

use std::fmt::Write;

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
