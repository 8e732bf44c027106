//! Evaluation of the partitioned problem at a configuration: the corrector, the reduced
//! gradient and the reduced Hessian.
//!
//! With `q = [u; v]`, `Φ_q = [Φ_u Φ_v]` (independent rows only) and `H = −Φ_u⁻¹ Φ_v`:
//! - corrector: Newton on `Φ(u; v) = 0` for fixed `v`: `Φ_u δu = −Φ`;
//! - multipliers: `Φ_uᵀ μ = V_uᵀ`, so that `V_qᵀ = Φ_qᵀ μ` at equilibrium;
//! - reduced gradient (eq. 37): `∂V/∂v = V_v + V_u H = V_v − Φ_vᵀ μ`;
//! - reduced Hessian: `Zᵀ (V_qq − Σ_k μ_k Φ_k,qq) Z`, `Z = [H; I]`, exact at feasible points.
//!
//! Independent coordinates are scaled, `v = S v̂` (positions by the characteristic length), and
//! gradients and Hessians are reported in the scaled coordinates `v̂`.

use super::partition::{partition, Partition};
use super::sparse::factor::{SparseFactors, Split};
use super::sparse::hessian::BlockHessian;
use super::sparse::kkt::{Factored, Kkt};
use crate::constraints::{Constraints, Triplets};
use crate::forces::{potential, Energy};
use crate::jet::HessianSink;
use crate::model::Model;
use nalgebra::{DMatrix, DVector, LU};

/// The model, its constraint rows and scratch space.
pub(crate) struct System<'a> {
    pub(crate) model: &'a Model,
    pub(crate) cons: Constraints,
    /// Column scale per coordinate (`L` for positions, 1 for Euler parameters).
    pub(crate) scale: Vec<f64>,
    /// Row scale per constraint row (`L^−k` for a row in m^k).
    pub(crate) row_scale: Vec<f64>,
    /// Sparse linear algebra (module `sparse`) instead of dense matrices.
    pub(crate) sparse: bool,
    phi: DVector<f64>,
    jac: Triplets,
    /// The configuration of the last triplets (`jac` and `phi`).
    jac_at: DVector<f64>,
    split: Option<Split>,
    kkt: Option<Kkt>,
    hess: BlockHessian,
}

/// The factorization of `Φ_u` and the values of `Φ_v` at one configuration.
#[derive(Clone)]
pub(crate) enum Factors {
    /// Dense LU with partial pivoting (small models).
    Dense {
        lu: LU<f64, nalgebra::Dyn, nalgebra::Dyn>,
        phi_v: DMatrix<f64>,
    },
    /// faer's sparse LU.
    Sparse(SparseFactors),
}

impl Factors {
    /// `Φ_u x = b`; `None` if `Φ_u` is singular.
    pub(crate) fn solve(&self, b: &DVector<f64>) -> Option<DVector<f64>> {
        match self {
            Factors::Dense { lu, .. } => {
                if b.is_empty() {
                    Some(b.clone())
                } else {
                    lu.solve(b)
                }
            }
            Factors::Sparse(f) => {
                let mut x = b.clone();
                f.solve(x.as_mut_slice()).then_some(x)
            }
        }
    }

    /// `Φ_uᵀ x = b`; `None` if `Φ_u` is singular.
    pub(crate) fn solve_transpose(&self, b: DVector<f64>) -> Option<DVector<f64>> {
        match self {
            Factors::Dense { lu, .. } => {
                if b.is_empty() {
                    return Some(b);
                }
                solve_transpose(lu, b)
            }
            Factors::Sparse(f) => {
                let mut x = b;
                f.solve_transpose(x.as_mut_slice()).then_some(x)
            }
        }
    }

    /// `Φ_v x`.
    pub(crate) fn phi_v_mul(&self, x: &DVector<f64>, rows: usize) -> DVector<f64> {
        match self {
            Factors::Dense { phi_v, .. } => phi_v * x,
            Factors::Sparse(f) => DVector::from_vec(f.phi_v_mul(x.as_slice(), rows)),
        }
    }

