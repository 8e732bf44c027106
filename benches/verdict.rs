//! Whole-process time of `restpose analyze --friction stick` (the friction verdict's cost)
//! against baseline binaries run alternately in the same series (plain harness: the machine's
//! speed drifts, so only ratios measured side by side mean anything).
//!
//! `cargo bench --bench verdict -- [RUNS] [NAME=BINARY …]`
//!
//! RUNS (default 60) runs of each case by each binary, in the order this build, then each
//! baseline, repeated (ABAB…). Baselines default to `main=$RESTPOSE_MAIN` (else
//! `~/.cache/restpose-target/release/restpose`, CI's build of main) when that file exists.
//! Cases (every run must exit 0 and, for this build, print `friction:`):
//! - `crate-ramp`: docs/crate_on_ramp.urdf, four sticking corners on a 0.35 rad ramp, `--mu 1`
//!   (cone programs run: the corners are statically indeterminate and need friction);
//! - `crate-level`: the same crate with gravity along the ramp's normal (no friction needed);
//! - `solo12-sprung`: robots/solo12 standing on its leg springs (feet determinate);
//! - `solo12-locked-0.2`: the same with its 12 joints locked, gravity tilted by 0.2 rad (a
//!   rigid body on four feet: indeterminate, `required_mu = tan 0.2`);
//! - `a1-servo`: example-robot-data's A1 with `--servo all=200` about its SRDF `standing`
//!   state (when `~/.cache/restpose-corpus` holds the unpacked corpus of scripts/corpus.sh).
//!
//! With `--instructions`, each case is also run once by each binary under valgrind's callgrind
//! (when `valgrind` is on the PATH): the instructions executed, a count that does not drift
//! with the machine's load, and their ratio to this build's.
//!
//! Prints per case and binary the median and the lower quartile of the wall time [ms] (the
//! lower quartile is the steadier on a loaded machine), their ratios to this build's
//! (`median_ratio` > 1: that binary is slower) and this build's time minus that binary's.
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

const EXE: &str = env!("CARGO_BIN_EXE_restpose");

/// One case: name, working directory, arguments.
struct Case {
    name: &'static str,
    dir: PathBuf,
    args: Vec<String>,
}

fn cases() -> Vec<Case> {
    let repo = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let s = |v: &[&str]| v.iter().map(|x| x.to_string()).collect::<Vec<_>>();
    let (a, g) = (0.35f64, 9.81);
    let level = [-g * a.sin(), 0.0, -g * a.cos()].map(|x| format!("{x}"));
    let crate_args = s(&[
        "analyze",
        "docs/crate_on_ramp.urdf",
        "--floating-base",
        "--friction",
        "stick",
        "--mu",
        "1",
        "-q",
    ]);
    let mut level_args = crate_args.clone();
    level_args.extend(["--gravity".to_string()].into_iter().chain(level));
    let mut locks = Vec::new();
    for leg in ["FL", "FR", "HL", "HR"] {
        let f = if leg.starts_with('F') { 1.0 } else { -1.0 };
        for (j, v) in [("HAA", 0.0), ("HFE", 0.8 * f), ("KFE", -1.6 * f)] {
            locks.push("--lock".to_string());
            locks.push(format!("{leg}_{j}={v}"));
        }
    }
    let solo = s(&[
        "analyze",
        "robots/solo12/solo12_ground.urdf",
        "--floating-base",
        "--friction",
        "stick",
        "--mu",
        "0.8",
        "-q",
    ]);
    let mut solo_locked = solo.clone();
    solo_locked.extend(locks);
    let b = 0.2f64;
    solo_locked.extend(
        ["--gravity".to_string()]
            .into_iter()
            .chain([-g * b.sin(), 0.0, -g * b.cos()].map(|x| format!("{x}"))),
    );
    let mut out = vec![
        Case {
            name: "crate-ramp",
            dir: repo.clone(),
            args: crate_args,
        },
        Case {
            name: "crate-level",
            dir: repo.clone(),
            args: level_args,
        },
        Case {
            name: "solo12-sprung",
            dir: repo.clone(),
            args: solo,
        },
        Case {
            name: "solo12-locked-0.2",
            dir: repo.clone(),
            args: solo_locked,
        },
    ];
    let erd = std::env::var_os("HOME").map(|h| {
        PathBuf::from(h).join(
            ".cache/restpose-corpus/unpacked-6.0.0/cmeel.prefix/share/example-robot-data/robots",
        )
    });
    if let Some(erd) = erd.filter(|d| d.join("a1_description/urdf/a1.urdf").exists()) {
        out.push(Case {
            name: "a1-servo",
            dir: erd,
            args: s(&[
                "analyze",
                "a1_description/urdf/a1.urdf",
                "--package",
                "example-robot-data=..",
                "--floating-base",
                "--ground",
                "--servo",
                "all=200",
                "--srdf",
                "a1_description/srdf/a1.srdf",
                "--srdf-state",
                "standing",
                "--friction",
                "stick",
                "-q",
            ]),
        });
    }
    out
}

