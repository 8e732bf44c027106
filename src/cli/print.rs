//! Human-readable output: the analysis summary and the model as `check` understood it (the
//! verification report is module `report`). Everything here formats values it is given;
//! nothing computes.

use restpose::export::json::AnalysisResult;
use restpose::export::summary::ModelSummary;

/// Writes a line to standard output; a closed pipe (`restpose analyze … | head`) is not an
/// error and must not panic.
macro_rules! out {
    ($($arg:tt)*) => {{
        use std::io::Write;
        let _ = writeln!(std::io::stdout().lock(), $($arg)*);
    }};
}
pub(crate) use out;

/// `eprintln!` that ignores a closed standard error (EPIPE: `restpose … 2>&1 | head -c 0`)
/// instead of panicking: the exit code stays the command's own.
macro_rules! note {
    ($($arg:tt)*) => {{
        use std::io::Write;
        let _ = writeln!(std::io::stderr().lock(), $($arg)*);
    }};
}
pub(crate) use note;

/// Whether an output path means standard output (`-`).
pub(crate) fn is_stdout(path: Option<&std::path::PathBuf>) -> bool {
    path.is_some_and(|p| p.as_os_str() == "-")
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
    note!(
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
    // The rows of the stops and contacts the rest pose rests on are counted (1 each, 3 for a
    // contact held tangentially): `check` counts the model's rows without them.
    let resting = r.active_limits.len()
        + r.contacts
            .iter()
            .map(|c| match c.state {
                restpose::solver::ContactState::Touching => 1,
                _ => 3,
            })
            .sum::<usize>();
    if resting == 0 {
        out!(
            "  bodies {}, coordinates {}, constraint rows {} ({} redundant), degrees of freedom {}",
            r.bodies,
            r.coordinates,
            r.constraints,
            r.redundant_constraints.len(),
            r.dof
        );
    } else {
        out!(
            "  bodies {}, coordinates {}, constraint rows {} ({} of stops and contacts at rest, {} redundant), degrees of freedom {} (with them held)",
            r.bodies,
            r.coordinates,
            r.constraints,
            resting,
            r.redundant_constraints.len(),
            r.dof
        );
    }
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
    for t in &r.topple {
        out!("  {}", t.describe());
    }
    out!();
    // Load steps and active-set rounds get their own columns when there is more than one.
    let staged = r.history.iter().any(|h| h.load_step != 1 || h.round != 1);
    if staged {
        out!("  load step   round   iteration   potential energy [J]   ‖∂V/∂v‖∞ [J]");
    } else {
        out!("  iteration   potential energy [J]   ‖∂V/∂v‖∞ [J]");
    }
    for h in &r.history {
        let stage = if !staged {
            String::new()
        } else if h.load_step == 0 {
            format!("{:>9}   {:>5}   ", "direct", h.round)
        } else {
            format!("{:>9}   {:>5}   ", h.load_step, h.round)
        };
        out!(
            "  {stage}{:>9}   {:>20.9}   {:>12.3e}",
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
        if eig.is_empty() {
            out!("  stability: {}", s.verdict);
        } else {
            out!(
                "  stability: {} (smallest eigenvalues of d²V/dθ² [N m/rad, N/m]: {})",
                s.verdict,
                eig.join(", ")
            );
        }
    }
    if let Some(mode) = r.stability.as_ref().and_then(|s| s.modes.first()) {
        let mut parts: Vec<(String, f64)> = mode
            .iter()
            .flat_map(|(n, v)| {
                let many = v.len() > 1;
                v.iter()
                    .enumerate()
                    .map(move |(k, x)| (if many { format!("{n}[{k}]") } else { n.clone() }, *x))
            })
            .filter(|p| p.1 != 0.0)
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
    let position = |name: &str| {
        r.joints
            .iter()
            .find(|(n, _)| n == name)
            .and_then(|(_, j)| j.position.first().copied())
    };
    stops_and_contacts(&r.active_limits, &r.contacts, &position);
    if !r.servos.is_empty() {
        out!();
        out!("  servo (actuator)                 reference     position      torque [N m or N]");
        for v in &r.servos {
            out!(
                "  {:<32} {:>9.6} {:>12.6}   {:>12.4}",
                v.joint,
                v.reference,
                v.position,
                v.torque
            );
        }
    }
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
/// The stops and contacts a pose rests on. A stop carrying no effort (below 5e-5, shown as
/// 0.0000) is only named on one line; `position` (the joint's coordinate, where known) marks a
/// joint beyond its stop.
pub(crate) fn stops_and_contacts(
    limits: &[restpose::solver::ActiveLimit],
    contacts: &[restpose::solver::Contact],
    position: &dyn Fn(&str) -> Option<f64>,
) {
    let (carrying, idle): (Vec<_>, Vec<_>) = limits.iter().partition(|l| l.effort.abs() >= 5e-5);
    if !carrying.is_empty() {
        out!();
        out!("  joint resting on a stop          bound     position       effort [N m or N]");
        for l in carrying {
            let beyond = position(&l.joint)
                .map(|p| {
                    if l.bound == "lower" {
                        l.value - p
                    } else {
                        p - l.value
                    }
                })
                .filter(|d| *d > 1e-6)
                .map(|d| format!("   beyond the stop by {d:.3e}"))
                .unwrap_or_default();
            out!(
                "  {:<32} {:<9} {:>12.6}   {:>12.4}{beyond}",
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
    if !idle.is_empty() {
        let names: Vec<&str> = idle.iter().take(6).map(|l| l.joint.as_str()).collect();
        out!(
            "  touching a stop without effort: {} joint{} ({}{})",
            idle.len(),
            if idle.len() == 1 { "" } else { "s" },
            names.join(", "),
            if idle.len() > names.len() {
                ", …"
            } else {
                ""
            }
        );
    }
    if !contacts.is_empty() {
        out!();
        out!("  contact (link @ ground)          point [m]                              normal force [N]  needs μ   state");
        // Beyond 40 contacts, the 20 deepest in the ground or carrying the most.
        let mut shown: Vec<&restpose::solver::Contact> = contacts.iter().collect();
        if shown.len() > 40 {
            shown.sort_by(|a, b| {
                a.gap
                    .total_cmp(&b.gap)
                    .then(b.normal_force.total_cmp(&a.normal_force))
            });
            shown.truncate(20);
        }
        for c in &shown {
            let p = c.point_world;
            out!(
                "  {:<32} [{:>10.5}, {:>10.5}, {:>10.5}]   {:>14.4}  {:>8}   {}",
                format!("{} @ {}", c.link, c.ground),
                p[0],
                p[1],
                p[2],
                c.normal_force,
                mu_text(c.required_friction, 4),
                serde_json::to_value(c.state)
                    .ok()
                    .and_then(|v| v.as_str().map(str::to_owned))
                    .unwrap_or_default()
            );
        }
        if shown.len() < contacts.len() {
            out!(
                "  … {} more contacts (the JSON lists every one)",
                contacts.len() - shown.len()
            );
        }
        let total: f64 = contacts.iter().map(|c| c.normal_force).sum();
        out!("  total normal force {total:.6} N");
    }
}

/// A friction coefficient with `digits` decimals; `unbounded` for a contact that would carry
/// friction without pushing (the need `f64::MAX` of `solver::friction::needs_mu`).
fn mu_text(mu: f64, digits: usize) -> String {
    if mu >= f64::MAX {
        "unbounded".into()
    } else {
        format!("{mu:.digits$}")
    }
}

/// The friction verdict and the balance of a free mechanism (analyze and verify).
pub(crate) fn friction_and_balance(
    f: Option<&restpose::solver::FrictionVerdict>,
    b: Option<&restpose::solver::balance::Balance>,
) {
    if let Some(f) = f {
        let given = match (f.mu, f.margin) {
            (Some(mu), Some(m)) if m.is_finite() && m.abs() < 1e300 => {
                format!(" (mu {mu}, margin {m:+.3e})")
            }
            (Some(mu), Some(_)) => format!(" (mu {mu})"),
            _ => String::new(),
        };
        out!(
            "  friction: required_mu {}{given}: {}",
            mu_text(f.required_mu, 6),
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
    // `{:<W}` by hand (the text, then spaces to W characters): one line per body and joint,
    // 20,000 lines at 10,000 links, where the formatter's padding was most of the listing.
    let padded = |w: &mut Vec<u8>, text: &str, width: usize| {
        w.extend_from_slice(text.as_bytes());
        let chars = if text.is_ascii() {
            text.len()
        } else {
            text.chars().count()
        };
        w.resize(w.len() + width.saturating_sub(chars), b' ');
    };
    out!("  bodies:");
    for b in &s.bodies {
        w.extend_from_slice(b"    ");
        padded(w, &b.name, 28);
        let _ = write!(w, " {:>10.4} kg   links: ", b.mass);
        for (k, l) in b.links.iter().enumerate() {
            if k > 0 {
                w.extend_from_slice(b", ");
            }
            w.extend_from_slice(l.as_bytes());
        }
        w.push(b'\n');
    }
    out!("  joints:");
    for j in &s.joints {
        w.extend_from_slice(b"    ");
        padded(w, &j.name, 28);
        w.push(b' ');
        padded(w, &j.kind, 13);
        w.push(b' ');
        padded(w, &j.role, 7);
        let _ = writeln!(w, " {} -> {}  ({} rows)", j.parent, j.child, j.rows);
    }
    for sp in &s.springs {
        out!("  spring {sp}");
    }
    for f in &s.forces {
        out!("  {f}");
    }
}
