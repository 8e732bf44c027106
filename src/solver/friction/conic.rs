//! The second-order cone programs of the friction verdict (module `friction`), solved by
//! Clarabel.
//!
//! The stop and contact multipliers are `λ(z) = λ₀ + N z` (every balancing distribution, `z`
//! free). A contact `i` has a normal force `n_i(z) = λ_{i,0}` and a friction force
//! `t_i(z) = (λ_{i,1}, λ_{i,2})` when it sticks. Two programs over `x = (z, θ)`:
//!
//! ```text
//! level(s, w):   min θ        s.t.  ‖t_i‖ ≤ s c_i n_i + θ w_i   (sticking contacts with c_i)
//! least(s):      min ½‖D λ‖²  s.t.  ‖t_i‖ ≤ s c_i n_i              (the same contacts)
//! both:          n_i ≥ 0 (every contact),  0 ≤ λ_stop ≤ limit (stops; limit where given)
//! ```
//!
//! `level` is the subproblem of the Dinkelbach-type iteration for `min_z max_i ‖t_i‖ / (c_i n_i)`
//! (module `friction`); `least` picks the least-norm distribution among those needing at most
//! `s`. `θ ≥ −1` keeps `level` bounded where self-equilibrated squeezes add normal force
//! without limit. With `s = 0` the friction rows are equalities `t_i = 0`.
//!
//! ## References
//! - P. J. Goulart, Y. Chen, Clarabel: an interior-point solver for conic programs with
//!   quadratic objectives, arXiv:2405.12762 (2024).

use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettings, DefaultSettingsBuilder, DefaultSolver, IPSolver, SolverStatus, SupportedConeT,
};
use nalgebra::{DMatrix, DVector};

/// One stop or contact of a support: its first multiplier and what holds it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Holder {
    /// A joint stop: `0 ≤ λ ≤ limit` (one row; `limit` from the joint's `effort`, in the
    /// multiplier's units).
    Stop {
        /// Upper bound of the stop's multiplier, if any.
        limit: Option<f64>,
    },
    /// A frictionless contact: `n ≥ 0` (one row).
    Smooth,
    /// A sticking contact: `n ≥ 0` and a friction force (three rows), bounded by the
    /// coefficient `c · s` in the programs (`c = None`: unbounded friction).
    Stick {
        /// Weight of the coefficient.
        c: Option<f64>,
    },
}

impl Holder {
    /// Its number of rows.
    pub(crate) fn rows(&self) -> usize {
        match self {
            Holder::Stick { .. } => 3,
            _ => 1,
        }
    }
}

/// Rows of `λ(z) = base + null z`, by holder.
pub(crate) struct Affine<'a> {
    pub(crate) base: &'a DVector<f64>,
    pub(crate) null: &'a DMatrix<f64>,
    pub(crate) holders: &'a [(usize, Holder)],
}

