//! The model's rows and the energy evaluated once for the balance check and the forces.
//!
//! The balance check (module `reduced`) evaluates `Φ` and the triplets of `Φ_q` of the model's
//! rows `Constraints::new(model, locks)` at the pose. The locked system of module `held` is
//! `Constraints::new(model, all)` with `all = locks ++ joint locks`: its blocks are the same
//! joint, normalization and lock blocks at the same rows, followed by the joint locks' (and,
//! without mimics, nothing in between). Rows are evaluated block by block, each from the pose
//! alone, so the locked system's values and triplets are the balance check's followed by those
//! of its last blocks: only those are evaluated again ([`ModelRows::install`]), and every
//! number is the one a full evaluation gives (the same operations on the same inputs, in the
//! same order; the triplets in the same order). The energy `V` and its gradient `∇V`, which
//! depend on the pose alone, are the finiteness guard's (module `reduced`), taken by the
//! locked system's evaluation instead of evaluating them again.

use crate::constraints::{Constraints, Triplets};
use crate::forces::Energy;
use crate::solver::system::System;
use nalgebra::DVector;

/// A block's kind and first row.
type BlockShape = (std::mem::Discriminant<crate::constraints::BlockKind>, usize);

/// The balance check's evaluated rows, with room for the rows to be added.
pub(super) struct ModelRows {
    jac: Triplets,
    phi: DVector<f64>,
    /// The kind and first row of each block of the balance check's constraints.
    shapes: Vec<BlockShape>,
    /// The configuration the rows were evaluated at.
    at: DVector<f64>,
    /// `V` and `∇V` at `at` on the same branches (the guard's).
    potential: (Energy, DVector<f64>),
}

impl ModelRows {
    /// The rows `sys` last evaluated at `q`, taken from it (`None` if it has not evaluated
    /// them there, or with mimics, whose rows follow the locks), with room in the triplets
    /// for `extra` more rows on two bodies (in place where module `reduced` reserved it), and
    /// `V` and `∇V` at `q` on the branches of `sys` (`potential`).
    pub(super) fn take(
        sys: &mut System,
        q: &DVector<f64>,
        extra: usize,
        potential: (Energy, DVector<f64>),
    ) -> Option<Self> {
        let w = &mut sys.work;
        if !w.jac_fresh || w.jac_at != *q || !sys.problem.model.mimics.is_empty() {
            return None;
        }
        w.jac_fresh = false;
        let mut entries = std::mem::take(&mut w.jac.entries);
        entries.reserve_exact(crate::jet::NL * extra);
        Some(ModelRows {
            jac: Triplets {
                rows: w.jac.rows,
                cols: w.jac.cols,
                entries,
            },
            phi: w.phi.clone(),
            shapes: sys
                .problem
                .cons
                .blocks
                .iter()
                .map(|b| (std::mem::discriminant(&b.kind), b.first))
                .collect(),
            at: q.clone(),
            potential,
        })
    }

    /// The triplets of the rows' `Φ_q` and `∇V`, where they were evaluated at `q`.
    pub(super) fn at(
        &self,
        q: &DVector<f64>,
    ) -> Option<(&[crate::constraints::Triplet], &DVector<f64>)> {
        (self.at == *q).then_some((&self.jac.entries[..], &self.potential.1))
    }

    /// Whether `cons` at `q` starts with the blocks these rows were evaluated for: the same
    /// kinds at the same rows, its next block (if any) where they end, at the same pose.
    fn fits(&self, cons: &Constraints, q: &DVector<f64>) -> bool {
        let k = self.shapes.len();
        cons.blocks.len() >= k
            && self.at == *q
            && cons.blocks[..k]
                .iter()
                .zip(&self.shapes)
                .all(|(b, s)| std::mem::discriminant(&b.kind) == s.0 && b.first == s.1)
            && cons.blocks.get(k).map_or(cons.len(), |b| b.first) == self.phi.len()
    }

