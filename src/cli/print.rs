//! Human-readable output: the analysis summary, the model as `check` understood it, and the
//! verification report. Everything here formats values it is given; nothing computes.

use restpose::export::json::AnalysisResult;
use restpose::export::summary::ModelSummary;
use restpose::verify::{Tolerances, Verification};

/// Writes a line to standard output; a closed pipe (`restpose analyze … | head`) is not an
/// error and must not panic.
macro_rules! out {
    ($($arg:tt)*) => {{
        use std::io::Write;
        let _ = writeln!(std::io::stdout().lock(), $($arg)*);
    }};
}
pub(crate) use out;

/// Whether an output path means standard output (`-`).
pub(crate) fn is_stdout(path: Option<&std::path::PathBuf>) -> bool {
    path.is_some_and(|p| p.as_os_str() == "-")
}

/// Writes JSON text to `path` atomically, or to standard output for `-`.
pub(crate) fn write_json(path: &std::path::Path, text: &str) -> anyhow::Result<()> {
    if path.as_os_str() == "-" {
        out!("{text}");
    } else {
        restpose::export::write_atomic(path, text.as_bytes())?;
    }
    Ok(())
}

/// Prints an import warning on standard error, with the library's hint for a missing
/// `package://` folder given as the `--package` option that supplies it.
pub(crate) fn warning(w: &str) {
    let hint = restpose::geometry::UNKNOWN_PACKAGE_HINT;
    let package = w
        .split("package `")
        .nth(1)
        .and_then(|rest| rest.split('`').next())
        .unwrap_or("NAME");
    eprintln!(
        "warning: {}",
        w.replace(hint, &format!("use --package {package}=DIR"))
    );
}

/// Writes a whole output file to `path` atomically, or to standard output for `-` (as is: the
/// text ends with its own newline; a closed pipe is not an error).
pub(crate) fn write_output(path: &std::path::Path, text: &str) -> anyhow::Result<()> {
    if path.as_os_str() == "-" {
        use std::io::Write;
        let mut stdout = std::io::stdout().lock();
        let _ = stdout
            .write_all(text.as_bytes())
            .and_then(|_| stdout.flush());
    } else {
        restpose::export::write_atomic(path, text.as_bytes())?;
    }
    Ok(())
}

/// The summary of a solve (`analyze`).
pub(crate) fn analysis(r: &AnalysisResult) {
    out!("robot `{}`", r.robot);
    out!(
        "  bodies {}, coordinates {}, constraint rows {} ({} redundant), degrees of freedom {}",
        r.bodies,
        r.coordinates,
        r.constraints,
        r.redundant_constraints.len(),
        r.dof
    );
    if !r.redundant_constraints.is_empty() {
        out!(
            "  redundant constraints: {}",
            r.redundant_constraints.join(", ")
        );
    }
    out!(
        "  independent coordinates: {}",
        r.independent_coordinates.join(", ")
    );
    out!();
    out!("  iteration   potential energy [J]   ‖∂V/∂v‖∞ [J]");
    for h in &r.history {
        out!(
            "  {:>9}   {:>20.9}   {:>12.3e}",
            h.iteration,
            h.potential_energy,
            h.gradient_norm
        );
    }
    out!();
    out!(
        "  {}: {} iterations, V = {:.9} J",
        r.termination,
        r.iterations,
        r.potential_energy
    );
    if let Some(s) = &r.stability {
        let eig: Vec<String> = s.eigenvalues.iter().map(|e| format!("{e:.4e}")).collect();
        out!(
            "  stability: {} (smallest reduced-Hessian eigenvalues {})",
            s.verdict,
            eig.join(", ")
        );
    }
    if let Some(mode) = r.stability.as_ref().and_then(|s| s.modes.first()) {
        let mut parts: Vec<(&String, f64)> = mode
            .iter()
            .flat_map(|(n, v)| v.iter().map(move |x| (n, *x)))
            .collect();
        parts.sort_by(|a, b| b.1.abs().total_cmp(&a.1.abs()));
        let shown: Vec<String> = parts
            .iter()
            .take(4)
            .map(|(n, x)| format!("{n} {x:+.3}"))
            .collect();
        out!(
            "  softest mode: {}{}",
            shown.join(", "),
            if parts.len() > 4 { ", …" } else { "" }
        );
    }
    out!();
    out!("  joint                          type          position");
    for (name, j) in &r.joints {
        let p: Vec<String> = j.position.iter().map(|v| format!("{v:.9}")).collect();
        out!(
            "  {:<30} {:<13} [{}]{}",
            name,
            j.kind,
            p.join(", "),
            units(&j.units)
        );
    }
    for v in &r.limit_violations {
        out!(
            "  warning: joint `{}` rests at {:.6}, outside its limits [{}, {}] (limits are not enforced)",
            v.joint, v.position, v.limits[0], v.limits[1]
        );
    }
    stops_and_contacts(&r.active_limits, &r.contacts);
    friction_and_balance(r.friction.as_ref(), r.balance.as_ref());
    if !r.reactions.is_empty() {
        out!();
        out!("  reaction on child at joint origin (world)   force [N]                          torque [N m]");
        for (name, re) in &r.reactions {
            let f = re.force_world;
            let t = re.torque_world;
            out!(
                "  {:<30} [{:>10.4}, {:>10.4}, {:>10.4}]   [{:>10.4}, {:>10.4}, {:>10.4}]",
                name,
                f[0],
                f[1],
                f[2],
                t[0],
                t[1],
                t[2]
            );
        }
    }
}

