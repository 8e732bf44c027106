//! Joint position limits from `<limit lower upper>`: `[lower, upper]` of the joint's first
//! coordinate, `lower ≤ q ≤ upper` when limits are enforced. URDF joints are read as urdfdom
//! reads them (a missing bound is 0), with a located warning where that reading is unusual.

use super::dom::Node;
use super::xml::{child, Source};
use crate::error::Result;
use crate::model::JointKind;

/// Position limits from `<limit lower upper>` (a missing bound is 0, as in urdfdom);
/// `lower > upper` is an error.
pub(super) fn limits(src: &Source, node: Node) -> Result<Option<[f64; 2]>> {
    let Some(l) = child(node, "limit") else {
        return Ok(None);
    };
    match (src.f64_opt(l, "lower")?, src.f64_opt(l, "upper")?) {
        (None, None) => Ok(None),
        (lo, hi) => {
            let (lo, hi) = (lo.unwrap_or(0.0), hi.unwrap_or(0.0));
            if lo > hi {
                return Err(src.error(
                    l,
                    format!(
                        "{}: <limit> has lower {lo} > upper {hi}",
                        src.describe(node)
                    ),
                ));
            }
            Ok(Some([lo, hi]))
        }
    }
}

/// Position limits of a URDF `<joint>`, read as urdfdom does, with a located warning where
/// that reading may not be what the author meant:
/// - `lower > upper` (Bullet's and pybullet's way to write "no limit", e.g. `lower="1"
///   upper="-1"`): no limits, as Bullet reads it (urdfdom accepts the file);
/// - a `<limit>` with neither `lower` nor `upper` on a revolute or prismatic joint (`effort`
///   and `velocity` only): `[0, 0]`, as urdfdom (and so Pinocchio, MoveIt) reads it, which
///   holds the joint at 0 while limits are enforced.
pub(super) fn urdf_limits(
    src: &Source,
    node: Node,
    kind: JointKind,
    warnings: &mut Vec<String>,
) -> Result<Option<[f64; 2]>> {
    let Some(l) = child(node, "limit") else {
        return Ok(None);
    };
    let bounded = matches!(kind, JointKind::Revolute | JointKind::Prismatic);
    match (src.f64_opt(l, "lower")?, src.f64_opt(l, "upper")?) {
        (None, None) if bounded => {
            warnings.push(src.warning(
                l,
                format!(
                    "{}: <limit> has no lower and no upper: read as [0, 0], as urdfdom reads it, \
                     which holds the joint at 0 while limits are enforced (give lower and upper, \
                     or make it continuous, for a free joint; --limits ignore frees it)",
                    src.describe(node)
                ),
            ));
            Ok(Some([0.0, 0.0]))
        }
        (None, None) => Ok(None),
        (lo, hi) => {
            let (lo, hi) = (lo.unwrap_or(0.0), hi.unwrap_or(0.0));
            if lo > hi {
                if bounded {
                    warnings.push(src.warning(
                        l,
                        format!(
                            "{}: <limit> has lower {lo} > upper {hi}, Bullet's way of saying \
                             \"no limit\": the joint is treated as unlimited",
                            src.describe(node)
                        ),
                    ));
                }
                return Ok(None);
            }
            Ok(Some([lo, hi]))
        }
    }
}
