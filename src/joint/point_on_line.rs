//! Point-on-line joint: the child's joint origin stays on the parent's z line. Rows `x₀·d,
//! y₀·d`; no coordinate; placed at zero displacement.

use super::spec::{name, Frame, Spec, ON_AXIS};

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
    motion: super::fixed::identity,
};
