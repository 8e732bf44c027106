//! The verification report (`verify`): the verdict, the efforts, the stops and contacts, and
//! the failures for standard error, a few of each kind. Formatting only.

use super::print::{out, stops_and_contacts};
use restpose::verify::{Tolerances, Verification};

/// Lines of each kind of failure shown (the largest first, as `verify` lists them).
const SHOWN_PER_KIND: usize = 5;

/// The verdict line of `verify` (all that `verify -q` prints on standard output).
pub(crate) fn verdict(robot: &str, v: &Verification) {
    out!(
        "robot `{}`: pose {}",
        robot,
        if v.passed { "PASSES" } else { "FAILS" }
    );
}

/// The failures of a verification for standard error: at most [`SHOWN_PER_KIND`] of each
/// kind (inside a ground, beyond a stop, pulling, slipping, efforts, ...) in their order, then
/// how many more of that kind there are.
pub(crate) fn failures(failures: &[String]) -> Vec<String> {
    fn kind(f: &str) -> &'static str {
        [
            "inside the ground",
            "beyond its stop",
            "would have to pull",
            "needs friction",
            "needs an effort",
        ]
        .into_iter()
        .find(|k| f.contains(k))
        .unwrap_or("other")
    }
    let mut seen: Vec<(&str, usize)> = Vec::new();
    let mut out = Vec::new();
    for f in failures {
        let k = kind(f);
        let n = match seen.iter_mut().find(|s| s.0 == k) {
            Some(s) => {
                s.1 += 1;
                s.1
            }
            None => {
                seen.push((k, 1));
                1
            }
        };
        if n <= SHOWN_PER_KIND {
            out.push(f.clone());
        }
    }
    for (k, n) in seen {
        if n > SHOWN_PER_KIND {
            out.push(format!(
                "… and {} more of that kind (`{k}`; {n} in all; the JSON lists every one)",
                n - SHOWN_PER_KIND
            ));
        }
    }
    out
}

/// The verification of a pose (`verify`). Up to 40 joint coordinates are all listed; beyond,
/// the 20 needing the largest efforts and a count.
pub(crate) fn verification(robot: &str, v: &Verification, tol: &Tolerances) {
    verdict(robot, v);
    out!(
        "  constraint residual {:.3e} (tolerance {:.1e}), potential energy {:.9} J",
        v.scaled_constraint_residual,
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
    let mut shown: Vec<&restpose::verify::Imbalance> = v.imbalance.iter().collect();
    if shown.len() > 40 {
        shown.sort_by(|a, b| b.effort.abs().total_cmp(&a.effort.abs()));
        shown.truncate(20);
    }
    for i in &shown {
        let flag = if i.locked {
            "  (held by a lock)"
        } else if i.effort.abs() > v.effort_tolerance {
            "  <- out of balance"
        } else {
            ""
        };
        out!("  {:<30} {:>3}   {:>14.6e}{flag}", i.joint, i.dof, i.effort);
    }
    if shown.len() < v.imbalance.len() {
        let out_of_balance = v
            .imbalance
            .iter()
            .filter(|i| !i.locked && i.effort.abs() > v.effort_tolerance)
            .count();
        out!(
            "  … {} more coordinates ({} of {} out of balance; the JSON lists every one)",
            v.imbalance.len() - shown.len(),
            out_of_balance,
            v.imbalance.len()
        );
    }
    if v.unassigned > v.effort_tolerance {
        out!(
            "  unassigned generalized force {:.3e} (spherical or floating joints)",
            v.unassigned
        );
    }
    stops_and_contacts(&v.unilateral.active_limits, &v.unilateral.contacts, &|_| {
        None
    });
    super::print::friction_and_balance(v.unilateral.friction.as_ref(), None);
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
