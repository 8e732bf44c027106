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
//! touches: the polygon rolls from vertex to vertex as a real foot rolls (a neighbour leaves
//! only at a stationary point, not early: module `release`). Points farther apart
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
pub(crate) fn near_pivot(model: &Model, active: &[Active], point: usize, ground: usize) -> bool {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Friction;
    use crate::urdf::{load_str, ImportOptions};

    /// A floating rod 1 × 0.01 × 0.01 m (a box: its corners at one end 0.01–0.014 m apart,
    /// within `δ = 0.1 · 1.0001` m; the two ends 1 m apart) above a ground, sticking.
    fn rod() -> (Model, Options, DVector<f64>) {
        let text = r#"<robot name="rod" xmlns:mech="urn:urdf-mech:1">
  <link name="rod"><inertial><mass value="1"/><inertia ixx="1e-4" ixy="0" ixz="0" iyy="0.08" iyz="0" izz="0.08"/></inertial>
    <collision><geometry><box size="1 0.01 0.01"/></geometry></collision></link>
  <mech:ground xyz="0 0 -1"/>
</robot>"#;
        let options = ImportOptions {
            floating_base: true,
            ..Default::default()
        };
        let model = load_str(text, "rod.urdf", &options).unwrap().model;
        let opts = Options {
            friction: Friction::Stick,
            ..Default::default()
        };
        let q = crate::State::initial(&model).q;
        (model, opts, q)
    }

    #[test]
    fn the_neighbours_of_a_pivot_push_only_and_take_over_when_it_leaves() {
        let (model, opts, q) = rod();
        assert_eq!(model.contact_points.len(), 8);
        let at = |x: f64| -> Vec<usize> {
            (0..8)
                .filter(|&k| (model.contact_points[k].point.x - x).abs() < 1e-12)
                .collect()
        };
        let (near, far) = (at(-0.5), at(0.5));
        assert_eq!((near.len(), far.len()), (4, 4));
        let mut active: Vec<Active> = Vec::new();
        for &k in near.iter().chain(&far[..1]) {
            let u = Unilateral::Contact {
                point: k,
                ground: 0,
            };
            let a = activate(&model, &opts, &active, u, &q);
            active.push(a);
        }
        // One pivot at each end: the first corner of the near end, the far corner.
        let anchored: Vec<bool> = active.iter().map(|a| a.anchor.is_some()).collect();
        assert_eq!(anchored, [true, false, false, false, true]);
        // The near pivot leaves: its nearest neighbour takes over, held where it is.
        let pivot = active.remove(0);
        promote(&model, &opts, &mut active, &[pivot], &q);
        let dist = |a: &Active| match a.row {
            Unilateral::Contact { point, .. } => {
                (model.contact_points[point].point - model.contact_points[near[0]].point).norm()
            }
            Unilateral::Limit { .. } => f64::INFINITY,
        };
        let nearest = (0..3)
            .min_by(|&i, &j| dist(&active[i]).total_cmp(&dist(&active[j])))
            .unwrap();
        for (i, a) in active.iter().enumerate().take(3) {
            assert_eq!(a.anchor.is_some(), i == nearest, "corner {i}");
        }
        assert!(active[3].anchor.is_some());
        // Frictionless, no contact is anchored and none is promoted.
        let none = Options::default();
        let u = Unilateral::Contact {
            point: near[0],
            ground: 0,
        };
        assert!(activate(&model, &none, &[], u, &q).anchor.is_none());
    }
}