/// What to minimize.
pub(crate) enum Goal<'a> {
    /// `θ`, with the friction bound `s c_i n_i + θ w_i`.
    Level { s: f64, w: &'a [f64] },
    /// `½ ‖D λ‖²` (`D` the diagonal `d`), with the friction bound `s c_i n_i`.
    Least { s: f64, d: &'a [f64] },
}

/// Accuracy asked of Clarabel (its defaults are `1e-8`): the verdict is compared with `μ`
/// to `1e-9`.
fn settings() -> DefaultSettings<f64> {
    DefaultSettingsBuilder::default()
        .verbose(false)
        .tol_gap_abs(1e-12)
        .tol_gap_rel(1e-12)
        .tol_feas(1e-12)
        .tol_ktratio(1e-9)
        .max_iter(100)
        .build()
        .unwrap_or_default()
}

/// A row `b − a·x` of the slack (`x = (z, θ)`).
struct Rows {
    /// Dense rows `a` over `x` and the constants `b`.
    a: Vec<Vec<f64>>,
    b: Vec<f64>,
    cones: Vec<SupportedConeT<f64>>,
}

impl Rows {
    /// The row `λ_r` as a slack: `λ_r = base_r + N_r z = b − a x` with `a = −N_r`.
    fn lambda(f: &Affine, r: usize, nx: usize, scale: f64) -> (Vec<f64>, f64) {
        let mut a = vec![0.0; nx];
        for (c, v) in a.iter_mut().zip(f.null.row(r).iter()) {
            *c = -v * scale;
        }
        (a, f.base[r] * scale)
    }

    fn push(&mut self, (a, b): (Vec<f64>, f64)) {
        self.a.push(a);
        self.b.push(b);
    }
}

/// The solution `z` (and `θ` for `Level`), or `None` where Clarabel finds no solution (an
/// infeasible support: no distribution with every contact pushing and every stop within its
/// limit).
pub(crate) fn solve(f: &Affine, goal: &Goal) -> Option<(DVector<f64>, f64)> {
    let k = f.null.ncols();
    let level = matches!(goal, Goal::Level { .. });
    let nx = k + usize::from(level);
    let mut rows = Rows {
        a: Vec::new(),
        b: Vec::new(),
        cones: Vec::new(),
    };
    let s = match goal {
        Goal::Level { s, .. } | Goal::Least { s, .. } => *s,
    };
    // Zero rows (friction forbidden), then nonnegative rows, then cones: Clarabel takes the
    // cones in the order of the rows.
    let mut zeros = 0;
    if !level && s == 0.0 {
        for &(first, h) in f.holders {
            if let Holder::Stick { c: Some(_) } = h {
                rows.push(Rows::lambda(f, first + 1, nx, 1.0));
                rows.push(Rows::lambda(f, first + 2, nx, 1.0));
                zeros += 2;
            }
        }
    }
    let mut nonneg = 0;
    for &(first, h) in f.holders {
        rows.push(Rows::lambda(f, first, nx, 1.0));
        nonneg += 1;
        if let Holder::Stop { limit: Some(l) } = h {
            // limit − λ ≥ 0.
            let (a, b) = Rows::lambda(f, first, nx, -1.0);
            rows.push((a, b + l));
            nonneg += 1;
        }
    }
    if level {
        // θ ≥ −1.
        let mut a = vec![0.0; nx];
        a[k] = -1.0;
        rows.push((a, 1.0));
        nonneg += 1;
    }
    if zeros > 0 {
        rows.cones.push(SupportedConeT::ZeroConeT(zeros));
    }
    rows.cones.push(SupportedConeT::NonnegativeConeT(nonneg));
    let mut i = 0;
    for &(first, h) in f.holders {
        let Holder::Stick { c: Some(c) } = h else {
            if matches!(h, Holder::Stick { .. }) {
                i += 1;
            }
            continue;
        };
        if !level && s == 0.0 {
            i += 1;
            continue;
        }
        // (s c n + θ w, t₁, t₂) in the second-order cone.
        let (mut a, b) = Rows::lambda(f, first, nx, s * c);
        if let Goal::Level { w, .. } = goal {
            a[k] = -w[i];
        }
        rows.push((a, b));
        rows.push(Rows::lambda(f, first + 1, nx, 1.0));
        rows.push(Rows::lambda(f, first + 2, nx, 1.0));
        rows.cones.push(SupportedConeT::SecondOrderConeT(3));
        i += 1;
    }
    let m = rows.b.len();
    let dense = DMatrix::from_fn(m, nx, |r, c| rows.a[r][c]);
    let a = csc(&dense);
    let (p, q) = match goal {
        Goal::Level { .. } => {
            let mut q = vec![0.0; nx];
            q[k] = 1.0;
            (CscMatrix::zeros((nx, nx)), q)
        }
        Goal::Least { d, .. } => {
            // ½‖D(base + N z)‖²: P = NᵀD²N, q = NᵀD² base.
            let dn = DMatrix::from_fn(f.null.nrows(), k, |r, c| d[r] * f.null[(r, c)]);
            let db = DVector::from_fn(f.base.len(), |r, _| d[r] * f.base[r]);
            let p = dn.transpose() * &dn;
            let q = dn.transpose() * db;
            (csc_upper(&p), q.iter().copied().collect())
        }
    };
    let mut solver = DefaultSolver::new(&p, &q, &a, &rows.b, &rows.cones, settings()).ok()?;
    solver.solve();
    let sol = &solver.solution;
    if !matches!(
        sol.status,
        SolverStatus::Solved | SolverStatus::AlmostSolved
    ) {
        return None;
    }
    let z = DVector::from_fn(k, |r, _| sol.x[r]);
    let theta = if level { sol.x[k] } else { sol.obj_val };
    Some((z, theta))
}

/// A dense matrix in compressed sparse column form (exact zeros dropped).
fn csc(m: &DMatrix<f64>) -> CscMatrix<f64> {
    let (mut colptr, mut rowval, mut nzval) = (vec![0], Vec::new(), Vec::new());
    for c in 0..m.ncols() {
        for r in 0..m.nrows() {
            if m[(r, c)] != 0.0 {
                rowval.push(r);
                nzval.push(m[(r, c)]);
            }
        }
        colptr.push(rowval.len());
    }
    CscMatrix::new(m.nrows(), m.ncols(), colptr, rowval, nzval)
}

/// The upper triangle of a symmetric matrix, as Clarabel takes `P`.
fn csc_upper(m: &DMatrix<f64>) -> CscMatrix<f64> {
    let upper = DMatrix::from_fn(
        m.nrows(),
        m.ncols(),
        |r, c| if r <= c { m[(r, c)] } else { 0.0 },
    );
    csc(&upper)
}
