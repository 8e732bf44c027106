//! The ground planes, the contact points with their forces, and the joints resting on a stop.
//!
//! A ground `n·(x − o) ≥ 0` is drawn as a square of side `4 L` (`L` the characteristic length)
//! centred on the mechanism's projection onto the plane, with a grid of lines every `L / 2`.
//! Each contact is a point coloured by its state (yellow touching, green sticking, red
//! slipping) with an arrow of the force the ground exerts on the link,
//! `f = f_n n + f_t`, scaled so the largest is one characteristic length. A joint resting on a
//! stop is a labelled orange point at its origin (and its axis arrow is orange). A free
//! mechanism standing on its contacts shows its support polygon (cyan, closed) and the
//! projection of its centre of mass along gravity (a point labelled with the stability
//! margin, cyan inside the polygon, red outside).

use super::shapes::{f3, sanitize};
use crate::model::Model;
use crate::solver::{ContactState, Report};
use crate::state::State;
use nalgebra::{Point3, Vector3};

type Logged = std::result::Result<(), rerun::RecordingStreamError>;

/// Colour of a joint axis resting on a stop.
pub(super) fn stop_color() -> rerun::Color {
    rerun::Color::from_rgb(255, 120, 0)
}

/// A unit vector perpendicular to `n` (unit).
fn perpendicular(n: &Vector3<f64>) -> Vector3<f64> {
    let helper = if n.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    n.cross(&helper).normalize()
}

/// Logs every ground plane as a square and a grid (static).
pub(super) fn log_grounds(rec: &rerun::RecordingStream, model: &Model, state: &State) -> Logged {
    let l = model.length_scale;
    let n_bodies = model.bodies.len().max(1) as f64;
    let centre = (0..model.bodies.len())
        .map(|b| state.q.fixed_rows::<3>(7 * b).into_owned())
        .fold(Vector3::zeros(), |a, x| a + x)
        / n_bodies;
    for g in &model.grounds {
        let n = g.normal.normalize();
        let (u, v) = {
            let u = perpendicular(&n);
            (u, n.cross(&u))
        };
        let c = centre - n * n.dot(&(centre - g.origin));
        let half = 2.0 * l;
        let corner = |a: f64, b: f64| f3(&(c + u * (a * half) + v * (b * half)));
        let path = format!("world/grounds/{}", sanitize(&g.name));
        rec.log_static(
            path.as_str(),
            &rerun::Mesh3D::new([
                corner(-1.0, -1.0),
                corner(1.0, -1.0),
                corner(1.0, 1.0),
                corner(-1.0, 1.0),
            ])
            .with_triangle_indices([[0, 1, 2], [0, 2, 3]])
            .with_vertex_normals([f3(&n); 4])
            .with_albedo_factor(rerun::Rgba32::from_rgb(205, 200, 185)),
        )?;
        let lines = 9;
        let mut strips = Vec::with_capacity(2 * lines);
        for k in 0..lines {
            let t = -1.0 + 2.0 * k as f64 / (lines - 1) as f64;
            strips.push([corner(t, -1.0), corner(t, 1.0)]);
            strips.push([corner(-1.0, t), corner(1.0, t)]);
        }
        // Lift the grid a hair above the square so that it is not hidden by it.
        let lift = f3(&(n * (1e-3 * l)));
        let strips: Vec<[[f32; 3]; 2]> = strips
            .into_iter()
            .map(|s| s.map(|p| [p[0] + lift[0], p[1] + lift[1], p[2] + lift[2]]))
            .collect();
        rec.log_static(
            format!("{path}/grid"),
            &rerun::LineStrips3D::new(strips)
                .with_colors([rerun::Color::from_rgb(150, 145, 130)])
                .with_radii([0.002 * l as f32]),
        )?;
    }
    Ok(())
}

