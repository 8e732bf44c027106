//! The potential energy of the generated benchmark families written independently of restpose,
//! in joint coordinates (shared by the tests and `benches/chain.rs`).
#![allow(dead_code)]

use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector2, Vector3};

/// `restpose::generate::chain(n, false)` at joint angles `th`: forward kinematics along the
/// chain (0.2 m links, 1 kg at mid-length, axes alternating y/z), gravity −z, springs
/// `k_i = 10 (n − i)²` about 0.
pub(crate) fn chain(n: usize, th: &[f64]) -> f64 {
    let mut pose = Isometry3::identity();
    let mut v = 0.0;
    for i in 0..n {
        let axis = if i % 2 == 0 {
            Vector3::y_axis()
        } else {
            Vector3::z_axis()
        };
        let x = if i == 0 { 0.0 } else { 0.2 };
        pose =
            pose * Translation3::new(x, 0.0, 0.0) * UnitQuaternion::from_axis_angle(&axis, th[i]);
        v += 9.81 * (pose * Point3::new(0.1, 0.0, 0.0)).z;
        v += 0.5 * 10.0 * ((n - i) * (n - i)) as f64 * th[i] * th[i];
    }
    v
}

/// `restpose::generate::ladder(n)` at the posts' absolute angles `phi` (each loop is a
/// parallelogram: its rung stays level), gravity −y, springs `10 (n − k)` about 0.1 rad.
pub(crate) fn ladder(n: usize, phi: &[f64]) -> f64 {
    let mut top = Vector2::new(0.0, 0.0);
    let mut v = 0.0;
    for k in 0..n {
        let down = |len: f64| Vector2::new(len * phi[k].sin(), -len * phi[k].cos());
        let left = top + down(0.15);
        let right = top + Vector2::new(0.4, 0.0) + down(0.15);
        let rung = top + down(0.3);
        v += 9.81 * (left.y + right.y + rung.y);
        v += 0.5 * 10.0 * (n - k) as f64 * (phi[k] - 0.1).powi(2);
        top = rung;
    }
    v
}

/// `restpose::generate::rope(n)` at joint angles `th` (continuous joints about y, 0.05 m links
/// of 0.05 kg with the centre of mass at mid-length, springs 2 N m/rad about 0, the anchor at
/// height `⌈n/3⌉ · 0.05 cos 0.3 + 0.01`): link `i` leaves its joint along
/// `(cos φ_i, 0, −sin φ_i)`, `φ_i = Σ_{j ≤ i} θ_j`.
pub(crate) fn rope(n: usize, th: &[f64]) -> f64 {
    let (l, mass, g, k) = (0.05, 0.05, 9.81, 2.0);
    let h = n.div_ceil(3) as f64 * l * 0.3f64.cos() + 0.01;
    let (mut z, mut phi, mut energy) = (h, 0.0, 0.0);
    for &t in &th[..n] {
        phi += t;
        energy += mass * g * (z - 0.5 * l * phi.sin()) + 0.5 * k * t * t;
        z -= l * phi.sin();
    }
    energy
}
