//! The product of Lanczos (module `largest`), `Ĥ x = Zᵀ W Z x` with `Z = [−Φ_u⁻¹ Φ_v S; S]`
//! (scaled independent coordinates, `S` their column scaling):
//!
//! ```text
//! d_v = S x,   Φ_u d_u = −Φ_v d_v,   y = W d,   Φ_uᵀ w = y_u,   Ĥ x = S (y_v − Φ_vᵀ w)
//! ```
//!
//! the operations of `System::tangent_step`, `BlockHessian::mul_add` and
//! `System::tangent_transpose` in their order (the same bits), with the `n`-long `d`, `y`
//! and the row-long right sides kept across products and solved in place.

use crate::solver::partition::Partition;
use crate::solver::system::{Eval, Factors, System};
use nalgebra::DVector;

/// `Ĥ x` at the point of `eval` with the `W` of the last block assembly, buffers kept.
pub(crate) struct ReducedProduct<'s, 'm> {
    sys: &'s System<'m>,
    part: &'s Partition,
    eval: &'s Eval,
    /// `S` of the independent coordinates.
    scale: Vec<f64>,
    dv: DVector<f64>,
    d: Vec<f64>,
    y: Vec<f64>,
    rows: Vec<f64>,
}

impl<'s, 'm> ReducedProduct<'s, 'm> {
    pub(crate) fn new(sys: &'s System<'m>, part: &'s Partition, eval: &'s Eval) -> Self {
        let n = sys.problem.model.coordinate_count();
        let columns = &sys.problem.scaling.columns;
        ReducedProduct {
            sys,
            part,
            eval,
            scale: part.independent.iter().map(|&c| columns[c]).collect(),
            dv: DVector::zeros(part.independent.len()),
            d: vec![0.0; n],
            y: vec![0.0; n],
            rows: vec![0.0; part.rows.len()],
        }
    }

    /// `Ĥ x` (module doc).
    pub(crate) fn apply(&mut self, x: &DVector<f64>) -> DVector<f64> {
        let (part, factors) = (self.part, &self.eval.factors);
        for (b, &c) in part.independent.iter().enumerate() {
            let v = x[b] * self.scale[b];
            self.dv[b] = v;
            self.d[c] = v;
        }
        let r = part.rows.len();
        if r > 0 {
            let rhs = factors.phi_v_mul(&self.dv, r);
            for (o, v) in self.rows.iter_mut().zip(rhs.iter()) {
                *o = -*v;
            }
            let solved = solve_in_place(factors, &mut self.rows, false);
            for (k, &c) in part.dependent.iter().enumerate() {
                self.d[c] = if solved { self.rows[k] } else { 0.0 };
            }
        }
        self.y.fill(0.0);
        self.sys.work.hess.mul_add(&self.d, &mut self.y);
        for (o, &c) in self.rows.iter_mut().zip(&part.dependent) {
            *o = self.y[c];
        }
        if !solve_in_place(factors, &mut self.rows, true) {
            self.rows.fill(0.0);
        }
        let w = DVector::from_column_slice(&self.rows);
        let t = factors.phi_v_tr_mul(&w, part.independent.len());
        DVector::from_iterator(
            part.independent.len(),
            part.independent
                .iter()
                .enumerate()
                .map(|(b, &c)| (self.y[c] - t[b]) * self.scale[b]),
        )
    }
}

/// `Φ_u x = b` (or `Φ_uᵀ x = b`) in place, as `Factors::solve` (`solve_transpose`) computes it.
fn solve_in_place(factors: &Factors, b: &mut [f64], transpose: bool) -> bool {
    match (factors, transpose) {
        (Factors::Tree(f), false) => f.solve(b),
        (Factors::Tree(f), true) => f.solve_transpose(b),
        (Factors::Sparse(f), false) => f.solve(b),
        (Factors::Sparse(f), true) => f.solve_transpose(b),
        (Factors::Dense { .. }, false) => match factors.solve(&DVector::from_column_slice(b)) {
            Some(x) => {
                b.copy_from_slice(x.as_slice());
                true
            }
            None => false,
        },
        (Factors::Dense { .. }, true) => {
            match factors.solve_transpose(DVector::from_column_slice(b)) {
                Some(x) => {
                    b.copy_from_slice(x.as_slice());
                    true
                }
                None => false,
            }
        }
    }
}
