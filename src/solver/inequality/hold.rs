//! Frictionless contacts held on the ground along a step (the projected search of the
//! contacts). A trial point `q(α)` of the line search that pushes inactive frictionless
//! contacts `H = {k : g_k(q(α)) < 0}` into their grounds is projected onto them, `g_k = 0` for
//! `k ∈ H`, together with the joints and the active rows (`assemble::project`: Newton on the
//! dependent coordinates of a fresh partition, the others held): each contact the step reached
//! stays on its ground while the rest of the step is taken. Contacts that the projection in turn
//! pushes into a ground join `H`, and the projection is repeated. The point is accepted by
//! Armijo's test on the change of the scaled independent coordinates actually made (the
//! projected Armijo rule, as for the stops: module `bend`), and every contact of `H` and every
//! inactive one touching there joins the active set at once. Where the test fails the step is
//! cut at the first boundary as before (module `guard`).
//!
//! Only frictionless contacts are held so (a sticking contact is anchored where it lands, and
//! where it lands is the path's: the guard cuts the step there); a trial that violates a stop,
//! a sticking contact, a roll limit or an obstacle's plane is left to the guard.

use super::active_set::Guard;
use crate::constraints::unilateral::{Active, Unilateral};
use crate::solver::options::Options;
use crate::solver::system::System;
use nalgebra::DVector;

/// Projections of one trial point before it is left to the guard's cut.
const MAX_PROJECTIONS: usize = 4;

impl Guard<'_> {
    /// The trial point `qt` with every inactive contact it pushes into its ground held on it
    /// (module docs), and the inequalities at their boundary there; `None` when the guard
    /// does not hold contacts so or the projection fails.
    pub(crate) fn hold(
        &self,
        sys: &System,
        qt: &DVector<f64>,
        options: &Options,
    ) -> Option<(DVector<f64>, Vec<usize>)> {
        let held = self.held.as_ref()?;
        let mut branches = sys.problem.cons.branches.clone();
        let mut q = qt.clone();
        let mut hit: Vec<usize> = Vec::new();
        for _ in 0..MAX_PROJECTIONS {
            let violated: Vec<usize> = (0..self.len())
                .filter(|&k| self.gap(k, &q, &branches) < -self.tol)
                .collect();
            if violated.is_empty() {
                break;
            }
            for &k in &violated {
                if !self.holdable(k) {
                    return None;
                }
                if !hit.contains(&k) {
                    hit.push(k);
                }
            }
            let mut rows: Vec<Active> = held.active.clone();
            for &k in &hit {
                let a = super::patch::activate(self.model, options, &rows, self.inactive[k], &q);
                rows.push(a);
            }
            q = crate::solver::assemble::project(
                self.model,
                q,
                &mut branches,
                &held.locks,
                &rows,
                options,
            )
            .ok()?;
        }
        if (0..self.len()).any(|k| self.gap(k, &q, &branches) < -self.tol) {
            return None;
        }
        hit.sort_unstable();
        Some((q, hit))
    }

    /// Whether guarded inequality `k` is a frictionless contact on a ground plane.
    fn holdable(&self, k: usize) -> bool {
        match self.inactive.get(k) {
            Some(Unilateral::Contact { ground, .. }) => *ground < self.model.grounds.len(),
            _ => false,
        }
    }
}

/// What [`Guard::hold`] projects with: the round's active rows and locks.
pub(crate) struct Held {
    pub(crate) active: Vec<Active>,
    pub(crate) locks: Vec<(crate::model::JointId, usize, f64)>,
}
