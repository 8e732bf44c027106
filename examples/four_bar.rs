//! A mechanism built in code, without URDF: a planar parallelogram four-bar closed by a loop
//! joint, held by a torsion spring on its crank, solved and checked against its closed form.
//!
//! Crank and rocker (0.3 m, 1 kg each) hang from pivots 1 m apart on the x axis; the coupler
//! (1 m, 2 kg) joins their ends, so it stays parallel to the ground and every point moves as
//! the crank's end does. With the crank at `φ` from +x and gravity −y the energy is
//! `V(φ) = g W sin φ + ½ k (φ − φ₀)²`, `W = (m_crank + m_rocker) a/2 + m_coupler a`, and the rest
//! pose satisfies `k (φ − φ₀) + g W cos φ = 0`.
//!
//! `cargo run --example four_bar` prints the rest angle; `cargo test --example four_bar` checks
//! it.

use nalgebra::{Isometry3, Matrix3, Vector3};
use restpose::model::{axis_frame, ForceLaw, Initial, JointKind, ModelBuilder};
use restpose::Model;

const A: f64 = 0.3;
const K: f64 = 20.0;
const REST: f64 = 1.0;
const G: f64 = 9.81;

/// The four-bar, started with the crank at 1.2 rad.
fn four_bar() -> restpose::Result<Model> {
    let mut b = ModelBuilder::new("parallelogram");
    b.set_gravity(Vector3::new(0.0, -G, 0.0));
    let bar = |b: &mut ModelBuilder, name: &str, mass: f64, length: f64| {
        let com = Vector3::new(length / 2.0, 0.0, 0.0);
        b.add_rigid_body(name, mass, com, Matrix3::identity() * 1e-2)
    };
    let crank = bar(&mut b, "crank", 1.0, A);
    let rocker = bar(&mut b, "rocker", 1.0, A);
    let coupler = bar(&mut b, "coupler", 2.0, 1.0);
    // Every joint turns about z; `at(x)` is a joint frame x along a body (or the ground).
    let at = |x: f64| axis_frame(Isometry3::translation(x, 0.0, 0.0), &Vector3::z_axis());
    let (hinge, pin) = (JointKind::Revolute, JointKind::Continuous);
    let crank_j = b.add_joint("crank_j", pin, None, at(0.0), Some(crank), at(0.0));
    let rocker_j = b.add_joint("rocker_j", pin, None, at(1.0), Some(rocker), at(0.0));
    let coupler_j = b.add_joint("coupler_j", pin, Some(crank), at(A), Some(coupler), at(0.0));
    b.add_loop_joint("close", hinge, Some(coupler), at(1.0), Some(rocker), at(A));
    let law = ForceLaw::Linear {
        stiffness: K,
        preload: 0.0,
    };
    b.add_joint_spring(crank_j, 0, law, REST);
    for (joint, value) in [(crank_j, 1.2), (rocker_j, 1.2), (coupler_j, -1.2)] {
        b.add_initial(Initial {
            joint,
            dof: 0,
            value,
        });
    }
    b.build()
}

/// The rest angle from the closed form, by Newton on `k (φ − φ₀) + g W cos φ = 0`.
fn closed_form() -> f64 {
    let w = (1.0 + 1.0) * A / 2.0 + 2.0 * A;
    let mut phi = REST;
    for _ in 0..50 {
        phi -= (K * (phi - REST) + G * w * phi.cos()) / (K - G * w * phi.sin());
    }
    phi
}

fn main() -> restpose::Result<()> {
    let model = four_bar()?;
    let (rest, report) = restpose::solve(&model, &Default::default())?;
    let phi = rest.joint(&model, "crank_j").unwrap_or_default();
    println!(
        "converged: {}, crank at {:.9} rad (closed form {:.9}), {} degree(s) of freedom",
        report.converged(),
        phi.first().copied().unwrap_or(f64::NAN),
        closed_form(),
        report.dof
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use restpose::verify::{verify, Tolerances};

    /// The solver's rest pose is the closed form's, the loop stays a parallelogram, and
    /// `verify` passes it as a stable rest pose.
    #[test]
    fn four_bar_rests_at_its_closed_form() {
        let model = four_bar().unwrap();
        let (rest, report) = restpose::solve(&model, &Default::default()).unwrap();
        assert!(report.converged(), "{:?}", report.termination);
        assert_eq!(report.dof, 1);
        let angle = |name: &str| rest.joint(&model, name).unwrap()[0];
        let phi = closed_form();
        assert!(
            (angle("crank_j") - phi).abs() < 1e-9,
            "{} vs {phi}",
            angle("crank_j")
        );
        assert!((angle("rocker_j") - phi).abs() < 1e-9);
        assert!((angle("coupler_j") + phi).abs() < 1e-9);
        let check = verify(&model, &rest, &Tolerances::default()).unwrap();
        assert!(check.passed, "{check:?}");
        assert_eq!(
            check.stability.unwrap().verdict,
            restpose::solver::Verdict::Stable
        );
    }
}
