//! Whole-process time and peak memory of `restpose check` and `restpose verify` on generated
//! chains (plain harness): what a user waits for, import and output included.
//!
//! `cargo bench --bench check_verify -- [N …]` (default: 1000 10000)
//!
//! For each N: `restpose generate chain --size N` into a temporary folder, one `analyze --json`
//! for the pose, then `check`, `verify --pose` (stability verdict from the KKT inertia above
//! 200 degrees of freedom) and `verify --pose --eigenvalues` (the lowest eigenvalues by
//! Lanczos, as before) on it, best of 3 runs each. Every run is
//! checked: `check` and `verify` exit 0 (the pose analyze found passes `verify`). Peak resident
//! memory is read with `/usr/bin/time -f %M` when that program exists. CPU time (user +
//! system) is printed beside the wall time: on a shared machine it is the steadier number.
use std::path::Path;
use std::process::Command;
use std::time::Instant;

const EXE: &str = env!("CARGO_BIN_EXE_restpose");

/// One run of `restpose ARGS`: (wall s, CPU s, peak RSS MB), the CPU time and memory from
/// `/usr/bin/time` when present (`NaN` otherwise). Panics unless the exit code is 0.
fn run(args: &[&str]) -> (f64, f64, f64) {
    let timed = Path::new("/usr/bin/time").exists();
    let mut cmd = if timed {
        let mut c = Command::new("/usr/bin/time");
        c.args(["-f", "%U %S %M", EXE]);
        c
    } else {
        Command::new(EXE)
    };
    let started = Instant::now();
    let out = cmd.args(args).output().expect("restpose runs");
    let wall = started.elapsed().as_secs_f64();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "restpose {args:?} failed: {stderr}");
    let last: Vec<f64> = stderr
        .lines()
        .last()
        .unwrap_or("")
        .split_whitespace()
        .filter_map(|x| x.parse().ok())
        .collect();
    match last[..] {
        [user, sys, kb] if timed => (wall, user + sys, kb / 1024.0),
        _ => (wall, f64::NAN, f64::NAN),
    }
}

/// Best of `k` runs by wall time.
fn best(k: usize, args: &[&str]) -> (f64, f64, f64) {
    (0..k)
        .map(|_| run(args))
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .expect("at least one run")
}

fn main() {
    let mut sizes: Vec<usize> = std::env::args()
        .skip(1)
        .filter_map(|a| a.parse().ok())
        .collect();
    if sizes.is_empty() {
        sizes = vec![1000, 10000];
    }
    let dir = tempfile::tempdir().expect("temporary folder");
    println!("| command | links | wall [s] | CPU [s] | peak RSS [MB] |");
    println!("|---|---:|---:|---:|---:|");
    for n in sizes {
        let urdf = dir.path().join(format!("chain{n}.urdf"));
        let pose = dir.path().join(format!("chain{n}.json"));
        let text = Command::new(EXE)
            .args(["generate", "chain", "--size", &n.to_string()])
            .output()
            .expect("generate runs");
        assert!(text.status.success());
        std::fs::write(&urdf, &text.stdout).expect("write the chain");
        let (urdf, pose) = (urdf.to_str().unwrap(), pose.to_str().unwrap());
        run(&["analyze", urdf, "--quiet", "--json", pose]);
        for (name, args) in [
            ("check", vec!["check", urdf]),
            ("verify", vec!["verify", urdf, "--pose", pose, "--quiet"]),
            (
                "verify --eigenvalues",
                vec!["verify", urdf, "--pose", pose, "--quiet", "--eigenvalues"],
            ),
        ] {
            let (wall, cpu, mb) = best(3, &args);
            println!("| `{name}` | {n} | {wall:.2} | {cpu:.2} | {mb:.0} |");
        }
    }
}
