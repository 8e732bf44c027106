//! Universal joint: rotation about z of the parent and x of the child. Motion
//! `Rz(θ₁) Rx(θ₂)`; rows spherical + `z₀·x₁`; coordinates `θ₁` (about `z₀`) and
//! `θ₂ = atan2(z₀·y₁, z₀·z₁)`.

use super::spec::{
    angle, at, name, no_values, rx, rz, t, Frame, Read, Spec, TreeMotion, NOT_IN_URDF, PARALLEL,
    POS, V,
};
use super::JointKind;
use nalgebra::Isometry3;

pub(super) const SPEC: Spec = Spec {
    names: &[name("universal", false, true, true)],
    coordinates: &[
        angle(Read::Angle),
        angle(Read::Atan2([V::Z0, V::Y1], [V::Z0, V::Z1])),
    ],
    value_counts: &[2],
    units: &["rad", "rad"],
    has_limits: true,
    rows: &[POS[0], POS[1], POS[2], PARALLEL[0]],
    row_names: &["pos_x", "pos_y", "pos_z", "cross"],
    closed_form: true,
    frame: Frame::TwoAxes,
    tree_motion: TreeMotion::Coordinates,
    configuration: NOT_IN_URDF,
    values_of_motion: no_values,
    motion,
};

/// `Rz(θ₁) Rx(θ₂)`.
fn motion(_: &JointKind, v: &[f64]) -> Isometry3<f64> {
    Isometry3::from_parts(t(0.0, 0.0, 0.0), rz(at(v, 0)) * rx(at(v, 1)))
}
