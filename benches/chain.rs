//! Solve time, iterations, time per iteration and peak memory of the generated benchmark
//! families (plain harness, no criterion: the sizes span four decades and each large size is
//! solved once, in its own process so that its peak memory can be read).
//!
//! `cargo bench --bench chain -- [--dense | --sparse | --tree] [--family chain|ladder|rope|robots] [N …]`
//!
//! - `chain N`: `restpose generate chain --size N` (N bodies);
//! - `ladder N`: `restpose generate ladder --size N` (N closed loops, 3N bodies);
//! - `rope N`: `restpose generate rope --size N` (N links hanging from the world, about two
//!   thirds of them lying on the ground: N sphere contacts are candidates); checked by
//!   `verify_rope` (not in the default run: `--family rope`, default sizes 100, 300, 1000);
//! - `robots`: the tractor-trailer and the 7-axis arm of `robots/`.
//!
//! Each row is measured in a child process (this executable again, with
//! `RESTPOSE_BENCH_CHILD=family:N:algebra`): best of 3 solves (1 above 2,000 bodies;
//! `RESTPOSE_BENCH_RUNS` overrides) with the
//! default options (Newton, gradient tolerance 1e-8), then the process's peak resident memory
//! (`VmHWM`). Solves are checked: converged, ‖Φ‖∞ below 1e-9, and (chains and ladders, after
//! the timing) the energy and its joint-space gradient against the family's energy written
//! here in joint coordinates (`verify_family`). Below the table, the growth
//! exponent `p` of time per iteration `∝ N^p`, fitted by least squares over N ≥ 100.
use restpose::{LinearAlgebra, Model, Options, State};
use std::process::Command;
use std::time::Instant;

fn model_text(family: &str, n: usize) -> (String, String) {
    match family {
        "chain" => (format!("chain{n}"), restpose::generate::chain(n, false)),
        "ladder" => (format!("ladder{n}"), restpose::generate::ladder(n)),
        "rope" => (format!("rope{n}"), restpose::generate::rope(n)),
        _ => {
            let name = ["tractor_trailer", "panda_class", "stewart_platform"][n];
            let path = format!("{}/robots/{name}.urdf", env!("CARGO_MANIFEST_DIR"));
            (
                name.to_string(),
                std::fs::read_to_string(path).expect("robot file"),
            )
        }
    }
}

#[path = "../tests/it/common/energies.rs"]
mod energies;

/// The family's potential energy written independently in joint coordinates.
fn joint_space_energy(family: &str, n: usize, th: &[f64]) -> f64 {
    if family == "chain" {
        energies::chain(n, th)
    } else {
        energies::ladder(n, th)
    }
}

/// Independent check of a generated family's answer: restpose's energy equals the joint-space
/// energy at its joint angles, and the joint-space gradient (central differences at 20 joints
/// spread along the mechanism) vanishes to its rounding `ε |V| / h`. Returns the largest
/// gradient found.
fn verify_family(family: &str, n: usize, model: &Model, state: &State, energy: f64) -> f64 {
    let values = state.joint_values(model);
    let angle = |name: String| {
        values
            .iter()
            .find(|(j, _)| *j == name)
            .map(|(_, v)| v[0])
            .expect("joint")
    };
    let th: Vec<f64> = (0..n)
        .map(|i| {
            angle(if family == "chain" {
                format!("joint{i}")
            } else {
                format!("hang_left{i}")
            })
        })
        .collect();
    let v = joint_space_energy(family, n, &th);
    assert!(
        (v - energy).abs() <= 1e-9 * v.abs(),
        "{family}{n}: energy {v} vs {energy}"
    );
    let h = 1e-5;
    let mut worst = 0.0f64;
    for i in (0..n).step_by((n / 20).max(1)) {
        let (mut p, mut m) = (th.clone(), th.clone());
        p[i] += h;
        m[i] -= h;
        let g = (joint_space_energy(family, n, &p) - joint_space_energy(family, n, &m)) / (2.0 * h);
        assert!(
            g.abs() < 1e-13 * v.abs() / h + 1e-6,
            "{family}{n}: ∂V/∂θ{i} = {g}"
        );
        worst = worst.max(g.abs());
    }
    worst
}

