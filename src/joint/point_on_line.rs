//! Point-on-line joint: the child's joint origin stays on the parent's z line. Rows `x₀·d,
//! y₀·d`; no coordinate; placed at zero displacement.

use super::spec::{name, no_values, Frame, Spec, TreeMotion, NOT_IN_URDF, ON_AXIS};

pub(super) const SPEC: Spec = Spec {
    names: &[name("point_on_line", false, true, false)],
    coordinates: &[],
    value_counts: &[0],
    units: &[],
    has_limits: false,
    rows: &ON_AXIS,
    row_names: &["line_x", "line_y"],
    closed_form: true,
    frame: Frame::Axis,
    tree_motion: TreeMotion::Pose,
    configuration: NOT_IN_URDF,
    values_of_motion: no_values,
    motion: super::fixed::identity,
};
