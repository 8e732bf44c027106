//! The KKT system of a Newton step on the sparse path: `[W Φ_uᵀ; Φ_u 0]` over the independent
//! rows, with `W` augmented by `Φ_qᵀ D R D Φ_q` (same solution, same inertia), factored by
//! LDLᵀ with a shift `δ` or by LU as a fall-back (module `sparse::kkt`).

use super::kkt_matrix::KktMatrix;
use super::Backend;
use super::{Eval, System};
use crate::jet::{HessianSink, LMat, NL};
use crate::model::BodyId;
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
        self.work
            .kkt
            .as_mut()
            .map_or(Factored::None, |k| k.factor(delta))
    }

    /// Assembles `W` at `q` and the KKT matrix (as [`System::factor_kkt`]) without factoring
    /// it; false if its structure cannot be built.
    pub(crate) fn assemble_kkt(&mut self, q: &DVector<f64>, part: &Partition, eval: &Eval) -> bool {
        self.lagrangian_blocks(q, part, eval);
        self.triplets(q);
        self.augment(part);
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

    /// Adds `Φ_qᵀ D R D Φ_q` over the independent rows to the block Hessian (see
    /// [`System::factor_kkt`]).
    fn augment(&mut self, part: &Partition) {
        let n = self.problem.model.coordinate_count();
        let mut wdiag = vec![0.0f64; n];
        for (&(a, b), blk) in self.work.hess.keys.iter().zip(&self.work.hess.values) {
            if a == b {
                for i in 0..7 {
                    wdiag[7 * a + i] =
                        blk[8 * i].abs() * self.problem.scaling.columns[7 * a + i].powi(2);
                }
            }
        }
        let floor = 1e-6 * wdiag.iter().fold(0.0f64, |x, &y| x.max(y)) + 1e-12;
        let mut in_part = vec![false; self.problem.cons.len()];
        for &r in &part.rows {
            in_part[r] = true;
        }
        let entries = &self.work.jac.entries;
        // The pending body pair and its accumulated `Σ ρ g gᵀ` (column-major, as `LMat`).
        let mut pending: Option<[Option<BodyId>; 2]> = None;
        let mut acc = [0.0f64; NL * NL];
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
            let rho = group.iter().fold(floor, |a, e| a.max(wdiag[e.1]))
                * self.problem.scaling.rows[row].powi(2);
            let mut bodies: [Option<BodyId>; 2] = [None, None];
            let mut local = true;
            for e in group {
                let b = e.1 / 7;
                if bodies.iter().any(|x| x.map(|y| y.0) == Some(b)) {
                    continue;
                }
                match bodies.iter().position(|x| x.is_none()) {
                    Some(slot) => bodies[slot] = Some(BodyId(b)),
                    None => local = false,
                }
            }
            if !local {
                for a in group {
                    for b in group {
                        self.work.hess.add_entry(a.1, b.1, rho * a.2 * b.2);
                    }
                }
                continue;
            }
            let mut g = [0.0f64; NL];
            for e in group {
                let side = usize::from(bodies[0].map(|x| x.0) != Some(e.1 / 7));
                g[7 * side + e.1 % 7] += e.2;
            }
            let same = pending.as_ref().is_some_and(|b| {
                b.iter()
                    .map(|x| x.map(|y| y.0))
                    .eq(bodies.iter().map(|x| x.map(|y| y.0)))
            });
            if !same {
                if let Some(b) = pending.take() {
                    self.work
                        .hess
                        .add_block(&b, &LMat::from_column_slice(&acc), 1.0);
                }
                pending = Some(bodies);
                acc = [0.0; NL * NL];
            }
            // `acc += g gᵀ ρ` in place, entry by entry in the same order of operations
            // (`(g_i g_j) ρ`), over the columns of the row's nonzero entries: a zero `g_i`
            // adds a signed zero, which changes no sum.
            for (j, &gj) in g.iter().enumerate() {
                if gj != 0.0 {
                    let col = &mut acc[NL * j..NL * j + NL];
                    for (a, &gi) in col.iter_mut().zip(&g) {
                        *a += gi * gj * rho;
                    }
                }
            }
        }
        if let Some(b) = pending.take() {
            self.work
                .hess
                .add_block(&b, &LMat::from_column_slice(&acc), 1.0);
        }
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
