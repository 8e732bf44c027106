//! The reduced problem at a feasible configuration: energy, multipliers `Φ_uᵀ μ = V_uᵀ`,
//! reduced gradient `∂V/∂v = V_v − Φ_vᵀ μ` (eq. 37), the tangent map `Z = [H; I] S` with
//! `H = −Φ_u⁻¹ Φ_v`, and the reduced Hessian `Zᵀ W Z`, `W = V_qq − Σ_k μ_k Φ_k,qq`.

use super::basis_products::{mul_add_columns, tr_mul, Pattern};
use super::{Backend, Factors, System};
use crate::forces::{potential, Energy};
use crate::jet::HessianSink;
use crate::solver::partition::Partition;
use nalgebra::{DMatrix, DVector};

/// The largest null-space basis (`coordinates × dof` entries, 8 MB) that
/// [`System::reduced_hessian_and_basis`] keeps.
pub(crate) const KEPT_BASIS_ENTRIES: usize = 1 << 20;

/// Quantities at a feasible configuration under a partition.
#[derive(Clone)]
pub(crate) struct Eval {
    pub(crate) energy: Energy,
    /// `V − μᵀ Φ` over the independent rows: the energy corrected to first order for the
    /// corrector's residual [J].
    pub(crate) merit: f64,
    /// Multipliers of the independent rows (in `Partition::rows` order).
    pub(crate) mu: DVector<f64>,
    /// Reduced gradient in scaled coordinates.
    pub(crate) grad_v: DVector<f64>,
    pub(crate) factors: Factors,
}

