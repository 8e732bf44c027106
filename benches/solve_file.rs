//! In-process solve time of one URDF file, from Rust: the baseline of the Python bindings'
//! overhead (`python/benches/overhead.py` runs this and `Model.solve` from Python alternately).
//!
//! `cargo bench --bench solve_file -- FILE [REPEATS] [--limits-ignore]`
//!
//! Loads FILE once, solves it once to warm up, then REPEATS times (default 200) and prints one
//! line `solve_file median_us=… min_us=… iterations=… converged=…`: each timed solve is what
//! `Model.solve` does in Rust, `restpose::solve` followed by `AnalysisResult::new` (the result
//! the bindings hand to Python), the result dropped inside the timing (as a discarded result is
//! in Python).
use restpose::export::json::AnalysisResult;
use restpose::{Limits, Options};
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| a != "--bench")
        .collect();
    let Some(file) = args.iter().find(|a| !a.starts_with("--")) else {
        eprintln!("usage: solve_file FILE [REPEATS] [--limits-ignore]");
        return;
    };
    let repeats: usize = args
        .iter()
        .filter(|a| !a.starts_with("--"))
        .nth(1)
        .and_then(|n| n.parse().ok())
        .unwrap_or(200)
        .max(1);
    let options = Options {
        limits: if args.iter().any(|a| a == "--limits-ignore") {
            Limits::Ignore
        } else {
            Limits::Enforce
        },
        ..Default::default()
    };
    let loaded = match restpose::urdf::load_file(file, &Default::default()) {
        Ok(l) => l,
        Err(e) => {
            eprintln!("error: {e}");
            std::process::exit(1);
        }
    };
    let model = &loaded.model;
    let solve = || -> restpose::Result<AnalysisResult> {
        let (state, report) = restpose::solve(model, &options)?;
        Ok(AnalysisResult::new(model, &state, &report))
    };
    let warm = match solve() {
        Ok(r) => r,
        Err(e) => {
            eprintln!("error: {e}");
            std::process::exit(1);
        }
    };
    let mut times: Vec<f64> = (0..repeats)
        .map(|_| {
            let t = Instant::now();
            // the result is dropped inside the timing, as Python drops a discarded result
            drop(std::hint::black_box(solve()));
            t.elapsed().as_secs_f64()
        })
        .collect();
    times.sort_by(f64::total_cmp);
    println!(
        "solve_file median_us={:.2} min_us={:.2} iterations={} converged={}",
        times[times.len() / 2] * 1e6,
        times[0] * 1e6,
        warm.iterations,
        warm.converged
    );
}
