//! The floor of restpose's formulation on a chain, beside restpose's own Newton iteration on
//! the same chains, in the same run (plain harness, no criterion, like the other benches).
//!
//! `cargo bench --bench floor -- [N …]` (default: 1000 10000)
//!
//! The floor is the linear algebra one Newton iteration of the paper's formulation cannot
//! avoid on a chain of `N` bodies (7 Cartesian coordinates and 6 independent rows each: five
//! revolute rows and the normalization row), with fixed-size nalgebra blocks and a workspace
//! allocated once:
//!
//! - **KKT factorization**: the `13 N` matrix `[W Φ_qᵀ; Φ_q 0]` in restpose's elimination order
//!   (each body's 7 coordinates, then the 6 rows pivoted at it; leaves first) is block
//!   tridiagonal: a `13 × 13` diagonal block `K_b` per body and a `13 × 7` coupling `C_b` to its
//!   parent's coordinates. Eliminating from the leaves to the root, `K_b = P L U` (partial
//!   pivoting), `X_b = K_b⁻¹ C_b`, and the parent's `7 × 7` coordinate block loses `C_bᵀ X_b`:
//!   no fill.
//! - **one KKT solve**: forward `y_b = K_b⁻¹ r_b`, `r_p −= C_bᵀ y_b` (leaves to root), backward
//!   `x_b = y_b − X_b x_p` (root to leaves).
//! - **`Φ_u`**: block triangular for a tree (a `6 × 6` diagonal block per body, a `6 × 6` block
//!   on its parent's dependent coordinates): one LU per diagonal block, one solve `Φ_uᵀ μ = g`
//!   (multipliers, leaves to root) and one `Φ_u x = r` (a corrector or tangent step, root to
//!   leaves).
//!
//! Then restpose solves the generated chain (`restpose generate chain --size N`, default
//! options, each `--linear-algebra` backend asked for on the command line: `sparse`, `tree`) and
//! the table gives its time per Newton iteration two ways, each with its ratio to the floor:
//!
//! - the minimizer's time over its iterations (evaluations, line search, corrector, KKT step,
//!   as `timings.iterations` counts them), which shares out what a solve does once: the
//!   partition, the first evaluation, and in the first iteration the structure of the linear
//!   algebra and the first touch of its memory (at 10,000 links about 20,000 fresh pages);
//! - an iteration in a steady state, `(timings.steps − timings.first_step) / (iterations −
//!   1)`: the iterations after the first, whose structure and memory are in place, as the
//!   floor's are (its blocks and workspace are built and touched before it is timed).
//!
//! Both sides are best-of figures: the floor of 40 runs (10 above 2,000 links), restpose of 10
//! solves (5 above 2,000; `RESTPOSE_FLOOR_RUNS=K` for K), each of its columns the best on its
//! own. `RESTPOSE_FLOOR_ALGEBRA=tree` (or `sparse`) runs that backend alone (for a profile).
use nalgebra::{SMatrix, SVector};
use restpose::{LinearAlgebra, Options};
use std::hint::black_box;
use std::time::Instant;

type M13 = SMatrix<f64, 13, 13>;
type M13x7 = SMatrix<f64, 13, 7>;
type M6 = SMatrix<f64, 6, 6>;
type V13 = SVector<f64, 13>;
type V6 = SVector<f64, 6>;

/// A chain's KKT and `Φ_u` blocks, and the workspace of their factors (allocated once).
struct Floor {
    /// Per body (leaves first): the diagonal block (values), the coupling to the parent.
    k: Vec<M13>,
    c: Vec<M13x7>,
    /// `Φ_u`: diagonal and parent blocks.
    a: Vec<M6>,
    ap: Vec<M6>,
    /// Factors.
    klu: Vec<nalgebra::LU<f64, nalgebra::Const<13>, nalgebra::Const<13>>>,
    x: Vec<M13x7>,
    alu: Vec<nalgebra::LU<f64, nalgebra::Const<6>, nalgebra::Const<6>>>,
    /// Right sides and solutions.
    r: Vec<V13>,
    g: Vec<V6>,
}

