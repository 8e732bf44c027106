//! An independent solution of the friction verdict's cone problem for one rigid body: the
//! contact forces that balance the body's weight, each inside a `sides`-sided pyramid
//! inscribed in its friction cone, found by phase 1 of the simplex method (written here,
//! each answer certified: see [`lp_feasible`]), and the smallest such `μ` by bisection. Inscribed
//! pyramids need at least the cone's `μ`; circumscribed ones (`μ cos(π/sides)`) at most.

use nalgebra::{DMatrix, DVector, Vector3};

/// A point contact: where, its unit normal (into the body).
pub(crate) struct Touch {
    pub(crate) p: Vector3<f64>,
    pub(crate) n: Vector3<f64>,
}

/// An orthonormal tangent basis of `n`.
fn tangents(n: &Vector3<f64>) -> [Vector3<f64>; 2] {
    let a = if n.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let t1 = n.cross(&a).normalize();
    [t1, n.cross(&t1)]
}

/// Feasibility of `{A x = b, x ≥ 0}` by phase 1 of the simplex method (Dantzig's rule on
/// rows scaled to unit norm), each answer certified from the final basis `B`: feasible when
/// `B x_B = b` re-solved gives `x_B ≥ 0` with the artificials at zero; infeasible when the
/// phase-1 duals `Bᵀ y = c_B` satisfy Farkas' lemma, `Aᵀ y ≤ 0` and `bᵀ y > 0` (each to
/// `10⁻¹³`: rounding). `None` when neither certificate holds (at the boundary of
/// feasibility, within rounding).
pub(crate) fn lp_feasible(a: &DMatrix<f64>, b: &DVector<f64>) -> Option<bool> {
    let (m, n) = (a.nrows(), a.ncols());
    // Rows scaled to unit norm and signed so that b ≥ 0.
    let mut a = a.clone();
    let mut b = b.clone();
    for r in 0..m {
        let norm = a.row(r).norm().max(b[r].abs()).max(1e-300);
        let s = if b[r] < 0.0 { -1.0 } else { 1.0 } / norm;
        a.row_mut(r).scale_mut(s);
        b[r] *= s;
    }
    // Tableau [A I | b], minimizing the sum of the artificials.
    let mut t = DMatrix::zeros(m + 1, n + m + 1);
    t.view_mut((0, 0), (m, n)).copy_from(&a);
    for r in 0..m {
        t[(r, n + r)] = 1.0;
        t[(r, n + m)] = b[r];
    }
    for c in 0..=n + m {
        let sum: f64 = (0..m).map(|r| t[(r, c)]).sum();
        t[(m, c)] = if c >= n && c < n + m { 0.0 } else { -sum };
    }
    let mut basis: Vec<usize> = (n..n + m).collect();
    for _ in 0..10_000 {
        let enter = (0..n + m)
            .filter(|&c| t[(m, c)] < -1e-12)
            .min_by(|&c1, &c2| t[(m, c1)].total_cmp(&t[(m, c2)]));
        let Some(enter) = enter else { break };
        let leave = (0..m).filter(|&r| t[(r, enter)] > 1e-9).min_by(|&r1, &r2| {
            let q1 = t[(r1, n + m)] / t[(r1, enter)];
            let q2 = t[(r2, n + m)] / t[(r2, enter)];
            q1.total_cmp(&q2).then(basis[r1].cmp(&basis[r2]))
        });
        let Some(leave) = leave else { break };
        let piv = t[(leave, enter)];
        for c in 0..=n + m {
            t[(leave, c)] /= piv;
        }
        for r in 0..=m {
            if r != leave {
                let f = t[(r, enter)];
                if f != 0.0 {
                    for c in 0..=n + m {
                        t[(r, c)] -= f * t[(leave, c)];
                    }
                }
            }
        }
        basis[leave] = enter;
    }
    // The columns of [A I] in the final basis.
    let column = |c: usize| -> DVector<f64> {
        if c < n {
            a.column(c).into_owned()
        } else {
            DVector::from_fn(m, |r, _| if r == c - n { 1.0 } else { 0.0 })
        }
    };
    let bm = DMatrix::from_columns(&basis.iter().map(|&c| column(c)).collect::<Vec<_>>());
    let lu = bm.clone().lu();
    // Feasible: x_B = B⁻¹ b nonnegative, artificials zero, A x = b.
    if let Some(xb) = lu.solve(&b) {
        let mut x = DVector::zeros(n);
        let mut artificial = 0.0f64;
        for (k, &c) in basis.iter().enumerate() {
            if c < n {
                x[c] = xb[k].max(0.0);
            } else {
                artificial = artificial.max(xb[k].abs());
            }
        }
        let negative = basis
            .iter()
            .enumerate()
            .filter(|(_, &c)| c < n)
            .map(|(k, _)| -xb[k])
            .fold(0.0, f64::max);
        if (&a * &x - &b).amax() <= 1e-13 && artificial <= 1e-13 && negative <= 1e-13 {
            return Some(true);
        }
    }
    // Infeasible: Farkas' y (phase-1 duals) with Aᵀ y ≤ 0 and bᵀ y > 0.
    let cb = DVector::from_fn(m, |k, _| if basis[k] >= n { 1.0 } else { 0.0 });
    if let Some(y) = bm.transpose().lu().solve(&cb) {
        let worst = (a.transpose() * &y).max();
        if worst <= 1e-13 * y.amax() && b.dot(&y) > 1e-13 * y.amax() {
            return Some(false);
        }
    }
    None
}

/// Whether forces inside inscribed `sides`-sided pyramids of half-aperture `mu` at `touches`
/// balance the weight `weight` [N] acting at `com` (force and moment about the origin).
pub(crate) fn feasible(
    touches: &[Touch],
    com: &Vector3<f64>,
    weight: &Vector3<f64>,
    mu: f64,
    sides: usize,
) -> Option<bool> {
    let mut cols = Vec::new();
    for t in touches {
        let [t1, t2] = tangents(&t.n);
        for j in 0..sides {
            let a = std::f64::consts::TAU * j as f64 / sides as f64;
            let d = t.n + (t1 * a.cos() + t2 * a.sin()) * mu;
            let m = t.p.cross(&d);
            cols.push(DVector::from_vec(vec![d.x, d.y, d.z, m.x, m.y, m.z]));
        }
    }
    let m = com.cross(weight);
    let rhs = DVector::from_vec(vec![-weight.x, -weight.y, -weight.z, -m.x, -m.y, -m.z]);
    lp_feasible(&DMatrix::from_columns(&cols), &rhs)
}

/// The smallest `mu` for which the inscribed pyramids balance the body, bracketed by
/// bisection on `[0, 4]` (`(lo, hi)`: infeasible at `lo`, feasible at `hi`), 40 halvings or
/// until an answer is within rounding.
pub(crate) fn least_mu(
    touches: &[Touch],
    com: &Vector3<f64>,
    weight: &Vector3<f64>,
    sides: usize,
) -> (f64, f64) {
    let (mut lo, mut hi) = (0.0, 4.0);
    for _ in 0..40 {
        let mid = 0.5 * (lo + hi);
        match feasible(touches, com, weight, mid, sides) {
            Some(true) => hi = mid,
            Some(false) => lo = mid,
            None => break,
        }
    }
    (lo, hi)
}