/// The units of a joint's coordinates after its values: ` rad` when they share one, ` [rad, m]`
/// when they differ, nothing for a joint without coordinates.
/// The joints resting on a stop and the contacts, with their forces (analyze and verify).
fn stops_and_contacts(
    limits: &[restpose::solver::ActiveLimit],
    contacts: &[restpose::solver::Contact],
) {
    if !limits.is_empty() {
        out!();
        out!("  joint resting on a stop          bound     position       effort [N m or N]");
        for l in limits {
            out!(
                "  {:<32} {:<9} {:>12.6}   {:>12.4}",
                l.joint,
                l.bound,
                l.value,
                l.effort
            );
        }
        for l in limits.iter().filter(|l| l.exceeds_effort_limit) {
            out!(
                "  warning: joint `{}` needs {:.4} on its {} stop, above its effort limit {}: the actuator cannot hold this pose",
                l.joint,
                l.effort.abs(),
                l.bound,
                l.effort_limit.unwrap_or_default()
            );
        }
    }
    if !contacts.is_empty() {
        out!();
        out!("  contact (link @ ground)          point [m]                              normal force [N]  needs μ   state");
        for c in contacts {
            let p = c.point_world;
            out!(
                "  {:<32} [{:>10.5}, {:>10.5}, {:>10.5}]   {:>14.4}  {:>8.4}   {}",
                format!("{} @ {}", c.link, c.ground),
                p[0],
                p[1],
                p[2],
                c.normal_force,
                c.required_friction,
                serde_json::to_value(c.state)
                    .ok()
                    .and_then(|v| v.as_str().map(str::to_owned))
                    .unwrap_or_default()
            );
        }
        let total: f64 = contacts.iter().map(|c| c.normal_force).sum();
        out!("  total normal force {total:.6} N");
    }
}

/// The friction verdict and the balance of a free mechanism (analyze and verify).
fn friction_and_balance(
    f: Option<&restpose::solver::FrictionVerdict>,
    b: Option<&restpose::solver::balance::Balance>,
) {
    if let Some(f) = f {
        let given = match (f.mu, f.margin) {
            (Some(mu), Some(m)) => format!(" (mu {mu}, margin {m:+.3e})"),
            _ => String::new(),
        };
        out!(
            "  friction: required_mu {:.6}{given}: {}",
            f.required_mu,
            if f.slipping {
                "SLIPPING, no contact forces inside the friction cones balance this pose"
            } else {
                "the contacts hold the pose"
            }
        );
    }
    if let Some(b) = b {
        let c = b.centre_of_mass;
        let p = b.com_projection;
        out!(
            "  balance: centre of mass [{:.5}, {:.5}, {:.5}], projected along gravity [{:.5}, {:.5}, {:.5}]",
            c[0], c[1], c[2], p[0], p[1], p[2]
        );
        out!(
            "  support polygon {} corners, stability margin {:.6} m{}",
            b.support_polygon.len(),
            b.stability_margin,
            if b.stability_margin < 0.0 {
                " (the centre of mass is outside the support polygon)"
            } else {
                ""
            }
        );
    }
}