/// Independent check of the rope on the ground: the energy equals the joint-space energy
/// (`energies::rope`); each contact touches (`|g| ≤ 1e-9` m), pushes (`f_n ≥ 0`) and is
/// complementary (`|g| f_n ≤ 1e-9 m · max f_n`); the anchor's vertical reaction plus the normal
/// forces carry the weight `n m g` (to 1e-8 N). Returns the largest `|g| f_n`.
fn verify_rope(n: usize, model: &Model, state: &State, report: &restpose::Report) -> f64 {
    let values = state.joint_values(model);
    let th: Vec<f64> = (0..n)
        .map(|i| {
            let name = format!("joint{i}");
            values
                .iter()
                .find(|(j, _)| *j == name)
                .map(|(_, v)| v[0])
                .expect("joint")
        })
        .collect();
    let v = energies::rope(n, &th);
    let energy = report.energy.total;
    assert!(
        (v - energy).abs() <= 1e-9 * v.abs(),
        "rope{n}: energy {v} vs {energy}"
    );
    let fmax = report
        .contacts
        .iter()
        .fold(0.0f64, |a, c| a.max(c.normal_force));
    let mut worst = 0.0f64;
    for c in &report.contacts {
        assert!(
            c.gap.abs() <= 1e-9 && c.normal_force >= 0.0,
            "rope{n}: {c:?}"
        );
        assert!(
            c.gap.abs() * c.normal_force <= 1e-9 * fmax,
            "rope{n}: {c:?}"
        );
        worst = worst.max(c.gap.abs() * c.normal_force);
    }
    let anchor = report
        .reactions
        .iter()
        .find(|(j, _)| j == "joint0")
        .expect("anchor");
    let normal: f64 = report.contacts.iter().map(|c| c.normal_force).sum();
    let weight = n as f64 * 0.05 * 9.81;
    assert!(
        (anchor.1.force_world[2] + normal - weight).abs() <= 1e-8,
        "rope{n}: vertical forces {} + {normal} vs weight {weight}",
        anchor.1.force_world[2]
    );
    worst
}

fn peak_rss_mb() -> f64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmHWM:"))
                .and_then(|l| l.split_whitespace().nth(1)?.parse::<f64>().ok())
        })
        .map_or(f64::NAN, |kb| kb / 1024.0)
}

/// One measurement (child process): prints `name bodies dof iterations best_ms peak_mb`.
fn child(spec: &str) {
    let parts: Vec<&str> = spec.split(':').collect();
    let (family, n, algebra) = (parts[0], parts[1].parse().unwrap(), parts[2]);
    let (name, text) = model_text(family, n);
    let model = restpose::urdf::load_str(&text, "bench.urdf", &Default::default())
        .expect("benchmark model loads")
        .model;
    let options = Options {
        linear_algebra: match algebra {
            "dense" => LinearAlgebra::Dense,
            "sparse" => LinearAlgebra::Sparse,
            "tree" => LinearAlgebra::Tree,
            _ => LinearAlgebra::Auto,
        },
        ..Default::default()
    };
    let runs = std::env::var("RESTPOSE_BENCH_RUNS")
        .ok()
        .and_then(|r| r.parse().ok())
        .unwrap_or(if model.bodies().len() > 2000 { 1 } else { 3 });
    let mut best = f64::INFINITY;
    let mut report = None;
    for _ in 0..runs {
        let t = Instant::now();
        let (s, r) = restpose::solve(&model, &options).expect("solves");
        best = best.min(t.elapsed().as_secs_f64() * 1e3);
        assert!(
            r.converged(),
            "{name} did not converge: {:?}",
            r.termination
        );
        assert!(r.diagnostics.constraint_residual < 1e-9);
        report = Some((s, r));
    }
    let (s, r) = report.unwrap();
    let peak = peak_rss_mb();
    let gradient = if family == "robots" {
        f64::NAN
    } else if family == "rope" {
        verify_rope(n, &model, &s, &r)
    } else {
        verify_family(family, n, &model, &s, r.energy.total)
    };
    println!(
        "{name} {} {} {} {best} {peak} {} {gradient:.1e}",
        model.bodies().len(),
        r.dof,
        r.iterations,
        r.diagnostics.linear_algebra
    );
}

