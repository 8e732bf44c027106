//! The augmentation of the KKT system's `W` block: `W += Φ_qᵀ D R D Φ_q` over the independent
//! rows (module `kkt`), with `R_k = max(ρ₀, max_{c ∈ row k} D_c² |W_cc|) d_k²` and
//! `ρ₀ = 10⁻⁶ max_c D_c² |W_cc| + 10⁻¹²`, where `c ∈ row k` runs over the coordinates of the
//! bodies the row is on (all 7 of each, its entries that are zero at every `q` included:
//! `joint::Row::pattern`), a normalization row's Euler parameters alone.
//!
//! A row on one or two bodies adds `ρ g gᵀ` to their `14 × 14` pair block (`g` the row's
//! entries in the pair's local order); consecutive rows on the same pair are summed before
//! they reach the block Hessian. A row on more bodies adds entry by entry. Which entries form
//! a row, its bodies and each entry's local index depend on the partition and the triplets'
//! pattern only: they are listed once per partition ([`AugmentPlan`]), and each assembly
//! runs over the values.

use super::System;
use crate::constraints::Constraints;
use crate::constraints::Triplet;
use crate::jet::{HessianSink, LMat, EULER, NL};
use crate::model::BodyId;
use crate::solver::partition::Partition;

/// One independent row's run of triplets.
struct Group {
    start: usize,
    end: usize,
    row: usize,
    /// The row's bodies in order of first appearance; `None` for a row on more than two.
    bodies: Option<[Option<BodyId>; 2]>,
    /// Whether `R_k`'s reach runs over all 7 coordinates of the bodies (every row on one or
    /// two bodies but a normalization), else over the row's entries.
    whole_bodies: bool,
}

/// The rows of the augmentation under one partition and one triplet pattern.
pub(crate) struct AugmentPlan {
    id: usize,
    triplets: usize,
    groups: Vec<Group>,
    /// Each triplet's index in its pair's local order (`7 side + c mod 7`).
    local: Vec<u8>,
}

impl AugmentPlan {
    /// The plan of the triplets `entries` (a row's entries consecutive; on one body, a run of
    /// consecutive entries) under `part`: one pass over the rows, the bodies of a row found
    /// where its column's body changes.
    fn new(part: &Partition, cons: &Constraints, m: usize, entries: &[Triplet]) -> Self {
        let mut in_part = vec![false; m];
        for &r in &part.rows {
            in_part[r] = true;
        }
        let mut groups = Vec::with_capacity(part.rows.len());
        let mut local = vec![0u8; entries.len()];
        let none = u32::MAX;
        let mut k = 0;
        while k < entries.len() {
            let (start, row) = (k, entries[k].0);
            // The row's bodies in order of first appearance (`none`: not yet), and whether
            // there are two at most.
            let (mut first, mut second, mut on_two, mut last) = (none, none, true, none);
            for e in &entries[start..] {
                if e.0 != row {
                    break;
                }
                let b = e.1 / 7;
                if b != last {
                    last = b;
                    if b != first && b != second {
                        if first == none {
                            first = b;
                        } else if second == none {
                            second = b;
                        } else {
                            on_two = false;
                        }
                    }
                }
                k += 1;
            }
            let row = row as usize;
            if !in_part[row] {
                continue;
            }
            if on_two {
                for (l, e) in local[start..k].iter_mut().zip(&entries[start..k]) {
                    let (b, c) = (e.1 / 7, e.1 % 7);
                    *l = (7 * u32::from(b != first) + c) as u8;
                }
            }
            let body = |b: u32| (b != none).then_some(BodyId(b as usize));
            groups.push(Group {
                start,
                end: k,
                row,
                bodies: on_two.then_some([body(first), body(second)]),
                whole_bodies: on_two && !cons.is_normalization(row),
            });
        }
        AugmentPlan {
            id: part.id,
            triplets: entries.len(),
            groups,
            local,
        }
    }

    fn fits(&self, part: &Partition, triplets: usize) -> bool {
        self.id == part.id && self.triplets == triplets
    }
}

