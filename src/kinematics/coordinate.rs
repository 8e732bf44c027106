//! Scalar joint coordinates `θ(q)` with exact gradients and Hessians.
//!
//! `θ = atan2(y_i·x_j, x_i·x_j)` about z, `d·z_i` along z; universal
//! `θ₂ = atan2(z_i·y_j, z_i·z_j)`; planar `x = d·x_i, y = d·y_i`. An angle is read on the
//! branch of the reference `θ_b`: `θ = θ_b + wrap(atan2 − θ_b)`, so `θ` is the real number
//! within π of `θ_b` (`θ_b = 3.5` reads the pose at 3.5 − 2π as 3.5, not −2.78). The
//! derivatives do not depend on the branch.

use super::frames::{angle_of, axis_of, frame_vector, Frames};
use crate::jet::{Pair, Scalar, Vec3Jet};
use crate::joint::{Read, V};
use crate::math::{rotation, wrap_angle};
use crate::model::Joint;
use nalgebra::Vector3;

/// The vector `v` of the joint frames `f`.
pub(crate) fn vector(f: &Frames, v: V) -> &Vec3Jet {
    match v {
        V::D => &f.d,
        V::X0 => &f.x[0],
        V::Y0 => &f.y[0],
        V::Z0 => &f.z[0],
        V::X1 => &f.x[1],
        V::Y1 => &f.y[1],
        V::Z1 => &f.z[1],
    }
}

/// Scalar joint coordinate `dof` read on the branch `reference` (used only if the
/// coordinate is an angle), or `None` if the joint has no such coordinate (its kind's
/// [`crate::joint::Spec::coordinates`] say how it is read).
///
/// Only the frame vectors the coordinate reads are formed (each as
/// [`super::frames::frames`] forms it: the same numbers): a revolute angle's three axes of
/// the eight jets.
pub(crate) fn coordinate(joint: &Joint, pair: &Pair, dof: usize, reference: f64) -> Option<Scalar> {
    let c = joint.kind.spec().coordinates.get(dof)?;
    let v = |v: V| frame_vector(joint, pair, v);
    let s = match c.read {
        Read::Angle => angle_of(pair, &v(V::Y0), &v(V::X0), &v(V::X1)),
        Read::Dot(a, b) => pair.dot(&v(a), &v(b)),
        Read::Atan2([a, b], [c, e]) => {
            let s = pair.dot(&v(a), &v(b));
            let c = pair.dot(&v(c), &v(e));
            pair.atan2(&s, &c)
        }
    };
    Some(if c.angle { on_branch(s, reference) } else { s })
}

/// The value of [`coordinate`] alone, without derivatives: the same arithmetic on the values
/// of the frames (bit for bit the same number), for the branches followed after every step.
pub(crate) fn coordinate_value(
    joint: &Joint,
    pair: &Pair,
    dof: usize,
    reference: f64,
) -> Option<f64> {
    let c = joint.kind.spec().coordinates.get(dof)?;
    let a = [rotation(&pair.p[0]), rotation(&pair.p[1])];
    let f = &joint.body_from_joint;
    let vector = |v: V| match axis_of(v) {
        Some((k, e)) => a[k] * (f[k].rotation * e),
        None => {
            let o = |k: usize| pair.r[k] + a[k] * f[k].translation.vector;
            o(1) - o(0)
        }
    };
    let dot = |a: V, b: V| vector(a).dot(&vector(b));
    let v = match c.read {
        Read::Angle => dot(V::Y0, V::X1).atan2(dot(V::X0, V::X1)),
        Read::Dot(a, b) => dot(a, b),
        Read::Atan2([a, b], [c, e]) => dot(a, b).atan2(dot(c, e)),
    };
    Some(if c.angle && reference.is_finite() {
        reference + wrap_angle(v - reference)
    } else {
        v
    })
}

/// [`coordinate_value`] of a coordinate 0 read as [`Read::Angle`] (bit for bit the same
/// number: the same operations on the same frames), with how far the child's `x₁` lies from
/// the parent's joint axis `z₀`: `ρ = |(x₀·x₁, y₀·x₁)| / (|x₀| |x₁|)`, the sine of the angle
/// between `x₁` and `z₀` (1 where the joint's rows hold). A rotation of `x₁` by `φ` turns the
/// angle at a rate of at most `|φ̇| / ρ` (module `solver::inequality::bend`). `None` where
/// coordinate 0 is not read as such an angle.
pub(crate) fn angle_value_and_spread(
    joint: &Joint,
    pair: &Pair,
    reference: f64,
) -> Option<(f64, f64)> {
    let c = joint.kind.spec().coordinates.first()?;
    if c.read != Read::Angle {
        return None;
    }
    let a = [rotation(&pair.p[0]), rotation(&pair.p[1])];
    let f = &joint.body_from_joint;
    let axis = |k: usize, e: Vector3<f64>| a[k] * (f[k].rotation * e);
    let (x0, y0, x1) = (
        axis(0, Vector3::x()),
        axis(0, Vector3::y()),
        axis(1, Vector3::x()),
    );
    let (s, co) = (y0.dot(&x1), x0.dot(&x1));
    let v = s.atan2(co);
    let value = if c.angle && reference.is_finite() {
        reference + wrap_angle(v - reference)
    } else {
        v
    };
    Some((value, s.hypot(co) / (x0.norm() * x1.norm())))
}