    /// `Φ_vᵀ y`.
    pub(crate) fn phi_v_tr_mul(&self, y: &DVector<f64>, dof: usize) -> DVector<f64> {
        match self {
            Factors::Dense { phi_v, .. } => phi_v.transpose() * y,
            Factors::Sparse(f) => DVector::from_vec(f.phi_v_tr_mul(y.as_slice(), dof)),
        }
    }

    /// Whether `Φ_u` has become ill-conditioned (dense: a pivot of `U` below `1e-8` of the
    /// largest; the sparse factors do not tell, and the minimizer re-partitions when the
    /// corrector or the line search fails instead).
    pub(crate) fn ill_conditioned(&self) -> bool {
        match self {
            Factors::Dense { lu, .. } => {
                let d = lu.u().diagonal().abs();
                !d.is_empty() && d.min() < 1e-8 * d.max()
            }
            Factors::Sparse(_) => false,
        }
    }
}

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

/// Column scale per coordinate: the characteristic length for positions, 1 for Euler
/// parameters.
pub(crate) fn coordinate_scale(model: &Model) -> Vec<f64> {
    let l = model.length_scale;
    (0..model.coordinate_count())
        .map(|i| if i % 7 < 3 { l } else { 1.0 })
        .collect()
}

/// Solves `Aᵀ x = b` with the factors `P A = L U` of `A`: `Uᵀ y = b`, `Lᵀ z = y`, `x = Pᵀ z`.
fn solve_transpose(
    lu: &LU<f64, nalgebra::Dyn, nalgebra::Dyn>,
    b: DVector<f64>,
) -> Option<DVector<f64>> {
    let y = lu.u().tr_solve_upper_triangular(&b)?;
    let mut z = lu.l().tr_solve_lower_triangular(&y)?;
    lu.p().inv_permute_rows(&mut z);
    Some(z)
}

/// Why the corrector gave up.
#[derive(Debug)]
pub(crate) struct CorrectorFailure;

/// Models with more coordinates than this (40 bodies) use the sparse path when the choice is
/// automatic. The sparse path is as fast or faster from 5 bodies up (BENCHMARKS.md), but the
/// dense path stays the default for small models: its Newton steps use the exact eigenvalues
/// of the reduced Hessian (negative curvature handled mode by mode), and its full-pivoting
/// partition picks the assembly branch the robot tests are written against (from a far start
/// the tractor-trailer reaches a different, lower-energy branch on the sparse path).
pub(crate) const SPARSE_FROM_COORDINATES: usize = 7 * 40;

impl<'a> System<'a> {
    pub(crate) fn new(model: &'a Model, cons: Constraints) -> Self {
        let scale = coordinate_scale(model);
        let l = model.length_scale;
        let row_scale = (0..cons.len())
            .map(|i| l.powi(-cons.length_power(i)))
            .collect();
        System {
            row_scale,
            model,
            phi: DVector::zeros(cons.len()),
            jac: Triplets::default(),
            jac_at: DVector::zeros(0),
            cons,
            scale,
            sparse: model.coordinate_count() > SPARSE_FROM_COORDINATES,
            split: None,
            kkt: None,
            hess: BlockHessian::default(),
        }
    }

    /// The system with the linear algebra of `options` (automatic: by size).
    pub(crate) fn with_options(
        model: &'a Model,
        cons: Constraints,
        options: &super::Options,
    ) -> Self {
        let mut sys = Self::new(model, cons);
        match options.linear_algebra {
            super::LinearAlgebra::Auto => {}
            super::LinearAlgebra::Dense => sys.sparse = false,
            super::LinearAlgebra::Sparse => sys.sparse = true,
        }
        sys
    }

    /// `Φ(q)` (invalidates the triplets' `Φ`).
    pub(crate) fn residual(&mut self, q: &DVector<f64>) -> &DVector<f64> {
        self.jac_at = DVector::zeros(0);
        self.cons.evaluate(self.model, q, &mut self.phi, None);
        &self.phi
    }

    /// `‖D Φ‖∞` at the point of the last evaluation: the residual with each row in m^k divided
    /// by `L^k`, so that one tolerance means the same in any length unit.
    pub(crate) fn dimensionless_residual(&self) -> f64 {
        self.phi
            .iter()
            .zip(&self.row_scale)
            .map(|(p, s)| (p * s).abs())
            .fold(0.0, f64::max)
    }