impl System<'_> {
    /// Adds `Φ_qᵀ D R D Φ_q` over the independent rows to the block Hessian (module docs).
    pub(super) fn augment(&mut self, part: &Partition) {
        let n = self.problem.model.coordinate_count();
        let columns = &self.problem.scaling.columns;
        let mut wdiag = std::mem::take(&mut self.work.wdiag);
        wdiag.clear();
        wdiag.resize(n, 0.0);
        for (&(a, b), blk) in self.work.hess.keys.iter().zip(&self.work.hess.values) {
            if a == b {
                for i in 0..7 {
                    wdiag[7 * a + i] = blk[8 * i].abs() * columns[7 * a + i].powi(2);
                }
            }
        }
        let mut hess = std::mem::take(&mut self.work.hess);
        self.augment_into(part, wdiag, &mut hess);
        self.work.hess = hess;
    }

    /// Adds `Φ_qᵀ D R D Φ_q` into `sink`, given `W`'s scaled diagonal `D_c² |W_cc|` in
    /// `wdiag` (the block Hessian's, or the fused assembly's: module `tree::fused`).
    pub(super) fn augment_into(
        &mut self,
        part: &Partition,
        wdiag: Vec<f64>,
        sink: &mut dyn HessianSink,
    ) {
        let m = self.problem.cons.len();
        let work = &mut self.work;
        let entries = &work.jac.entries;
        let plan = match work.augment.take() {
            Some(p) if p.fits(part, entries.len()) => p,
            _ => AugmentPlan::new(part, &self.problem.cons, m, entries),
        };
        let floor = 1e-6 * wdiag.iter().fold(0.0f64, |x, &y| x.max(y)) + 1e-12;
        // Each body's largest `D_c² |W_cc|` (a maximum: the same in any order).
        let mut body_max = std::mem::take(&mut work.body_max);
        body_max.clear();
        body_max.extend(
            wdiag
                .chunks_exact(7)
                .map(|w| w.iter().fold(floor, |a, &x| a.max(x))),
        );
        // The pending body pair and its accumulated `Σ ρ g gᵀ` (handed to the sink as it is).
        let mut pending: Option<[Option<BodyId>; 2]> = None;
        let mut acc = LMat::zeros();
        for g in &plan.groups {
            let range = g.start..g.end;
            let group = &entries[range.clone()];
            let row_scale = self.problem.scaling.rows[g.row].powi(2);
            let Some(bodies) = g.bodies else {
                let rho = group.iter().fold(floor, |a, e| a.max(wdiag[e.1 as usize])) * row_scale;
                for a in group {
                    for b in group {
                        sink.add_entry(a.1 as usize, b.1 as usize, rho * a.2 * b.2);
                    }
                }
                continue;
            };
            let mut gv: Local = [0.0; 16];
            let mut reach = floor;
            if g.whole_bodies {
                for b in bodies.iter().flatten() {
                    reach = reach.max(body_max[b.0]);
                }
                for (e, &i) in group.iter().zip(&plan.local[range]) {
                    gv[usize::from(i) & 15] += e.2;
                }
            } else {
                for (e, &i) in group.iter().zip(&plan.local[range]) {
                    reach = reach.max(wdiag[e.1 as usize]);
                    gv[usize::from(i) & 15] += e.2;
                }
            }
            let rho = reach * row_scale;
            if pending != Some(bodies) {
                if let Some(b) = pending.take() {
                    sink.add_symmetric_block(&b, &acc, 1.0);
                }
                pending = Some(bodies);
                acc.as_mut_slice().fill(0.0);
            }
            add_outer(&mut acc, &gv, rho);
        }
        if let Some(b) = pending.take() {
            sink.add_symmetric_block(&b, &acc, 1.0);
        }
        work.augment = Some(plan);
        work.wdiag = wdiag;
        work.body_max = body_max;
    }
}

/// A row's entries in its pair's local order: 14 used, 16 so that a local index masked by
/// 15 needs no bounds check.
type Local = [f64; 16];

