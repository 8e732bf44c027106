//! Where a base pose applies: `mech:base` and [`super::ImportOptions::base_pose`] place the
//! floating root link, a body that is no tree joint's child (`State::initial`). A model whose
//! root is fixed to the world has none (a body hung from the world by a `floating` joint is that
//! joint's child, placed by its initial value). A file's `mech:base` is the start *when the base
//! floats* (a result written by a floating-base analysis carries one, and may be read with its
//! base fixed); a base pose given to the importer for a model with no floating root is refused
//! rather than silently ignored.

use crate::model::Model;

/// Why a base pose cannot apply.
pub(super) const NO_FLOATING_ROOT: &str =
    "the importer's base pose (`base_pose`) places the floating root link, and this \
    model has none (its root is fixed to the world, and every moving link hangs from a joint): \
    let the root link float (`floating_base`), or give a `floating` joint's start as its \
    initial value (`mech:initial`: x, y, z, then the unit quaternion w, x, y, z)";

/// Whether some body is no tree joint's child: a floating root, which a base pose places.
pub(super) fn has_floating_root(model: &Model) -> bool {
    let mut child = vec![false; model.bodies.len()];
    for j in model.joints.iter().filter(|j| j.tree && !j.merged) {
        if let Some(c) = j.bodies[1] {
            child[c.index()] = true;
        }
    }
    child.iter().any(|c| !c)
}