/// A deterministic pseudo-random number in `[−1, 1)`.
fn rnd(state: &mut u64) -> f64 {
    *state = state
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    ((*state >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
}

impl Floor {
    fn new(n: usize) -> Self {
        let mut s = 1u64;
        let mut k = Vec::with_capacity(n);
        let mut c = Vec::with_capacity(n);
        let mut a = Vec::with_capacity(n);
        let mut ap = Vec::with_capacity(n);
        for _ in 0..n {
            // W_bb symmetric positive (augmented), A_b full rank: the KKT block is
            // nonsingular and indefinite, like restpose's.
            let mut w = SMatrix::<f64, 7, 7>::from_fn(|_, _| 0.1 * rnd(&mut s));
            w = w * w.transpose() + SMatrix::<f64, 7, 7>::identity() * 2.0;
            let rows =
                SMatrix::<f64, 6, 7>::from_fn(|i, j| rnd(&mut s) + if i == j { 2.0 } else { 0.0 });
            let mut kb = M13::zeros();
            kb.fixed_view_mut::<7, 7>(0, 0).copy_from(&w);
            kb.fixed_view_mut::<6, 7>(7, 0).copy_from(&rows);
            kb.fixed_view_mut::<7, 6>(0, 7).copy_from(&rows.transpose());
            k.push(kb);
            c.push(M13x7::from_fn(|_, _| 0.1 * rnd(&mut s)));
            a.push(rows.fixed_view::<6, 6>(0, 0).into_owned());
            ap.push(M6::from_fn(|_, _| 0.5 * rnd(&mut s)));
        }
        Floor {
            klu: k.iter().map(|m| m.lu()).collect(),
            x: vec![M13x7::zeros(); n],
            alu: a.iter().map(|m| m.lu()).collect(),
            r: vec![V13::zeros(); n],
            g: vec![V6::zeros(); n],
            k,
            c,
            a,
            ap,
        }
    }

    /// One iteration's floor; returns a checksum (so that nothing is optimized away).
    fn iterate(&mut self) -> f64 {
        let n = self.k.len();
        // KKT factorization, leaves (index 0) to root (index n − 1).
        let mut carry = SMatrix::<f64, 7, 7>::zeros();
        for b in 0..n {
            let mut kb = self.k[b];
            let mut top = kb.fixed_view_mut::<7, 7>(0, 0);
            top -= carry;
            let lu = kb.lu();
            let mut x = self.c[b];
            lu.solve_mut(&mut x);
            carry = self.c[b].transpose() * x;
            self.klu[b] = lu;
            self.x[b] = x;
        }
        // One KKT solve.
        let mut up = SVector::<f64, 7>::zeros();
        for b in 0..n {
            let mut r = V13::from_fn(|i, _| 1.0 + (i + b) as f64 * 1e-3);
            let mut head = r.fixed_rows_mut::<7>(0);
            head -= up;
            self.klu[b].solve_mut(&mut r);
            up = self.c[b].transpose() * r;
            self.r[b] = r;
        }
        let mut xp = SVector::<f64, 7>::zeros();
        for b in (0..n).rev() {
            let x = self.r[b] - self.x[b] * xp;
            self.r[b] = x;
            xp = x.fixed_rows::<7>(0).into_owned();
        }
        // Φ_u: factor, Φ_uᵀ μ = g (leaves to root), Φ_u x = r (root to leaves).
        for b in 0..n {
            self.alu[b] = self.a[b].lu();
        }
        let mut from_children = V6::zeros();
        for b in 0..n {
            let mut g = V6::from_element(1.0) - from_children;
            let ok = self.alu[b].solve_mut(&mut g);
            debug_assert!(ok);
            // The child's rows reach the parent's columns: its `ap` block.
            from_children = self.ap[b].transpose() * g;
            self.g[b] = g;
        }
        let mut xp6 = V6::zeros();
        for b in (0..n).rev() {
            let mut x = V6::from_element(1.0) - self.ap[b] * xp6;
            self.alu[b].solve_mut(&mut x);
            xp6 = x;
        }
        self.r.iter().map(|r| r[0]).sum::<f64>() + self.g[0][0] + xp6[0]
    }
}

/// Best time of `reps` runs of `f` [s].
fn best(reps: usize, mut f: impl FnMut()) -> f64 {
    (0..reps)
        .map(|_| {
            let t = Instant::now();
            f();
            t.elapsed().as_secs_f64()
        })
        .fold(f64::INFINITY, f64::min)
}

/// restpose's time per Newton iteration on the chain [s]: the minimizer's time over its
/// iterations (`timings.iterations` over `iterations`: the partition, the first evaluation and
/// the structures built in the first iteration shared out), and an iteration in a steady state
/// (`(timings.steps − timings.first_step) / (iterations − 1)`: the structure built, its memory
/// touched, as the floor's own workspace); each the best of `reps` solves, and the iterations.
fn restpose_iteration(n: usize, algebra: LinearAlgebra, reps: usize) -> Option<(f64, f64, usize)> {
    let text = restpose::generate::chain(n, false);
    let model = restpose::urdf::load_str(&text, "floor.urdf", &Default::default())
        .ok()?
        .model;
    let options = Options {
        linear_algebra: algebra,
        ..Options::default()
    };
    let mut out: Option<(f64, f64, usize)> = None;
    for _ in 0..reps {
        let t = Instant::now();
        let (_, report) = restpose::solve(&model, &options).ok()?;
        let total = t.elapsed().as_secs_f64();
        let it = report.iterations.max(1);
        let timings = report.diagnostics.timings;
        let per = if timings.iterations > 0.0 {
            timings.iterations
        } else {
            total
        } / it as f64;
        let steady = if it > 1 {
            (timings.steps - timings.first_step) / (it - 1) as f64
        } else {
            per
        };
        let (best, best_steady) =
            out.map_or((per, steady), |(b, s, _)| (b.min(per), s.min(steady)));
        out = Some((best, best_steady, report.iterations));
    }
    out
}

fn main() {
    let sizes: Vec<usize> = std::env::args()
        .skip(1)
        .filter_map(|a| a.parse().ok())
        .collect();
    let sizes = if sizes.is_empty() {
        vec![1000, 10000]
    } else {
        sizes
    };
    println!(
        "| chain N | floor [ms] | algebra | iterations | restpose [ms / iteration] | ÷ floor | steady iteration [ms] | ÷ floor |"
    );
    println!("|---:|---:|---|---:|---:|---:|---:|---:|");
    for n in sizes {
        let mut floor = Floor::new(n);
        let reps = if n > 2000 { 10 } else { 40 };
        let mut sum = 0.0;
        let t_floor = best(reps, || sum += black_box(floor.iterate()));
        black_box(sum);
        for (name, algebra) in [
            ("sparse", LinearAlgebra::Sparse),
            ("tree", LinearAlgebra::Tree),
        ] {
            // `RESTPOSE_FLOOR_ALGEBRA`: one backend only (module docs).
            if std::env::var("RESTPOSE_FLOOR_ALGEBRA").is_ok_and(|a| a != name) {
                continue;
            }
            // One solve's figure swings with the machine by more than the gains measured here.
            let reps = std::env::var("RESTPOSE_FLOOR_RUNS")
                .ok()
                .and_then(|v| v.parse().ok())
                .unwrap_or(if n > 2000 { 5 } else { 10 });
            match restpose_iteration(n, algebra, reps) {
                Some((t, steady, it)) => println!(
                    "| {n} | {:.2} | {name} | {it} | {:.2} | {:.2} | {:.2} | {:.2} |",
                    1e3 * t_floor,
                    1e3 * t,
                    t / t_floor,
                    1e3 * steady,
                    steady / t_floor
                ),
                None => println!(
                    "| {n} | {:.2} | {name} | — | failed | — | — | — |",
                    1e3 * t_floor
                ),
            }
        }
    }
}