    /// `Φ` at the point of the last [`System::jacobian`] or [`System::residual`] call.
    pub(crate) fn phi(&self) -> &DVector<f64> {
        &self.phi
    }

    /// `Φ(q)` and the triplets of `Φ_q(q)` into the scratch (kept if they are at `q`).
    fn triplets(&mut self, q: &DVector<f64>) {
        if self.jac_at.len() == q.len() && self.jac_at == *q {
            return;
        }
        self.cons
            .evaluate(self.model, q, &mut self.phi, Some(&mut self.jac));
        self.jac_at.clone_from(q);
    }

    /// Dense `Φ_q(q)` (and `Φ(q)` into the scratch).
    #[cfg(test)]
    pub(crate) fn jacobian(&mut self, q: &DVector<f64>) -> DMatrix<f64> {
        self.triplets(q);
        self.jac.to_dense()
    }

    /// Partition at `q` (full pivoting of the dense `Φ_q`, or the sparse body-by-body
    /// elimination).
    pub(crate) fn partition(&mut self, q: &DVector<f64>) -> Partition {
        self.triplets(q);
        if self.sparse {
            super::sparse::partition::partition(
                self.model,
                self.cons.len(),
                q.len(),
                &self.jac.entries,
                &self.row_scale,
                &self.scale,
            )
        } else {
            partition(&self.jac.to_dense(), &self.row_scale, &self.scale)
        }
    }

    /// Factors `Φ_u` of the last triplets under `part`.
    fn factors(&mut self, part: &Partition) -> Option<Factors> {
        let n = self.model.coordinate_count();
        let m = self.cons.len();
        if self.sparse {
            let entries = &self.jac.entries;
            if !self
                .split
                .as_ref()
                .is_some_and(|s| s.fits(part, entries.len()))
            {
                self.split = Some(Split::new(part, m, n, entries)?);
            }
            let split = self.split.as_mut()?;
            return Some(Factors::Sparse(split.factor(entries)));
        }
        let r = part.rows.len();
        let dof = part.independent.len();
        let mut row_pos = vec![usize::MAX; m];
        for (k, &i) in part.rows.iter().enumerate() {
            row_pos[i] = k;
        }
        // Column position: dependent k, or independent dof-offset k.
        let mut col_pos = vec![(false, 0usize); n];
        for (k, &c) in part.dependent.iter().enumerate() {
            col_pos[c] = (true, k);
        }
        for (k, &c) in part.independent.iter().enumerate() {
            col_pos[c] = (false, k);
        }
        let mut phi_u = DMatrix::zeros(r, r);
        let mut phi_v = DMatrix::zeros(r, dof);
        for &(i, c, v) in &self.jac.entries {
            let a = row_pos[i];
            if a == usize::MAX {
                continue;
            }
            match col_pos[c] {
                (true, k) => phi_u[(a, k)] += v,
                (false, k) => phi_v[(a, k)] += v,
            }
        }
        Some(Factors::Dense {
            lu: phi_u.lu(),
            phi_v,
        })
    }

    /// The Newton change of the dependent coordinates `Φ_u δu = −Φ` at `q` (independent rows);
    /// also leaves `Φ(q)` in the scratch.
    pub(crate) fn dependent_step(
        &mut self,
        q: &DVector<f64>,
        part: &Partition,
    ) -> Option<DVector<f64>> {
        self.triplets(q);
        let f = self.factors(part)?;
        let rhs = DVector::from_iterator(part.rows.len(), part.rows.iter().map(|&a| -self.phi[a]));
        f.solve(&rhs)
    }

    /// Newton corrector: solves the independent rows for `u` with `v` fixed; returns the number
    /// of iterations. Also fails if the redundant rows are not satisfied at the end.
    #[cfg(test)]
    pub(crate) fn correct(
        &mut self,
        q: &mut DVector<f64>,
        part: &Partition,
        tol: f64,
        max_iterations: usize,
    ) -> Result<usize, CorrectorFailure> {
        self.correct_from(q, part, tol, max_iterations, None)
    }