/// Logs the contact points and forces of the rest pose.
pub(super) fn log_contacts(rec: &rerun::RecordingStream, model: &Model, report: &Report) -> Logged {
    if report.contacts.is_empty() {
        return Ok(());
    }
    let l = model.length_scale;
    let force = |c: &crate::solver::Contact| {
        Vector3::from(c.normal_world) * c.normal_force + Vector3::from(c.tangential_force)
    };
    let fmax = report
        .contacts
        .iter()
        .map(|c| force(c).norm())
        .fold(0.0, f64::max)
        .max(f64::MIN_POSITIVE);
    let color = |s: ContactState| match s {
        ContactState::Touching => rerun::Color::from_rgb(240, 200, 0),
        ContactState::Sticking => rerun::Color::from_rgb(30, 170, 70),
        ContactState::Slipping => rerun::Color::from_rgb(230, 30, 30),
    };
    let points: Vec<[f32; 3]> = report
        .contacts
        .iter()
        .map(|c| f3(&Vector3::from(c.point_world)))
        .collect();
    let colors: Vec<rerun::Color> = report.contacts.iter().map(|c| color(c.state)).collect();
    rec.log(
        "world/contacts/points",
        &rerun::Points3D::new(points.clone())
            .with_colors(colors.clone())
            .with_radii([0.02 * l as f32]),
    )?;
    let vectors: Vec<[f32; 3]> = report
        .contacts
        .iter()
        .map(|c| f3(&(force(c) * (l / fmax))))
        .collect();
    let labels: Vec<String> = report
        .contacts
        .iter()
        .map(|c| format!("{} {:.3} N", c.link, force(c).norm()))
        .collect();
    rec.log(
        "world/contacts/forces",
        &rerun::Arrows3D::from_vectors(vectors)
            .with_origins(points)
            .with_colors(colors)
            .with_labels(labels),
    )
}

/// Logs the joints resting on a stop as labelled points at their origins.
pub(super) fn log_stops(
    rec: &rerun::RecordingStream,
    model: &Model,
    state: &State,
    report: &Report,
) -> Logged {
    for stop in &report.active_limits {
        let Some(j) = model.joint_id(&stop.joint).map(|id| model.joint(id)) else {
            continue;
        };
        let origin = match j.bodies[1] {
            Some(b) => state.body_pose(b) * j.body_from_joint[1],
            None => j.body_from_joint[1],
        };
        let p = origin * Point3::origin();
        rec.log(
            format!("world/stops/{}", sanitize(&stop.joint)),
            &rerun::Points3D::new([f3(&p.coords)])
                .with_colors([stop_color()])
                .with_radii([0.03 * model.length_scale as f32])
                .with_labels([format!(
                    "{} on its {} stop {:.4}, effort {:.4}",
                    stop.joint, stop.bound, stop.value, stop.effort
                )]),
        )?;
    }
    Ok(())
}

/// Logs the support polygon and the centre of mass's projection (`report.balance`).
pub(super) fn log_balance(rec: &rerun::RecordingStream, model: &Model, report: &Report) -> Logged {
    let Some(b) = &report.balance else {
        return Ok(());
    };
    let l = model.length_scale;
    let cyan = rerun::Color::from_rgb(0, 190, 220);
    let corners: Vec<[f32; 3]> = b
        .support_polygon
        .iter()
        .map(|p| f3(&Vector3::from(*p)))
        .collect();
    let n = corners.len();
    let edges: Vec<[[f32; 3]; 2]> = (0..n)
        .filter(|&i| n > 2 || i + 1 < n)
        .map(|i| [corners[i], corners[(i + 1) % n]])
        .collect();
    if !edges.is_empty() {
        rec.log(
            "world/balance/support_polygon",
            &rerun::LineStrips3D::new(edges)
                .with_colors([cyan])
                .with_radii([0.004 * l as f32]),
        )?;
    }
    let inside = b.stability_margin >= 0.0;
    rec.log(
        "world/balance/com_projection",
        &rerun::Points3D::new([f3(&Vector3::from(b.com_projection))])
            .with_colors([if inside {
                cyan
            } else {
                rerun::Color::from_rgb(230, 30, 30)
            }])
            .with_radii([0.025 * l as f32])
            .with_labels([format!(
                "centre of mass, margin {:.4} m",
                b.stability_margin
            )]),
    )
}