fn units(u: &[&str]) -> String {
    match u.first() {
        None => String::new(),
        Some(first) if u.iter().all(|x| x == first) => format!(" {first}"),
        Some(_) => format!(" [{}]", u.join(", ")),
    }
}

/// The model as understood (`check`)'s text output with the body of the listing made beforehand by [`model_listing`]:
/// the header line (rows and degrees of freedom), the listing, the assembly error.
pub(crate) fn model_with_listing(s: &ModelSummary, listing: &[u8]) {
    use std::io::Write;
    // One buffered writer for the whole listing (standard output is line-buffered: a write
    // per line would be 20,000 system calls for a 10,000-joint model).
    let mut w = std::io::BufWriter::new(std::io::stdout().lock());
    let _ = writeln!(
        w,
        "robot `{}`: {} bodies, {} coordinates, {} constraint rows, {}",
        s.robot,
        s.bodies.len(),
        s.coordinates,
        s.constraints,
        s.dof.map_or(
            "does not assemble at the initial guess".to_string(),
            |d| format!("{d} degrees of freedom")
        )
    );
    let _ = w.write_all(listing);
    if let Some(e) = &s.assembly_error {
        let _ = writeln!(w, "  assembly: {e}");
    }
}

/// The part of `check`'s text output that does not depend on the check: gravity, links,
/// bodies, joints, springs and forces.
pub(crate) fn model_listing(s: &ModelSummary, w: &mut Vec<u8>) {
    use std::io::Write;
    macro_rules! out {
        ($($arg:tt)*) => {{
            let _ = writeln!(w, $($arg)*);
        }};
    }
    out!(
        "  gravity [{}, {}, {}] m/s²",
        s.gravity[0],
        s.gravity[1],
        s.gravity[2]
    );
    out!(
        "  links welded to the world: {}",
        if s.fixed_links.is_empty() {
            "none".to_string()
        } else {
            s.fixed_links.join(", ")
        }
    );
    out!("  bodies:");
    for b in &s.bodies {
        out!(
            "    {:<28} {:>10.4} kg   links: {}",
            b.name,
            b.mass,
            b.links.join(", ")
        );
    }
    out!("  joints:");
    for j in &s.joints {
        out!(
            "    {:<28} {:<13} {:<7} {} -> {}  ({} rows)",
            j.name,
            j.kind,
            j.role,
            j.parent,
            j.child,
            j.rows
        );
    }
    for sp in &s.springs {
        out!("  spring {sp}");
    }
    for f in &s.forces {
        out!("  {f}");
    }
}

/// The verification of a pose (`verify`).
pub(crate) fn verification(robot: &str, v: &Verification, tol: &Tolerances) {
    out!(
        "robot `{}`: pose {}",
        robot,
        if v.passed { "PASSES" } else { "FAILS" }
    );
    out!(
        "  constraint residual {:.3e} (tolerance {:.1e}), potential energy {:.9} J",
        v.constraint_residual,
        tol.constraint,
        v.potential_energy
    );
    for c in &v.closure {
        out!(
            "  {} `{}`: position error {:.3e} m, rotation error {:.3e} rad",
            if c.loop_joint { "loop joint" } else { "joint" },
            c.joint,
            c.position_error,
            c.rotation_error
        );
    }
    out!("  joint                          dof   effort to hold [N m or N]");
    for i in &v.imbalance {
        let flag = if i.effort.abs() > v.effort_tolerance {
            "  <- out of balance"
        } else {
            ""
        };
        out!("  {:<30} {:>3}   {:>14.6e}{flag}", i.joint, i.dof, i.effort);
    }
    if v.unassigned > v.effort_tolerance {
        out!(
            "  unassigned generalized force {:.3e} (spherical or floating joints)",
            v.unassigned
        );
    }
    stops_and_contacts(&v.unilateral.active_limits, &v.unilateral.contacts);
    friction_and_balance(v.unilateral.friction.as_ref(), None);
    if v.unilateral.contacts.len() + v.unilateral.active_limits.len() > 0 {
        out!(
            "  penetration {:.3e}, complementarity max |g λ| {:.3e} J",
            v.unilateral.penetration,
            v.unilateral.complementarity
        );
    }
    if let Some(s) = &v.stability {
        out!("  stability: {}", s.verdict);
    }
}