/// `θ_b + wrap(θ − θ_b)` with the derivatives of `θ`.
pub(crate) fn on_branch(mut s: Scalar, reference: f64) -> Scalar {
    if reference.is_finite() {
        s.v = reference + wrap_angle(s.v - reference);
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::jet::pair_of;
    use crate::model::{BodyId, JointKind};
    use nalgebra::{DVector, Isometry3, UnitQuaternion, Vector3};

    fn revolute() -> Joint {
        Joint {
            name: "j".into(),
            kind: JointKind::Revolute,
            parent_link: "a".into(),
            child_link: "b".into(),
            bodies: [None, Some(BodyId(0))],
            body_from_joint: [Isometry3::identity(), Isometry3::identity()],
            tree: true,
            merged: false,
            limits: None,
            effort_limit: None,
            source: None,
        }
    }

    /// A body turned by `a` about z reads as the real number within π of the reference.
    #[test]
    fn angle_is_read_on_the_reference_branch() {
        let j = revolute();
        for (turned, reference, expected) in [
            (3.5, 3.5, 3.5),
            (3.5, 0.0, 3.5 - std::f64::consts::TAU),
            (-3.5, -3.2, -3.5),
            (
                0.3,
                4.0 * std::f64::consts::PI,
                0.3 + 4.0 * std::f64::consts::PI,
            ),
        ] {
            let r = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), turned);
            let q = DVector::from_vec(vec![0.0, 0.0, 0.0, r.w, r.i, r.j, r.k]);
            let pair = pair_of(&j.bodies, &q, false);
            let theta = coordinate(&j, &pair, 0, reference).unwrap().v;
            assert!(
                (theta - expected).abs() < 1e-12,
                "turned {turned} reference {reference}: {theta} ≠ {expected}"
            );
        }
    }

    /// The value alone equals the jets' value bit for bit, for every joint kind and
    /// coordinate, on raw (non-unit) pairs and several branches.
    #[test]
    fn value_alone_equals_the_jets_value_bit_for_bit() {
        let kinds = [
            JointKind::Revolute,
            JointKind::Continuous,
            JointKind::Prismatic,
            JointKind::Fixed,
            JointKind::Floating,
            JointKind::Planar,
            JointKind::Spherical,
            JointKind::Universal,
            JointKind::Cylindrical,
            JointKind::Screw { pitch: 0.01 },
            JointKind::Distance { length: 0.3 },
            JointKind::PointOnLine,
        ];
        let (mut read, mut spread) = (0, 0);
        for kind in kinds {
            let mut j = revolute();
            j.kind = kind;
            j.bodies = [Some(BodyId(0)), Some(BodyId(1))];
            j.body_from_joint = [
                Isometry3::new(Vector3::new(0.1, -0.2, 0.3), Vector3::new(0.3, -0.2, 0.9)),
                Isometry3::new(Vector3::new(-0.2, 0.05, 0.4), Vector3::new(-0.5, 0.4, 0.1)),
            ];
            for seed in 0..4 {
                let pair = crate::jet::testing::sample_pair(seed);
                for dof in 0..7 {
                    for reference in [0.0, 7.0, -2.5] {
                        let jet = coordinate(&j, &pair, dof, reference).map(|s| s.v);
                        let value = coordinate_value(&j, &pair, dof, reference);
                        assert_eq!(jet, value, "{kind:?} dof {dof} seed {seed}");
                        read += usize::from(value.is_some());
                        // With the spread of `x₁` from the axis: the same value, bit for bit.
                        if let (0, Some((v, rho))) =
                            (dof, angle_value_and_spread(&j, &pair, reference))
                        {
                            assert_eq!(Some(v.to_bits()), value.map(f64::to_bits), "{kind:?}");
                            assert!((0.0..=1.0 + 1e-12).contains(&rho), "{kind:?}: ρ {rho}");
                            spread += 1;
                        }
                    }
                }
            }
        }
        assert!(read > 100);
        assert!(spread >= 36, "{spread}");
    }
}