    /// Puts the rows of `sys` at `q` into its workspace, as `System::triplets` would: these
    /// rows, then the evaluation of its blocks after them; returns `V` and `∇V` at `q`, for
    /// `System::evaluate_knowing` (a system on the same branches). Evaluates them all where
    /// `sys` does not start with these rows' blocks (and returns `None`).
    pub(super) fn install(
        self,
        sys: &mut System,
        q: &DVector<f64>,
    ) -> Option<(Energy, DVector<f64>)> {
        if !self.fits(&sys.problem.cons, q) {
            sys.triplets(q);
            return None;
        }
        let model = sys.problem.model;
        let mut tail = sys.problem.cons.clone();
        tail.blocks.drain(..self.shapes.len());
        let mut phi = DVector::zeros(tail.len());
        let mut added = Triplets::default();
        tail.evaluate(model, q, &mut phi, Some(&mut added));
        let m0 = self.phi.len();
        phi.rows_mut(0, m0).copy_from(&self.phi);
        let mut entries = self.jac.entries;
        entries.extend_from_slice(&added.entries);
        let w = &mut sys.work;
        w.jac = Triplets {
            rows: added.rows,
            cols: added.cols,
            entries,
        };
        w.phi = phi;
        w.jac_at = self.at;
        w.jac_fresh = true;
        Some(self.potential)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::constraints::BlockKind;
    use crate::solver::system::Backend;

    /// The locked system's rows installed from the balance check's equal those it evaluates
    /// itself, bit for bit and triplet for triplet: on a chain, a chain with a lock of its
    /// own and a ladder (loops), fixed and floating, at a bent pose; rows of a system whose
    /// blocks differ are not used (the system evaluates its own); with mimics there is
    /// nothing to take.
    #[test]
    fn installed_rows_are_the_evaluated_ones() {
        let chain = crate::generate::chain(12, false);
        let locked = chain.replace(
            "</robot>",
            "<mech:lock joint=\"joint3\" value=\"0.2\"/></robot>",
        );
        for text in [chain, locked, crate::generate::ladder(4)] {
            for floating in [false, true] {
                let options = crate::urdf::ImportOptions {
                    floating_base: floating,
                    ..Default::default()
                };
                let model = crate::urdf::load_str(&text, "t.urdf", &options)
                    .unwrap()
                    .model;
                let mut state = crate::state::State::initial(&model);
                for (k, x) in state.q.iter_mut().enumerate() {
                    *x += 1e-2 * ((k * 37 % 11) as f64 - 5.0);
                }
                let locks = crate::solver::lock_values(&model);
                let coords = super::super::run::tree_coordinates(&model, &state);
                let mut all = locks.clone();
                all.extend(coords.iter().copied());
                let system = |rows: &[_]| {
                    System::new(&model, Constraints::new(&model, rows), Backend::Sparse)
                };
                let mut g = DVector::zeros(state.q.len());
                let energy =
                    crate::forces::potential(&model, &state.branches, &state.q, &mut g, None)
                        .unwrap();
                let mut balance = system(&locks);
                balance.triplets(&state.q);
                let rows =
                    ModelRows::take(&mut balance, &state.q, coords.len(), (energy, g.clone()))
                        .unwrap();
                let mut own = system(&all);
                own.triplets(&state.q);
                let mut installed = system(&all);
                let known = rows.install(&mut installed, &state.q);
                assert!(installed.work.jac_fresh);
                // The evaluation with the given `V`, `∇V` is the one that evaluates them.
                let part = own.partition(&state.q);
                let evaluated = own.evaluate(&state.q, &part).unwrap();
                let given = installed.evaluate_knowing(&state.q, &part, known).unwrap();
                assert_eq!(evaluated.energy, given.energy, "{}", model.name);
                assert_eq!(evaluated.mu, given.mu, "{}", model.name);
                assert_eq!(evaluated.grad_v, given.grad_v, "{}", model.name);
                assert_eq!(evaluated.merit, given.merit, "{}", model.name);
                assert_eq!(own.work.jac.entries, installed.work.jac.entries);
                assert_eq!(own.work.jac.rows, installed.work.jac.rows);
                assert_eq!(own.work.phi, installed.work.phi, "{}", model.name);
                assert!(own
                    .problem
                    .cons
                    .blocks
                    .iter()
                    .any(|b| matches!(b.kind, BlockKind::Lock { .. })));
                // The locked system's rows do not start the balance check's: not used.
                let mut locked = system(&all);
                locked.triplets(&state.q);
                let rows = ModelRows::take(&mut locked, &state.q, 0, (energy, g)).unwrap();
                let mut other = system(&locks);
                assert!(rows.install(&mut other, &state.q).is_none());
                let mut fresh = system(&locks);
                fresh.triplets(&state.q);
                assert_eq!(other.work.jac.entries, fresh.work.jac.entries);
                assert_eq!(other.work.phi, fresh.work.phi);
            }
        }
        let model = crate::urdf::load_str(
            include_str!("../../robots/panda_class.urdf"),
            "panda_class.urdf",
            &Default::default(),
        )
        .unwrap()
        .model;
        assert!(!model.mimics.is_empty());
        let state = crate::state::State::initial(&model);
        let mut sys = System::new(
            &model,
            Constraints::new(&model, &crate::solver::lock_values(&model)),
            Backend::Sparse,
        );
        sys.triplets(&state.q);
        let potential = (Default::default(), DVector::zeros(state.q.len()));
        assert!(ModelRows::take(&mut sys, &state.q, 0, potential).is_none());
    }
}
