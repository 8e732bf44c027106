//! Solve time of generated chains and ladders (dense path), plain harness:
//! `cargo bench --bench chain [N …]` prints one row per family and size.
use std::time::Instant;

/// A benchmark family: its name and a generator of URDF text for size N.
type Family = (&'static str, fn(usize) -> String);

fn main() {
    let sizes: Vec<usize> = std::env::args()
        .skip(1)
        .filter_map(|a| a.parse().ok())
        .collect::<Vec<_>>();
    let sizes = if sizes.is_empty() {
        vec![5, 10, 20, 40, 80]
    } else {
        sizes
    };
    println!("| family | N | coordinates | iterations | solve [ms] | ms / iteration |");
    println!("|---|---:|---:|---:|---:|---:|");
    let families: [Family; 2] = [
        ("chain", |n| restpose::generate::chain(n, false)),
        ("ladder", |n| restpose::generate::ladder(n / 2)),
    ];
    for (family, make) in families {
        for &n in &sizes {
            let text = make(n);
            let model = restpose::urdf::load_str(&text, "chain.urdf", &Default::default())
                .expect("generated chain loads")
                .model;
            let mut best = f64::INFINITY;
            let mut iterations = 0;
            for _ in 0..3 {
                let t = Instant::now();
                let (_, report) = restpose::solve(&model, &Default::default()).expect("solves");
                let ms = t.elapsed().as_secs_f64() * 1e3;
                assert!(report.converged(), "{family} {n} did not converge");
                iterations = report.iterations;
                best = best.min(ms);
            }
            println!(
                "| {family} | {} | {} | {iterations} | {best:.2} | {:.2} |",
                if family == "ladder" { n / 2 } else { n },
                model.coordinate_count(),
                best / iterations.max(1) as f64
            );
        }
    }
}