/// Wall time [s] of one run; panics unless it exits 0.
fn run(exe: &Path, case: &Case) -> f64 {
    let started = Instant::now();
    let out = Command::new(exe)
        .args(&case.args)
        .current_dir(&case.dir)
        .output()
        .expect("restpose runs");
    let wall = started.elapsed().as_secs_f64();
    assert!(
        out.status.success(),
        "{} {}: {}",
        exe.display(),
        case.name,
        String::from_utf8_lossy(&out.stderr)
    );
    wall
}

/// Instructions executed by one run under callgrind (`None` without valgrind).
fn instructions(exe: &Path, case: &Case) -> Option<u64> {
    let out = Command::new("valgrind")
        .args(["--tool=callgrind", "--callgrind-out-file=/dev/null"])
        .arg(exe)
        .args(&case.args)
        .current_dir(&case.dir)
        .output()
        .ok()?;
    let text = String::from_utf8_lossy(&out.stderr);
    let at = text.find("Collected : ")? + "Collected : ".len();
    text[at..].split_whitespace().next()?.parse().ok()
}

fn quantile(v: &mut [f64], q: f64) -> f64 {
    v.sort_by(f64::total_cmp);
    v[((v.len() - 1) as f64 * q).round() as usize]
}

fn main() {
    let args: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| a != "--bench")
        .collect();
    let runs: usize = args
        .iter()
        .find_map(|a| a.parse().ok())
        .unwrap_or(60)
        .max(1);
    let counted = args.iter().any(|a| a == "--instructions");
    let mut bins: Vec<(String, PathBuf)> = vec![("this".into(), PathBuf::from(EXE))];
    let named: Vec<(String, PathBuf)> = args
        .iter()
        .filter_map(|a| a.split_once('='))
        .map(|(n, p)| (n.to_string(), PathBuf::from(p)))
        .collect();
    if named.is_empty() {
        let main = std::env::var_os("RESTPOSE_MAIN")
            .map(PathBuf::from)
            .or_else(|| {
                std::env::var_os("HOME")
                    .map(|h| PathBuf::from(h).join(".cache/restpose-target/release/restpose"))
            });
        if let Some(m) = main.filter(|m| m.exists()) {
            bins.push(("main".into(), m));
        }
    }
    bins.extend(named);
    for case in cases() {
        // This build must give a verdict on every case.
        let out = Command::new(EXE)
            .args(case.args.iter().filter(|a| *a != "-q"))
            .current_dir(&case.dir)
            .output()
            .expect("restpose runs");
        assert!(
            String::from_utf8_lossy(&out.stdout).contains("friction:"),
            "{}: no friction verdict",
            case.name
        );
        if counted {
            let counts: Vec<Option<u64>> =
                bins.iter().map(|(_, b)| instructions(b, &case)).collect();
            for ((name, _), n) in bins.iter().zip(&counts) {
                if let (Some(n), Some(Some(this))) = (n, counts.first()) {
                    println!(
                        "verdict {:<18} {:<6} instructions={n} instructions_ratio={:.3}",
                        case.name,
                        name,
                        *n as f64 / *this as f64
                    );
                }
            }
        }
        for (_, b) in &bins {
            run(b, &case); // warm the file cache
        }
        let mut times = vec![Vec::with_capacity(runs); bins.len()];
        for _ in 0..runs {
            for (k, (_, b)) in bins.iter().enumerate() {
                times[k].push(run(b, &case));
            }
        }
        let medians: Vec<f64> = times.iter_mut().map(|t| quantile(t, 0.5)).collect();
        let q1: Vec<f64> = times.iter_mut().map(|t| quantile(t, 0.25)).collect();
        for (k, (name, _)) in bins.iter().enumerate() {
            println!(
                "verdict {:<18} {:<6} median_ms={:.3} q1_ms={:.3} median_ratio={:.3} q1_ratio={:.3} this_minus_median_ms={:+.3} this_minus_q1_ms={:+.3}",
                case.name,
                name,
                medians[k] * 1e3,
                q1[k] * 1e3,
                medians[k] / medians[0],
                q1[k] / q1[0],
                (medians[0] - medians[k]) * 1e3,
                (q1[0] - q1[k]) * 1e3,
            );
        }
    }
}
