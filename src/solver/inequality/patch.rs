//! Rounded hulls roll on one sticking pivot. A mesh foot is a convex hull of many vertices
//! (Solo's 1,705, Go2's 329) approximating a rounded surface. Held where each vertex first
//! touched (module `active_set`), two sticking vertices a millimetre apart clamp the foot: the
//! pair transmits a moment `M` by opposite normal forces `±M / d` (±4·10⁴ N on the Solo-12's
//! feet), and when the pulling one is released its tangential rows go with it, so the step of
//! the next round slides it back into the ground instead of lifting it; the guard stops it at
//! once and anchors it a little further on. The foot crawls by such hops, about 10⁻⁶ J per
//! round, and the search ends at `max_iterations` (Go2, Solo, Solo-12 standing, issue 21).
//!
//! A rigid body touching a plane at nearby points of a rounded surface is held tangentially by
//! one of them, its pivot; the others within the patch radius
//!
//! `δ = PATCH_FRACTION · D`  (`D` the diagonal of the box around the link's contact points)
//!
//! of a pivot on the same ground push along the normal only (no friction of their own), so the
//! multiplier of the pivot's gap is the rate of lifting it about its neighbours, and a pivot
//! that pulls hands its role to the touching neighbour nearest to it, anchored where that one
//! touches: the polygon rolls from vertex to vertex as a real foot rolls. Points farther apart
//! (a box's corners) each stick where they touched, as before.

use crate::constraints::unilateral::{Active, Unilateral};
use crate::model::Model;
use crate::solver::options::Options;
use nalgebra::DVector;

/// The patch radius as a fraction of the diagonal of the link's contact points (module docs).
pub(crate) const PATCH_FRACTION: f64 = 0.1;

/// `δ` of the link carrying contact point `point` (module docs).
fn patch_radius(model: &Model, point: usize) -> f64 {
    let c = &model.contact_points[point];
    let mut lo = c.point;
    let mut hi = c.point;
    for p in model
        .contact_points
        .iter()
        .filter(|p| p.body == c.body && p.link == c.link)
    {
        lo = lo.inf(&p.point);
        hi = hi.sup(&p.point);
    }
    PATCH_FRACTION * (hi - lo).norm()
}

/// Whether contact `point` on `ground` lies within the patch of a sticking pivot among
/// `active` (same body, same link, same ground).
fn near_pivot(model: &Model, active: &[Active], point: usize, ground: usize) -> bool {
    let c = &model.contact_points[point];
    let delta = patch_radius(model, point);
    active.iter().any(|a| match (a.anchor, a.row) {
        (
            Some(_),
            Unilateral::Contact {
                point: p,
                ground: g,
            },
        ) if g == ground && p != point => {
            let o = &model.contact_points[p];
            o.body == c.body && o.link == c.link && (o.point - c.point).norm() <= delta
        }
        _ => false,
    })
}

/// `u` made active at `q` (`active_set::activate`), without tangential rows when it lies on
/// the patch of a sticking pivot among `active`.
pub(crate) fn activate(
    model: &Model,
    options: &Options,
    active: &[Active],
    u: Unilateral,
    q: &DVector<f64>,
) -> Active {
    let mut a = super::active_set::activate(model, options, u, q);
    if let (Some(_), Unilateral::Contact { point, ground }) = (a.anchor, u) {
        if near_pivot(model, active, point, ground) {
            a.anchor = None;
        }
    }
    a
}

/// After the sticking pivots among `removed` left the set, each hands its role to the touching
/// contact of its patch nearest to it that has no anchor but would stick, anchored where it
/// touches at `q` (module docs).
pub(crate) fn promote(
    model: &Model,
    options: &Options,
    active: &mut [Active],
    removed: &[Active],
    q: &DVector<f64>,
) {
    for r in removed {
        let (Some(_), Unilateral::Contact { point, ground }) = (r.anchor, r.row) else {
            continue;
        };
        let c = &model.contact_points[point];
        let delta = patch_radius(model, point);
        let candidate = active
            .iter()
            .enumerate()
            .filter_map(|(i, a)| match (a.anchor, a.row) {
                (
                    None,
                    Unilateral::Contact {
                        point: p,
                        ground: g,
                    },
                ) if g == ground => {
                    let o = &model.contact_points[p];
                    let d = (o.point - c.point).norm();
                    (o.body == c.body
                        && o.link == c.link
                        && d <= delta
                        && options.contact().sticks(&o.settings))
                    .then_some((i, p, d))
                }
                _ => None,
            })
            .min_by(|a, b| a.2.total_cmp(&b.2));
        if let Some((i, p, _)) = candidate {
            if !near_pivot(model, active, p, ground) {
                active[i] = super::active_set::activate(model, options, active[i].row, q);
            }
        }
    }
}