    /// The corrector, starting with chord steps on the factors `chord` of `Φ_u` at a nearby
    /// point (no Jacobian, no factorization: `Φ_u(q₀) δu = −Φ(q)`) while each step at least
    /// halves the residual, then Newton steps with `Φ_u(q)` refactored.
    pub(crate) fn correct_from(
        &mut self,
        q: &mut DVector<f64>,
        part: &Partition,
        tol: f64,
        max_iterations: usize,
        mut chord: Option<&Factors>,
    ) -> Result<usize, CorrectorFailure> {
        let mut first = f64::INFINITY;
        let mut last = f64::INFINITY;
        for it in 0..=max_iterations {
            self.residual(q);
            let res = part
                .rows
                .iter()
                .map(|&i| self.phi[i].abs() * self.row_scale[i])
                .fold(0.0, f64::max);
            if !res.is_finite() {
                return Err(CorrectorFailure);
            }
            // Chord steps converge linearly: they go on to 10⁻³ of the tolerance, so that the
            // result is as tight as a Newton step would leave it (a stalled chord step
            // switches to Newton).
            let target = if chord.is_some() { 1e-3 * tol } else { tol };
            if res <= target || (res <= tol && it == max_iterations) {
                let all = self.dimensionless_residual();
                return if all <= tol.max(1e-8) {
                    Ok(it)
                } else {
                    Err(CorrectorFailure)
                };
            }
            if it == 0 {
                first = res;
            } else if res > 1e3 * first.max(tol) {
                return Err(CorrectorFailure);
            }
            if it == max_iterations {
                break;
            }
            if res > 0.5 * last {
                chord = None;
            }
            last = res;
            let du = match chord {
                Some(f) => {
                    let rhs = DVector::from_iterator(
                        part.rows.len(),
                        part.rows.iter().map(|&a| -self.phi[a]),
                    );
                    f.solve(&rhs)
                }
                None => self.dependent_step(q, part),
            };
            let Some(du) = du else {
                return Err(CorrectorFailure);
            };
            for (k, &c) in part.dependent.iter().enumerate() {
                q[c] += du[k];
            }
        }
        Err(CorrectorFailure)
    }