/// `acc += g gᵀ ρ`, entry by entry as `(g_i g_j) ρ`, over the columns of `g`'s nonzero
/// entries: a zero `g_i` adds a signed zero, which changes no sum (the sums start at `+0`, so
/// they are never `−0`). A row on the Euler parameters alone (a dot product of two axes, a
/// normalization) therefore adds over their rows only ([`EULER`]: the two runs `3..7`,
/// `10..14`).
///
/// Entries `(i, j)` and `(j, i)` sum the same products `g_i g_j = g_j g_i` in the same order
/// (the signed zeros aside), so the sum is symmetric to the last bit: the sink may read it
/// either way ([`HessianSink::add_symmetric_block`]).
fn add_outer(acc: &mut LMat, g: &Local, rho: f64) {
    let acc = acc.as_mut_slice();
    let g = &g[..NL];
    let euler_only = g[0..3].iter().chain(&g[7..10]).all(|&x| x == 0.0);
    if euler_only {
        for &j in &EULER {
            let gj = g[j];
            if gj != 0.0 {
                for run in [3..7, 10..14] {
                    let col = &mut acc[NL * j + run.start..NL * j + run.end];
                    for (a, &gi) in col.iter_mut().zip(&g[run]) {
                        *a += gi * gj * rho;
                    }
                }
            }
        }
        return;
    }
    for (j, &gj) in g.iter().enumerate() {
        if gj != 0.0 {
            let col = &mut acc[NL * j..NL * j + NL];
            for (a, &gi) in col.iter_mut().zip(g) {
                *a += gi * gj * rho;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::constraints::Constraints;
    use crate::solver::sparse::hessian::BlockHessian;
    use crate::solver::system::{Backend, System};
    use crate::urdf::{load_str, ImportOptions};
    use nalgebra::{DMatrix, DVector};

    fn dense(h: &BlockHessian, n: usize) -> DMatrix<f64> {
        let mut d = DMatrix::zeros(n, n);
        for c in 0..n {
            let mut e = vec![0.0; n];
            e[c] = 1.0;
            let mut y = vec![0.0; n];
            h.mul_add(&e, &mut y);
            d.set_column(c, &DVector::from_vec(y));
        }
        d
    }

    /// The augmentation adds `Σ_k R_k ∇Φ_k ∇Φ_kᵀ` over the independent rows, with `R_k` as the
    /// module says, computed here densely from the triplets (`c ∈ row k`: the coordinates of
    /// the bodies of its triplets); and a second assembly under the
    /// same partition (the plan reused) adds exactly what a fresh plan adds.
    #[test]
    fn augmentation_adds_the_weighted_gram_matrix_of_the_independent_rows() {
        let texts = [
            crate::generate::chain(7, false),
            include_str!("../../../robots/four_bar_spatial.urdf").to_string(),
            crate::generate::ladder(2),
        ];
        for text in &texts {
            let model = load_str(text, "m.urdf", &ImportOptions::default())
                .expect("model loads")
                .model;
            let n = model.coordinate_count();
            let q = crate::solver::initial_state(&model).q;
            let mut sys = System::new(&model, Constraints::new(&model, &[]), Backend::Tree);
            let part = sys.partition(&q);
            let eval = sys.evaluate(&q, &part).expect("evaluates");
            sys.lagrangian_blocks(&q, &part, &eval);
            let before = dense(&sys.work.hess, n);
            sys.augment(&part);
            let after = dense(&sys.work.hess, n);
            // Reference: ρ_k from W's scaled diagonal over the coordinates of the row's bodies
            // (a normalization's entries), the row's gradient from the triplets.
            let cols = &sys.problem.scaling.columns;
            let wdiag: Vec<f64> = (0..n)
                .map(|c| before[(c, c)].abs() * cols[c].powi(2))
                .collect();
            let floor = 1e-6 * wdiag.iter().fold(0.0f64, |a, &b| a.max(b)) + 1e-12;
            let mut expected = before.clone();
            for &r in &part.rows {
                let mut g = DVector::<f64>::zeros(n);
                let mut reach = floor;
                for e in sys.work.jac.entries.iter().filter(|e| e.0 as usize == r) {
                    let c = e.1 as usize;
                    g[c] += e.2;
                    let body = c - c % 7;
                    if sys.problem.cons.is_normalization(r) {
                        reach = reach.max(wdiag[c]);
                    } else {
                        reach = wdiag[body..body + 7].iter().fold(reach, |a, &x| a.max(x));
                    }
                }
                let rho = reach * sys.problem.scaling.rows[r].powi(2);
                expected += &g * g.transpose() * rho;
            }
            let scale = after.amax().max(1.0);
            assert!(
                (&after - &expected).amax() <= 1e-12 * scale,
                "{}",
                (&after - &expected).amax()
            );
            // Again with the plan in place, and with a fresh one.
            sys.lagrangian_blocks(&q, &part, &eval);
            sys.augment(&part);
            let reused = dense(&sys.work.hess, n);
            sys.work.augment = None;
            sys.lagrangian_blocks(&q, &part, &eval);
            sys.augment(&part);
            assert_eq!(reused, dense(&sys.work.hess, n));
            assert_eq!(reused, after);
        }
    }
}
