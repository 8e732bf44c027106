//! Solve time of generated chains (dense path), plain harness:
//! `cargo bench --bench chain` prints one row per size.
use std::time::Instant;

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
    println!("| N links | coordinates | iterations | solve [ms] | ms / iteration |");
    println!("|---:|---:|---:|---:|---:|");
    for n in sizes {
        let text = restpose::generate::chain(n, false);
        let model = restpose::urdf::load_str(&text, "chain.urdf", &Default::default())
            .expect("generated chain loads")
            .model;
        let mut best = f64::INFINITY;
        let mut iterations = 0;
        for _ in 0..3 {
            let t = Instant::now();
            let (_, report) = restpose::solve(&model, &Default::default()).expect("solves");
            let ms = t.elapsed().as_secs_f64() * 1e3;
            assert!(report.converged(), "chain {n} did not converge");
            iterations = report.iterations;
            best = best.min(ms);
        }
        println!(
            "| {n} | {} | {iterations} | {best:.2} | {:.2} |",
            7 * n,
            best / iterations.max(1) as f64
        );
    }
}