    /// Energy, multipliers and reduced gradient at a feasible `q`; `None` where the energy is
    /// undefined or `Φ_u` is singular.
    pub(crate) fn evaluate(&mut self, q: &DVector<f64>, part: &Partition) -> Option<Eval> {
        self.triplets(q);
        let mut grad_q = DVector::zeros(q.len());
        let energy = potential(self.model, &self.cons.branches, q, &mut grad_q, None)?;
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
            grad_v[b] *= self.scale[c];
        }
        let merit = energy.total
            - part
                .rows
                .iter()
                .zip(mu.iter())
                .map(|(&row, m)| m * self.phi[row])
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
        let n = self.model.coordinate_count();
        let mut dq = DVector::zeros(n);
        let mut dvu = dv.clone();
        for (b, &c) in part.independent.iter().enumerate() {
            dvu[b] *= self.scale[c];
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
            out[b] *= self.scale[c];
        }
        out
    }

    /// The null-space basis `Z = [H; I] S` (n × dof) at `eval`.
    pub(crate) fn null_basis(&self, part: &Partition, eval: &Eval) -> DMatrix<f64> {
        let n = self.model.coordinate_count();
        let dof = part.independent.len();
        let mut z = DMatrix::zeros(n, dof);
        for b in 0..dof {
            let mut e = DVector::zeros(dof);
            e[b] = 1.0;
            z.set_column(b, &self.tangent_step(part, eval, &e));
        }
        z
    }

    /// The multiplier weights `−μ` over all rows.
    fn weights(&self, part: &Partition, eval: &Eval) -> DVector<f64> {
        let mut weights = DVector::zeros(self.cons.len());
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
            self.model,
            &self.cons.branches,
            q,
            &mut g,
            Some(&mut w as &mut dyn HessianSink),
        );
        self.cons
            .add_hessian(self.model, q, &self.weights(part, eval), &mut w);
        w
    }

    /// `W` into the block-sparse scratch.
    fn lagrangian_blocks(&mut self, q: &DVector<f64>, part: &Partition, eval: &Eval) {
        let mut hess = std::mem::take(&mut self.hess);
        hess.clear();
        let mut g = DVector::zeros(q.len());
        let _ = potential(
            self.model,
            &self.cons.branches,
            q,
            &mut g,
            Some(&mut hess as &mut dyn HessianSink),
        );
        self.cons
            .add_hessian(self.model, q, &self.weights(part, eval), &mut hess);
        self.hess = hess;
    }

    /// The reduced Hessian `Zᵀ W Z` in scaled coordinates (dense: `O(n² dof)`; sparse: one
    /// column at a time through the factors, `O(dof · nnz)`).
    pub(crate) fn reduced_hessian(
        &mut self,
        q: &DVector<f64>,
        part: &Partition,
        eval: &Eval,
    ) -> DMatrix<f64> {
        let hr = if self.sparse {
            self.lagrangian_blocks(q, part, eval);
            let dof = part.independent.len();
            let mut hr = DMatrix::zeros(dof, dof);
            for b in 0..dof {
                let mut e = DVector::zeros(dof);
                e[b] = 1.0;
                hr.set_column(b, &self.reduced_apply(part, eval, &e));
            }
            hr
        } else {
            let z = self.null_basis(part, eval);
            let w = self.lagrangian_hessian(q, part, eval);
            z.transpose() * w * &z
        };
        (&hr + hr.transpose()) * 0.5
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
        self.hess.mul_add(zx.as_slice(), wzx.as_mut_slice());
        self.tangent_transpose(part, eval, &wzx)
    }

    /// Assembles `W` at `q` and factors the KKT matrix with the shift `δ` (scaled coordinates).
    ///
    /// `W` is augmented by `Φ_qᵀ D R D Φ_q` over the independent rows (`R` diagonal and
    /// positive): the KKT solution is the same (its `δq` satisfies `Φ_q δq = 0`) and so is the
    /// matrix's inertia (the augmented matrix is congruent to the plain one), but the position
    /// coordinates, on which gravity has no curvature, get positive pivots in the LDLᵀ order.
    /// `R_k` is the largest scaled diagonal entry of `W` among the row's coordinates (at least
    /// `10⁻⁶` of the largest overall), so that the term is on the scale of `W` nearby.
    pub(crate) fn factor_kkt(
        &mut self,
        q: &DVector<f64>,
        part: &Partition,
        eval: &Eval,
        fresh: bool,
        delta: f64,
    ) -> Factored {
        if fresh {
            self.lagrangian_blocks(q, part, eval);
            self.triplets(q);
            self.augment(part);
            let (m, n) = (self.cons.len(), q.len());
            if !self
                .kkt
                .as_ref()
                .is_some_and(|k| k.fits(part, self.jac.entries.len(), self.hess.keys.len()))
            {
                self.kkt = Kkt::new(part, m, n, &self.jac.entries, &self.hess);
            }
            let Some(kkt) = self.kkt.as_mut() else {
                return Factored::None;
            };
            kkt.assemble(&self.jac.entries, &self.row_scale, &self.scale, &self.hess);
        }
        self.kkt
            .as_mut()
            .map_or(Factored::None, |k| k.factor(delta))
    }

    /// Adds `Φ_qᵀ D R D Φ_q` over the independent rows to the block Hessian (see
    /// [`System::factor_kkt`]).
    fn augment(&mut self, part: &Partition) {
        let n = self.model.coordinate_count();
        let mut wdiag = vec![0.0f64; n];
        for (&(a, b), blk) in self.hess.keys.iter().zip(&self.hess.values) {
            if a == b {
                for i in 0..7 {
                    wdiag[7 * a + i] = blk[8 * i].abs() * self.scale[7 * a + i].powi(2);
                }
            }
        }
        let floor = 1e-6 * wdiag.iter().fold(0.0f64, |x, &y| x.max(y)) + 1e-12;
        let mut in_part = vec![false; self.cons.len()];
        for &r in &part.rows {
            in_part[r] = true;
        }
        let entries = &self.jac.entries;
        let mut pending: Option<([Option<crate::model::BodyId>; 2], crate::jet::LMat)> = None;
        let mut k = 0;
        while k < entries.len() {
            let row = entries[k].0;
            let mut end = k;
            while end < entries.len() && entries[end].0 == row {
                end += 1;
            }
            let group = &entries[k..end];
            k = end;
            if !in_part[row] {
                continue;
            }
            let rho =
                group.iter().fold(floor, |a, e| a.max(wdiag[e.1])) * self.row_scale[row].powi(2);
            let mut bodies: [Option<crate::model::BodyId>; 2] = [None, None];
            let mut local = true;
            for e in group {
                let b = e.1 / 7;
                if bodies.iter().any(|x| x.map(|y| y.0) == Some(b)) {
                    continue;
                }
                match bodies.iter().position(|x| x.is_none()) {
                    Some(slot) => bodies[slot] = Some(crate::model::BodyId(b)),
                    None => local = false,
                }
            }
            if !local {
                for a in group {
                    for b in group {
                        self.hess.add_entry(a.1, b.1, rho * a.2 * b.2);
                    }
                }
                continue;
            }
            let mut g = crate::jet::LVec::zeros();
            for e in group {
                let side = usize::from(bodies[0].map(|x| x.0) != Some(e.1 / 7));
                g[7 * side + e.1 % 7] += e.2;
            }
            let same = pending.as_ref().is_some_and(|(b, _)| {
                b.iter()
                    .map(|x| x.map(|y| y.0))
                    .eq(bodies.iter().map(|x| x.map(|y| y.0)))
            });
            if !same {
                if let Some((b, acc)) = pending.take() {
                    self.hess.add_block(&b, &acc, 1.0);
                }
                pending = Some((bodies, crate::jet::LMat::zeros()));
            }
            if let Some((_, acc)) = pending.as_mut() {
                *acc += g * g.transpose() * rho;
            }
        }
        if let Some((b, acc)) = pending.take() {
            self.hess.add_block(&b, &acc, 1.0);
        }
    }

    /// Replaces the KKT factors by LU (see [`Kkt::fall_back_to_lu`]).
    pub(crate) fn kkt_fall_back_to_lu(&mut self) -> Factored {
        self.kkt
            .as_mut()
            .map_or(Factored::None, |k| k.fall_back_to_lu())
    }

    /// The largest diagonal entry of the scaled `W` of the last KKT assembly.
    pub(crate) fn kkt_scale(&self) -> f64 {
        self.kkt.as_ref().map_or(0.0, |k| k.max_diagonal())
    }

    /// Solves the factored KKT system for the right side `b` over all coordinates (scaled;
    /// zero constraint rows); returns the scaled `δq̂`.
    pub(crate) fn kkt_solve(&self, b: &DVector<f64>) -> Option<DVector<f64>> {
        self.kkt_solve_to(b, 1e-13)
    }

    /// [`System::kkt_solve`], refined only until the backward error is below `target`.
    pub(crate) fn kkt_solve_to(&self, b: &DVector<f64>, target: f64) -> Option<DVector<f64>> {
        let kkt = self.kkt.as_ref()?;
        let n = kkt.coordinates();
        let mut rhs = vec![0.0; n + kkt.rows()];
        rhs[..n].copy_from_slice(b.as_slice());
        kkt.solve(&mut rhs, target)
            .then(|| DVector::from_column_slice(&rhs[..n]))
    }
}

