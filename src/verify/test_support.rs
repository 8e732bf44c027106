//! Helpers of the `verify` tests: models from URDF text, and the comparison of `analyze`'s
//! self-check (`Eigenvalues::Skip`, its own partition) with `verify`'s report at one pose.

use super::Verification;
use crate::model::Model;

/// The model of URDF `text`, on a floating base if `floating`.
pub(super) fn model(text: &str, floating: bool) -> Model {
    let options = crate::urdf::ImportOptions {
        floating_base: floating,
        ..Default::default()
    };
    crate::urdf::load_str(text, "t.urdf", &options)
        .unwrap()
        .model
}

/// Asserts that the self-check's report `s` says what `verify`'s `v` says at the same pose:
/// the same pass, residual, force scale, unassigned force and energy, and the same joints'
/// efforts in the same order. Returns the largest difference of the efforts, NaN if any is
/// (the failures' texts, in `unilateral`, quote the efforts: the callers whose efforts agree
/// exactly compare them).
pub(super) fn same_report(v: &Verification, s: &Verification, what: &str) -> f64 {
    assert_eq!(v.passed, s.passed, "{what}");
    assert_eq!(
        v.scaled_constraint_residual, s.scaled_constraint_residual,
        "{what}"
    );
    assert_eq!(v.force_scale, s.force_scale, "{what}");
    assert_eq!(v.unassigned, s.unassigned, "{what}");
    assert_eq!(v.potential_energy, s.potential_energy, "{what}");
    assert_eq!(v.imbalance.len(), s.imbalance.len(), "{what}");
    let mut worst = 0.0f64;
    for (a, b) in v.imbalance.iter().zip(&s.imbalance) {
        assert_eq!(
            (&a.joint, a.dof, a.locked),
            (&b.joint, b.dof, b.locked),
            "{what}"
        );
        // A NaN difference sticks (and fails the callers' bounds).
        let d = (a.effort - b.effort).abs();
        if d.is_nan() || d > worst {
            worst = d;
        }
    }
    worst
}