impl System<'_> {
    /// Energy, multipliers and reduced gradient at a feasible `q`; `None` where the energy is
    /// undefined or `Φ_u` is singular.
    pub(crate) fn evaluate(&mut self, q: &DVector<f64>, part: &Partition) -> Option<Eval> {
        self.evaluate_knowing(q, part, None)
    }

    /// [`System::evaluate`] with `V(q)` and `∇V(q)` given where the caller has evaluated them
    /// already (`forces::potential` at `q` on this system's branches: `verify`'s finiteness
    /// guard), instead of evaluating them again: the same numbers.
    pub(crate) fn evaluate_knowing(
        &mut self,
        q: &DVector<f64>,
        part: &Partition,
        known: Option<(Energy, DVector<f64>)>,
    ) -> Option<Eval> {
        self.triplets(q);
        let (energy, grad_q) = match known {
            Some(known) => known,
            None => {
                let mut grad_q = DVector::zeros(q.len());
                let energy = potential(
                    self.problem.model,
                    &self.problem.cons.branches,
                    q,
                    &mut grad_q,
                    None,
                )?;
                (energy, grad_q)
            }
        };
        let dof = part.independent.len();
        let factors = self.factors(part)?;
        let v_u = DVector::from_iterator(
            part.dependent.len(),
            part.dependent.iter().map(|&c| grad_q[c]),
        );
        let mu = factors.solve_transpose(v_u)?;
        let v_v = DVector::from_iterator(dof, part.independent.iter().map(|&c| grad_q[c]));
        let mut grad_v = v_v - factors.phi_v_tr_mul(&mu, dof);
        for (b, &c) in part.independent.iter().enumerate() {
            grad_v[b] *= self.problem.scaling.columns[c];
        }
        let merit = energy.total
            - part
                .rows
                .iter()
                .zip(mu.iter())
                .map(|(&row, m)| m * self.work.phi[row])
                .sum::<f64>();
        Some(Eval {
            energy,
            merit,
            mu,
            grad_v,
            factors,
        })
    }

    /// `Z δv̂` for a step `δv̂` in scaled independent coordinates: the first-order change of all
    /// coordinates.
    pub(crate) fn tangent_step(
        &self,
        part: &Partition,
        eval: &Eval,
        dv: &DVector<f64>,
    ) -> DVector<f64> {
        let n = self.problem.model.coordinate_count();
        let mut dq = DVector::zeros(n);
        let mut dvu = dv.clone();
        for (b, &c) in part.independent.iter().enumerate() {
            dvu[b] *= self.problem.scaling.columns[c];
            dq[c] = dvu[b];
        }
        if !part.rows.is_empty() {
            let rhs = -eval.factors.phi_v_mul(&dvu, part.rows.len());
            if let Some(du) = eval.factors.solve(&rhs) {
                for (k, &c) in part.dependent.iter().enumerate() {
                    dq[c] = du[k];
                }
            }
        }
        dq
    }

    /// Column `b` of `Z` into `out` (zeroed, `n` long): [`System::tangent_step`] of the unit
    /// step `e_b`, the same operations on the same numbers, without its allocations (`dvu`:
    /// scratch of `dof` entries; the factors' solve in place in `out`'s rows of the dependent
    /// coordinates' order, through a buffer of `rows` entries).
    fn tangent_column(
        &self,
        part: &Partition,
        eval: &Eval,
        b: usize,
        dvu: &mut DVector<f64>,
        out: &mut [f64],
    ) {
        for (k, &c) in part.independent.iter().enumerate() {
            dvu[k] = (if k == b { 1.0 } else { 0.0 }) * self.problem.scaling.columns[c];
            out[c] = dvu[k];
        }
        if part.rows.is_empty() {
            return;
        }
        let mut rhs = -eval.factors.phi_v_mul(dvu, part.rows.len());
        let solved = match &eval.factors {
            Factors::Sparse(f) => f.solve(rhs.as_mut_slice()),
            Factors::Tree(f) => f.solve(rhs.as_mut_slice()),
            Factors::Dense { .. } => match eval.factors.solve(&rhs) {
                Some(du) => {
                    rhs = du;
                    true
                }
                None => false,
            },
        };
        if solved {
            for (k, &c) in part.dependent.iter().enumerate() {
                out[c] = rhs[k];
            }
        }
    }

    /// `Z` into the `n × dof` zeros `z`: the columns of [`System::tangent_column`] bit for
    /// bit, on the tree factors all in one pass (`Φ_v S` scattered once, one solve with `dof`
    /// right sides: [`TreeLu::solve_columns`]), otherwise one by one.
    ///
    /// [`TreeLu::solve_columns`]: crate::solver::tree::phi_u::TreeLu::solve_columns
    fn tangent_columns(&self, part: &Partition, eval: &Eval, z: &mut DMatrix<f64>) {
        let dof = part.independent.len();
        let r = part.rows.len();
        if let (Factors::Tree(f), true) = (&eval.factors, r > 0) {
            // `dvu` of `tangent_column`: `1 · s_b` at `b`.
            let scale: Vec<f64> = part
                .independent
                .iter()
                .map(|&c| 1.0 * self.problem.scaling.columns[c])
                .collect();
            // `−Φ_v dvu` for every `b` (row-major `rows × dof`), negated as that of one column.
            let mut x = vec![0.0; r * dof];
            f.add_phi_v_scaled(&scale, &mut x, dof);
            for v in x.iter_mut() {
                *v = -*v;
            }
            if f.solve_columns(&mut x, dof) {
                for (b, &c) in part.independent.iter().enumerate() {
                    z[(c, b)] = scale[b];
                }
                for (k, &c) in part.dependent.iter().enumerate() {
                    for (b, &v) in x[k * dof..(k + 1) * dof].iter().enumerate() {
                        z[(c, b)] = v;
                    }
                }
                return;
            }
            z.fill(0.0);
        }
        let mut dvu = DVector::zeros(dof);
        for b in 0..dof {
            self.tangent_column(part, eval, b, &mut dvu, z.column_mut(b).as_mut_slice());
        }
    }

    /// `Zᵀ y` for a covector `y` over all coordinates, in scaled independent coordinates:
    /// `S (y_v − Φ_vᵀ Φ_u⁻ᵀ y_u)`.
    pub(crate) fn tangent_transpose(
        &self,
        part: &Partition,
        eval: &Eval,
        y: &DVector<f64>,
    ) -> DVector<f64> {
        let dof = part.independent.len();
        let y_u =
            DVector::from_iterator(part.dependent.len(), part.dependent.iter().map(|&c| y[c]));
        let w = eval
            .factors
            .solve_transpose(y_u)
            .unwrap_or_else(|| DVector::zeros(part.rows.len()));
        let mut out = DVector::from_iterator(dof, part.independent.iter().map(|&c| y[c]))
            - eval.factors.phi_v_tr_mul(&w, dof);
        for (b, &c) in part.independent.iter().enumerate() {
            out[b] *= self.problem.scaling.columns[c];
        }
        out
    }

    /// The null-space basis `Z = [H; I] S` (n × dof) at `eval`.
    pub(crate) fn null_basis(&self, part: &Partition, eval: &Eval) -> DMatrix<f64> {
        let n = self.problem.model.coordinate_count();
        let dof = part.independent.len();
        let mut z = DMatrix::zeros(n, dof);
        if let Factors::Dense { lu, phi_v } = &eval.factors {
            // All columns at once: `H S = −Φ_u⁻¹ (Φ_v S)`, one solve with `dof` right sides.
            let scale = |b: usize| self.problem.scaling.columns[part.independent[b]];
            for (b, &c) in part.independent.iter().enumerate() {
                z[(c, b)] = scale(b);
            }
            if !part.rows.is_empty() {
                // `x (−s)` for each nonzero `x`, `+0` for the zeros (not `−0`): the solve
                // skips its zero steps on such columns (module `dense_lu`); the signs of zero
                // entries of the result are all it can change.
                let mut rhs = phi_v.as_ref().clone();
                for (b, mut col) in rhs.column_iter_mut().enumerate() {
                    let s = -scale(b);
                    for x in col.iter_mut() {
                        *x = if *x == 0.0 { 0.0 } else { *x * s };
                    }
                }
                if lu.solve_mut(&mut rhs) {
                    for (k, &c) in part.dependent.iter().enumerate() {
                        z.row_mut(c).copy_from(&rhs.row(k));
                    }
                }
            }
            return z;
        }
        for b in 0..dof {
            let mut e = DVector::zeros(dof);
            e[b] = 1.0;
            z.set_column(b, &self.tangent_step(part, eval, &e));
        }
        z
    }

    /// The multiplier weights `−μ` over all rows.
    pub(super) fn weights(&self, part: &Partition, eval: &Eval) -> DVector<f64> {
        let mut weights = DVector::zeros(self.problem.cons.len());
        for (k, &row) in part.rows.iter().enumerate() {
            weights[row] = -eval.mu[k];
        }
        weights
    }

    /// The Hessian of the Lagrangian `W = V_qq − Σ μ_k Φ_k,qq` at `q`.
    pub(crate) fn lagrangian_hessian(
        &self,
        q: &DVector<f64>,
        part: &Partition,
        eval: &Eval,
    ) -> DMatrix<f64> {
        let n = q.len();
        let mut w = DMatrix::zeros(n, n);
        let mut g = DVector::zeros(n);
        let _ = potential(
            self.problem.model,
            &self.problem.cons.branches,
            q,
            &mut g,
            Some(&mut w as &mut dyn HessianSink),
        );
        self.problem
            .cons
            .add_hessian(self.problem.model, q, &self.weights(part, eval), &mut w);
        w
    }

    /// `W` into the block-sparse scratch (the gradient, which is not needed, and the weights
    /// into scratch vectors reused from one assembly to the next).
    pub(super) fn lagrangian_blocks(&mut self, q: &DVector<f64>, part: &Partition, eval: &Eval) {
        let mut hess = std::mem::take(&mut self.work.hess);
        hess.clear();
        if hess.keys.is_empty() {
            // A diagonal block per body and two per joint between bodies (the usual terms).
            let model = self.problem.model;
            hess.reserve(
                model.bodies.len(),
                model.bodies.len() + 2 * model.joints.len(),
            );
        }
        let mut g = std::mem::take(&mut self.work.grad);
        refill(&mut g, q.len());
        let _ = potential(
            self.problem.model,
            &self.problem.cons.branches,
            q,
            &mut g,
            Some(&mut hess as &mut dyn HessianSink),
        );
        self.work.grad = g;
        let mut weights = std::mem::take(&mut self.work.weights);
        refill(&mut weights, self.problem.cons.len());
        for (k, &row) in part.rows.iter().enumerate() {
            weights[row] = -eval.mu[k];
        }
        self.problem
            .cons
            .add_hessian(self.problem.model, q, &weights, &mut hess);
        self.work.weights = weights;
        self.work.hess = hess;
    }

    /// The reduced Hessian `Zᵀ W Z` in scaled coordinates (dense: `O(n² dof)`; sparse: one
    /// column at a time through the factors, `O(dof · nnz)`).
    pub(crate) fn reduced_hessian(
        &mut self,
        q: &DVector<f64>,
        part: &Partition,
        eval: &Eval,
    ) -> DMatrix<f64> {
        self.reduced_hessian_and_basis(q, part, eval).0
    }

    /// [`System::reduced_hessian`] and the null-space basis `Z` it was formed with (the
    /// columns of [`System::null_basis`], bit for bit), kept where `Z` has at most
    /// [`KEPT_BASIS_ENTRIES`] entries (the minimizer's path curvature and the joint-space
    /// spectrum use it again at the same point instead of solving for it anew).
    pub(crate) fn reduced_hessian_and_basis(
        &mut self,
        q: &DVector<f64>,
        part: &Partition,
        eval: &Eval,
    ) -> (DMatrix<f64>, Option<DMatrix<f64>>) {
        let n = self.problem.model.coordinate_count();
        let dof = part.independent.len();
        let keep = n * dof <= KEPT_BASIS_ENTRIES;
        let (hr, basis) = if self.backend != Backend::Dense && keep {
            // `Z` column by column through the factors, `W Z` through the blocks, then
            // `Zᵀ (W Z)` as one product (no transposed solves).
            self.lagrangian_blocks(q, part, eval);
            let mut z = DMatrix::zeros(n, dof);
            let mut wz = DMatrix::zeros(n, dof);
            self.tangent_columns(part, eval, &mut z);
            let pattern = Pattern::of(&z);
            mul_add_columns(&self.work.hess, &z, &pattern, &mut wz);
            (tr_mul(&z, &wz, &pattern), Some(z))
        } else if self.backend != Backend::Dense {
            self.lagrangian_blocks(q, part, eval);
            let mut hr = DMatrix::zeros(dof, dof);
            let mut basis = keep.then(|| DMatrix::zeros(n, dof));
            for b in 0..dof {
                let mut e = DVector::zeros(dof);
                e[b] = 1.0;
                // `reduced_apply`, keeping `Z e_b`.
                let zx = self.tangent_step(part, eval, &e);
                let mut wzx = DVector::zeros(zx.len());
                self.work.hess.mul_add(zx.as_slice(), wzx.as_mut_slice());
                hr.set_column(b, &self.tangent_transpose(part, eval, &wzx));
                if let Some(z) = basis.as_mut() {
                    z.set_column(b, &zx);
                }
            }
            (hr, basis)
        } else {
            let z = self.null_basis(part, eval);
            let w = self.lagrangian_hessian(q, part, eval);
            (z.transpose() * w * &z, keep.then_some(z))
        };
        (symmetric_part(hr), basis)
    }

    /// `Zᵀ W Z x` with the `W` of the last block assembly (sparse path).
    pub(crate) fn reduced_apply(
        &self,
        part: &Partition,
        eval: &Eval,
        x: &DVector<f64>,
    ) -> DVector<f64> {
        let zx = self.tangent_step(part, eval, x);
        let mut wzx = DVector::zeros(zx.len());
        self.work.hess.mul_add(zx.as_slice(), wzx.as_mut_slice());
        self.tangent_transpose(part, eval, &wzx)
    }
}

/// `(A + Aᵀ) / 2` of a square `a`, in place: each entry `(a_ij + a_ji) · 0.5`, the
/// operations of `(&a + a.transpose()) * 0.5` (an IEEE sum is commutative) without its two
/// temporaries.
pub(crate) fn symmetric_part(mut a: DMatrix<f64>) -> DMatrix<f64> {
    let n = a.nrows();
    for j in 0..n {
        for i in 0..=j {
            let s = (a[(i, j)] + a[(j, i)]) * 0.5;
            a[(i, j)] = s;
            a[(j, i)] = s;
        }
    }
    a
}

/// `v` as `len` zeros, in place when it has that length already.
fn refill(v: &mut DVector<f64>, len: usize) {
    if v.len() == len {
        v.fill(0.0);
    } else {
        *v = DVector::zeros(len);
    }
}