#[cfg(test)]
mod tests {
    //! The assembled global derivatives against central differences, on real robots at
    //! random (non-assembled, non-unit) configurations.
    use super::*;
    use crate::urdf::{load_str, ImportOptions};

    /// Analytic value against a central difference, relative to `1 + |value|`.
    fn assert_fd(analytic: f64, fd: f64, tol: f64, what: impl Fn() -> String) {
        assert!(
            (fd - analytic).abs() < tol * (1.0 + analytic.abs().min(fd.abs())),
            "{}",
            what()
        );
    }

    fn models() -> Vec<Model> {
        [
            include_str!("../../robots/pendulum.urdf"),
            include_str!("../../robots/slider_crank.urdf"),
            include_str!("../../robots/four_bar_spatial.urdf"),
        ]
        .iter()
        .map(|t| {
            load_str(t, "robot.urdf", &ImportOptions::default())
                .unwrap()
                .model
        })
        .collect()
    }

    fn random_q(n: usize, seed: u64) -> DVector<f64> {
        let mut s = seed;
        DVector::from_fn(n, |i, _| {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let r = ((s >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0;
            if i % 7 == 3 {
                1.0 + 0.2 * r
            } else {
                0.3 * r
            }
        })
    }

    #[test]
    fn potential_gradient_and_hessian_match_finite_differences() {
        for model in models() {
            let n = model.coordinate_count();
            let q = random_q(n, 7);
            let mut g = DVector::zeros(n);
            let mut h = DMatrix::zeros(n, n);
            potential(
                &model,
                &Default::default(),
                &q,
                &mut g,
                Some(&mut h as &mut dyn HessianSink),
            )
            .unwrap();
            let step = 1e-6;
            for i in 0..n {
                let mut qp = q.clone();
                let mut qm = q.clone();
                qp[i] += step;
                qm[i] -= step;
                let (mut gp, mut gm) = (DVector::zeros(n), DVector::zeros(n));
                let vp = potential(&model, &Default::default(), &qp, &mut gp, None)
                    .unwrap()
                    .total;
                let vm = potential(&model, &Default::default(), &qm, &mut gm, None)
                    .unwrap()
                    .total;
                let fd = (vp - vm) / (2.0 * step);
                assert_fd(g[i], fd, 1e-6, || {
                    format!("{}: V_q[{i}] {} vs {fd}", model.name, g[i])
                });
                for j in 0..n {
                    let fdh = (gp[j] - gm[j]) / (2.0 * step);
                    assert_fd(h[(j, i)], fdh, 1e-5, || {
                        format!("{}: V_qq[{j},{i}] {} vs {fdh}", model.name, h[(j, i)])
                    });
                }
            }
        }
    }

    #[test]
    fn constraint_jacobian_and_weighted_hessian_match_finite_differences() {
        for model in models() {
            let n = model.coordinate_count();
            let sys_cons = Constraints::new(&model, &[(crate::model::JointId(0), 0, 0.3)]);
            let mut sys = System::new(&model, sys_cons);
            let m = sys.cons.len();
            let q = random_q(n, 11);
            let j = sys.jacobian(&q);
            let w = DVector::from_fn(m, |i, _| ((i * 37 % 11) as f64 - 5.0) * 0.1);
            let mut h = DMatrix::zeros(n, n);
            sys.cons.add_hessian(&model, &q, &w, &mut h);
            let step = 1e-6;
            for i in 0..n {
                let mut qp = q.clone();
                let mut qm = q.clone();
                qp[i] += step;
                qm[i] -= step;
                let jp = sys.jacobian(&qp);
                let php = sys.phi.clone();
                let jm = sys.jacobian(&qm);
                let phm = sys.phi.clone();
                for r in 0..m {
                    let fd = (php[r] - phm[r]) / (2.0 * step);
                    assert_fd(j[(r, i)], fd, 1e-6, || {
                        format!(
                            "{}: Φ_q[{},{i}] ({}) {} vs {fd}",
                            model.name,
                            r,
                            sys.cons.row_name(r),
                            j[(r, i)]
                        )
                    });
                }
                let gp = jp.transpose() * &w;
                let gm = jm.transpose() * &w;
                for k in 0..n {
                    let fd = (gp[k] - gm[k]) / (2.0 * step);
                    assert_fd(h[(k, i)], fd, 1e-5, || {
                        format!("{}: (wᵀΦ)_qq[{k},{i}] {} vs {fd}", model.name, h[(k, i)])
                    });
                }
            }
        }
    }

    /// The Newton step from the sparse KKT system equals `−Ĥ⁻¹ ∇f` with the reduced Hessian
    /// formed explicitly (dense path), and the sparse path's reduced gradient and reduced
    /// Hessian equal the dense path's under the same partition.
    #[test]
    fn kkt_step_is_the_reduced_newton_step() {
        let mut all = models();
        all.push(
            load_str(
                &crate::generate::ladder(3),
                "l.urdf",
                &ImportOptions::default(),
            )
            .unwrap()
            .model,
        );
        for model in all {
            let q0 = crate::solver::initial_state(&model).q;
            let q = crate::solver::assemble_only(&model, q0, &mut Default::default(), &[]).unwrap();
            let mut dense = System::new(&model, Constraints::new(&model, &[]));
            dense.sparse = false;
            let part = dense.partition(&q);
            let ed = dense.evaluate(&q, &part).unwrap();
            let hd = dense.reduced_hessian(&q, &part, &ed);
            let mut sparse = System::new(&model, Constraints::new(&model, &[]));
            sparse.sparse = true;
            let es = sparse.evaluate(&q, &part).unwrap();
            let hs = sparse.reduced_hessian(&q, &part, &es);
            let scale = hd.amax().max(1.0);
            assert!((&hd - &hs).amax() < 1e-9 * scale, "{}", model.name);
            assert!((&ed.grad_v - &es.grad_v).amax() < 1e-9 * (1.0 + ed.grad_v.amax()));
            let g = &es.grad_v;
            if g.amax() < 1e-12 {
                continue;
            }
            assert!(
                sparse.factor_kkt(&q, &part, &es, true, 0.0)
                    != crate::solver::sparse::kkt::Factored::None,
                "{}",
                model.name
            );
            let mut b = DVector::zeros(q.len());
            for (k, &c) in part.independent.iter().enumerate() {
                b[c] = -g[k];
            }
            let dq = sparse.kkt_solve(&b).unwrap();
            let d = DVector::from_iterator(g.len(), part.independent.iter().map(|&c| dq[c]));
            let expected = hd.clone().lu().solve(&(-g)).unwrap();
            assert!(
                (&d - &expected).amax() < 1e-8 * expected.amax(),
                "{}: KKT step {d} vs reduced Newton step {expected}",
                model.name
            );
            // δq is the tangent step of δv: Φ_q δq = 0 on the independent rows.
            let full = sparse.tangent_step(&part, &es, &d);
            let dq_unscaled =
                DVector::from_iterator(q.len(), (0..q.len()).map(|i| dq[i] * sparse.scale[i]));
            assert!(
                (&full - &dq_unscaled).amax() < 1e-8 * (1.0 + full.amax()),
                "{}",
                model.name
            );
        }
    }

    /// The reduced gradient equals the derivative of f(v) = V(u(v), v) along each independent
    /// coordinate (finite differences through the corrector), and the reduced Hessian the
    /// derivative of the reduced gradient.
    #[test]
    fn reduced_gradient_and_hessian_match_differences_through_the_corrector() {
        for model in models() {
            let q0 = crate::solver::initial_state(&model).q;
            let q = crate::solver::assemble_only(&model, q0, &mut Default::default(), &[]).unwrap();
            let mut sys = System::new(&model, Constraints::new(&model, &[]));
            let part = sys.partition(&q);
            let e = sys.evaluate(&q, &part).unwrap();
            let hr = sys.reduced_hessian(&q, &part, &e);
            let step = 1e-5;
            for (b, &c) in part.independent.iter().enumerate() {
                let at = |sign: f64, sys: &mut System| {
                    let mut qq = q.clone();
                    qq[c] += sign * step * sys.scale[c];
                    sys.correct(&mut qq, &part, 1e-13, 50).unwrap();
                    sys.evaluate(&qq, &part).unwrap()
                };
                let ep = at(1.0, &mut sys);
                let em = at(-1.0, &mut sys);
                let fd = (ep.energy.total - em.energy.total) / (2.0 * step);
                assert_fd(e.grad_v[b], fd, 1e-6, || {
                    format!("{}: ∂f/∂v[{b}] {} vs {fd}", model.name, e.grad_v[b])
                });
                for a in 0..part.independent.len() {
                    let fdh = (ep.grad_v[a] - em.grad_v[a]) / (2.0 * step);
                    assert_fd(hr[(a, b)], fdh, 1e-5, || {
                        format!(
                            "{}: reduced Hessian [{a},{b}] {} vs {fdh}",
                            model.name,
                            hr[(a, b)]
                        )
                    });
                }
            }
        }
    }
}
