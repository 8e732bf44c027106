//! The KKT system of a Newton step on the sparse path: `[W Φ_uᵀ; Φ_u 0]` over the independent
//! rows, with `W` augmented by `Φ_qᵀ D R D Φ_q` (same solution, same inertia), factored by
//! LDLᵀ with a shift `δ` or by LU as a fall-back (module `sparse::kkt`).

use super::kkt_matrix::KktMatrix;
use super::Backend;
use super::{Eval, System};
use crate::forces::potential;
use crate::solver::partition::Partition;
use crate::solver::sparse::kkt::{Factored, Kkt};
use crate::solver::tree::kkt::TreeKkt;
use nalgebra::DVector;

impl System<'_> {
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
        if fresh && !self.assemble_kkt(q, part, eval) {
            return Factored::None;
        }
        self.factor_assembled(delta)
    }

    /// Factors the KKT matrix in place with the shift `δ`.
    fn factor_assembled(&mut self, delta: f64) -> Factored {
        self.work
            .kkt
            .as_mut()
            .map_or(Factored::None, |k| k.factor(delta))
    }

    /// [`System::factor_kkt`] for a Newton step: the same matrix, assembled by the fused pass
    /// where the tree structure fits (module `tree::fused`: no block Hessian, whose values
    /// are left as they were; [`System::reduced_apply`] needs [`System::factor_kkt`]).
    pub(crate) fn factor_step_kkt(
        &mut self,
        q: &DVector<f64>,
        part: &Partition,
        eval: &Eval,
        fresh: bool,
        delta: f64,
    ) -> Factored {
        if fresh && !self.assemble_fused(q, part, eval) && !self.assemble_kkt(q, part, eval) {
            return Factored::None;
        }
        self.factor_assembled(delta)
    }

    /// The fused assembly of the tree KKT matrix at `q` (module `tree::fused`); false where
    /// the structure in place does not fit (the caller assembles by the general path).
    pub(crate) fn assemble_fused(
        &mut self,
        q: &DVector<f64>,
        part: &Partition,
        eval: &Eval,
    ) -> bool {
        if self.backend != Backend::Tree {
            return false;
        }
        self.triplets(q);
        let (triplets, blocks) = (self.work.jac.entries.len(), self.work.hess.keys.len());
        // Only a tree structure that fits (a sparse one stays in place for the general path).
        let fits =
            matches!(&self.work.kkt, Some(KktMatrix::Tree(t)) if t.fits(part, triplets, blocks));
        if !fits {
            return false;
        }
        let Some(KktMatrix::Tree(mut tree)) = self.work.kkt.take() else {
            return false;
        };
        let (model, n) = (self.problem.model, q.len());
        let mut g = std::mem::take(&mut self.work.grad);
        if g.len() == n {
            g.fill(0.0);
        } else {
            g = DVector::zeros(n);
        }
        let mut weights = std::mem::take(&mut self.work.weights);
        weights.fill(0.0);
        weights.resize_vertically_mut(self.problem.cons.len(), 0.0);
        for (k, &row) in part.rows.iter().enumerate() {
            weights[row] = -eval.mu[k];
        }
        let mut sink = tree.fused_begin(&self.work.hess.keys);
        let _ = potential(
            model,
            &self.problem.cons.branches,
            q,
            &mut g,
            Some(&mut sink),
        );
        self.problem.cons.add_hessian(model, q, &weights, &mut sink);
        let complete = !sink.missing;
        self.work.grad = g;
        self.work.weights = weights;
        if complete {
            let columns = &self.problem.scaling.columns;
            let mut wdiag = std::mem::take(&mut self.work.wdiag);
            tree.fused_diagonal(columns, &mut wdiag);
            let mut sink = tree.fused_sink();
            self.augment_into(part, wdiag, &mut sink);
            let complete = !sink.missing;
            let scaling = &self.problem.scaling;
            tree.fused_finish(&self.work.jac.entries, &scaling.rows, &scaling.columns);
            self.work.kkt = Some(KktMatrix::Tree(tree));
            return complete;
        }
        self.work.kkt = Some(KktMatrix::Tree(tree));
        false
    }

    /// Assembles `W` at `q` and the KKT matrix (as [`System::factor_kkt`]) without factoring
    /// it; false if its structure cannot be built.
    pub(crate) fn assemble_kkt(&mut self, q: &DVector<f64>, part: &Partition, eval: &Eval) -> bool {
        self.kkt_blocks(q, part, eval);
        self.assemble_kkt_of_blocks(q, part)
    }

    /// The first half of [`System::assemble_kkt`]: `W` (augmented) into the block Hessian and
    /// the triplets at `q`; the second, [`System::assemble_kkt_of_blocks`], needs no `Eval`.
    pub(crate) fn kkt_blocks(&mut self, q: &DVector<f64>, part: &Partition, eval: &Eval) {
        self.lagrangian_blocks(q, part, eval);
        self.triplets(q);
        self.augment(part);
    }

    /// The KKT matrix of the blocks and triplets of [`System::kkt_blocks`], assembled.
    pub(crate) fn assemble_kkt_of_blocks(&mut self, q: &DVector<f64>, part: &Partition) -> bool {
        let (m, n) = (self.problem.cons.len(), q.len());
        let (triplets, blocks) = (self.work.jac.entries.len(), self.work.hess.keys.len());
        if !self
            .work
            .kkt
            .as_ref()
            .is_some_and(|k| k.fits(part, triplets, blocks))
        {
            let (entries, hess) = (&self.work.jac.entries, &self.work.hess);
            let tree = (self.backend == Backend::Tree
                && self.work.tree_kkt_refused != Some((part.id, triplets)))
            .then(|| TreeKkt::new(part, m, n, entries, hess))
            .flatten();
            if tree.is_none() && self.backend == Backend::Tree {
                self.work.tree_kkt_refused = Some((part.id, triplets));
            }
            self.work.kkt = match tree {
                Some(t) => Some(KktMatrix::Tree(Box::new(t))),
                None => Kkt::new(part, m, n, entries, hess).map(|k| KktMatrix::Sparse(Box::new(k))),
            };
        }
        let Some(kkt) = self.work.kkt.as_mut() else {
            return false;
        };
        kkt.assemble(
            &self.work.jac.entries,
            &self.problem.scaling.rows,
            &self.problem.scaling.columns,
            &self.work.hess,
        );
        true
    }

    /// Replaces the KKT factors by LU (see [`Kkt::fall_back_to_lu`]).
    pub(crate) fn kkt_fall_back_to_lu(&mut self) -> Factored {
        self.work
            .kkt
            .as_mut()
            .map_or(Factored::None, |k| k.fall_back_to_lu())
    }

    /// The largest diagonal entry of the scaled `W` of the last KKT assembly.
    pub(crate) fn kkt_scale(&self) -> f64 {
        self.work.kkt.as_ref().map_or(0.0, |k| k.max_diagonal())
    }

    /// Solves the factored KKT system for the right side `b` over all coordinates (scaled;
    /// zero constraint rows); returns the scaled `δq̂`.
    pub(crate) fn kkt_solve(&self, b: &DVector<f64>) -> Option<DVector<f64>> {
        self.kkt_solve_to(b, 1e-13)
    }

    /// [`System::kkt_solve`], refined only until the backward error is below `target`.
    pub(crate) fn kkt_solve_to(&self, b: &DVector<f64>, target: f64) -> Option<DVector<f64>> {
        let kkt = self.work.kkt.as_ref()?;
        let n = kkt.coordinates();
        let mut rhs = vec![0.0; n + kkt.rows()];
        rhs[..n].copy_from_slice(b.as_slice());
        kkt.solve(&mut rhs, target)
            .then(|| DVector::from_column_slice(&rhs[..n]))
    }
}