fn main() {
    if let Ok(spec) = std::env::var("RESTPOSE_BENCH_CHILD") {
        child(&spec);
        return;
    }
    let args: Vec<String> = std::env::args().skip(1).collect();
    let algebra = if args.iter().any(|a| a == "--dense") {
        "dense"
    } else if args.iter().any(|a| a == "--sparse") {
        "sparse"
    } else if args.iter().any(|a| a == "--tree") {
        "tree"
    } else {
        "auto"
    };
    let family = args
        .iter()
        .position(|a| a == "--family")
        .and_then(|i| args.get(i + 1).cloned());
    let sizes: Vec<usize> = args.iter().filter_map(|a| a.parse().ok()).collect();
    let families: Vec<(&str, Vec<usize>)> = match family.as_deref() {
        Some("robots") => vec![("robots", vec![0, 1, 2])],
        Some(f @ ("chain" | "ladder" | "rope")) => vec![(
            match f {
                "chain" => "chain",
                "ladder" => "ladder",
                _ => "rope",
            },
            if !sizes.is_empty() {
                sizes.clone()
            } else if f == "rope" {
                vec![100, 300, 1000]
            } else {
                vec![10, 100, 1000]
            },
        )],
        _ => {
            let s = if sizes.is_empty() {
                vec![10, 100, 1000]
            } else {
                sizes.clone()
            };
            vec![
                ("chain", s.clone()),
                ("ladder", s),
                ("robots", vec![0, 1, 2]),
            ]
        }
    };
    let exe = std::env::current_exe().expect("own path");
    println!("| model | bodies | dof | algebra | iterations | solve [ms] | ms / iteration | peak RSS [MB] | joint-space check: max \\|∂V/∂θ\\| [N m] (rope: max \\|g\\| f_n [N m]) |");
    println!("|---|---:|---:|---|---:|---:|---:|---:|---:|");
    for (family, sizes) in families {
        let mut fit = Vec::new();
        for n in sizes {
            let out = Command::new(&exe)
                .env("RESTPOSE_BENCH_CHILD", format!("{family}:{n}:{algebra}"))
                .output()
                .expect("child runs");
            let text = String::from_utf8_lossy(&out.stdout);
            let f: Vec<&str> = text.split_whitespace().collect();
            if !out.status.success() || f.len() < 7 {
                println!(
                    "| {family} {n} | failed: {} |",
                    String::from_utf8_lossy(&out.stderr)
                        .lines()
                        .last()
                        .unwrap_or("")
                );
                continue;
            }
            let (bodies, its, ms): (f64, f64, f64) = (
                f[1].parse().unwrap(),
                f[3].parse().unwrap(),
                f[4].parse().unwrap(),
            );
            let per = ms / its.max(1.0);
            println!(
                "| {} | {} | {} | {} | {} | {ms:.2} | {per:.3} | {:.1} | {} |",
                f[0],
                f[1],
                f[2],
                f[6],
                f[3],
                f[5].parse::<f64>().unwrap(),
                f.get(7).filter(|g| **g != "NaN").unwrap_or(&"—")
            );
            if family != "robots" && bodies >= 100.0 {
                fit.push((bodies.ln(), per.ln()));
            }
        }
        if fit.len() >= 2 {
            let k = fit.len() as f64;
            let (sx, sy) = fit.iter().fold((0.0, 0.0), |a, p| (a.0 + p.0, a.1 + p.1));
            let (mx, my) = (sx / k, sy / k);
            let num: f64 = fit.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
            let den: f64 = fit.iter().map(|p| (p.0 - mx).powi(2)).sum();
            println!(
                "\n{family}: time per iteration ∝ bodies^{:.2} (least squares, bodies ≥ 100)\n",
                num / den
            );
        }
    }
}
