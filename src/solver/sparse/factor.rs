//! Sparse `Φ_u` and `Φ_v` under a partition, and the sparse LU of `Φ_u`.
//!
//! The positions of the Jacobian's triplets do not depend on `q`, so the split of the triplets
//! into `Φ_u` (independent rows × dependent columns, compressed-column for faer) and `Φ_v`
//! (independent rows × independent columns, a list of entries) is computed once per partition,
//! together with faer's symbolic LU analysis (COLAMD ordering, elimination structure); each
//! evaluation only refills the values and refactors numerically.

use super::pattern::{Ix, Pattern, NONE};
use crate::constraints::Triplet;
use crate::solver::partition::Partition;
use faer::linalg::solvers::SolveCore;
use faer::sparse::linalg::solvers::{Lu, SymbolicLu};
use faer::{Conj, MatMut};

/// Where each Jacobian triplet goes under one partition.
pub(crate) struct Split {
    /// Id of the partition.
    id: usize,
    /// Number of independent rows (the order of `Φ_u`).
    rows: usize,
    /// Number of triplets the maps were built for.
    triplets: usize,
    pattern: Pattern,
    symbolic: SymbolicLu<Ix>,
    /// Slot in `Φ_u` of each triplet, or `NONE`.
    u_slot: Vec<Ix>,
    /// `(row position, independent position, triplet index)` of the `Φ_v` entries.
    v_entries: Vec<(usize, usize, usize)>,
    values: Vec<f64>,
}

/// The numeric factors of `Φ_u` and the values of `Φ_v` at one configuration.
#[derive(Clone)]
pub(crate) struct SparseFactors {
    lu: Option<Lu<Ix, f64>>,
    /// `(row position, independent position, value)`.
    phi_v: Vec<Triplet>,
}

impl Split {
    /// The split of the triplets `entries` under `part`; `None` if faer's symbolic analysis
    /// fails (out of memory).
    pub(crate) fn new(part: &Partition, m: usize, n: usize, entries: &[Triplet]) -> Option<Self> {
        let mut row_pos = vec![NONE; m];
        for (k, &r) in part.rows.iter().enumerate() {
            row_pos[r] = k;
        }
        let mut dep_pos = vec![NONE; n];
        for (k, &c) in part.dependent.iter().enumerate() {
            dep_pos[c] = k;
        }
        let mut ind_pos = vec![NONE; n];
        for (k, &c) in part.independent.iter().enumerate() {
            ind_pos[c] = k;
        }
        let r = part.rows.len();
        let positions: Vec<(usize, usize)> = entries
            .iter()
            .filter(|e| row_pos[e.0 as usize] != NONE && dep_pos[e.1 as usize] != NONE)
            .map(|e| (row_pos[e.0 as usize], dep_pos[e.1 as usize]))
            .collect();
        let pattern = Pattern::new(r, r, positions);
        let symbolic = SymbolicLu::try_new(pattern.symbolic()).ok()?;
        let mut u_slot = vec![Ix::MAX; entries.len()];
        let mut v_entries = Vec::new();
        for (k, e) in entries.iter().enumerate() {
            let rp = row_pos[e.0 as usize];
            if rp == NONE {
                continue;
            }
            if dep_pos[e.1 as usize] != NONE {
                u_slot[k] = pattern.slot(rp, dep_pos[e.1 as usize]) as Ix;
            } else if ind_pos[e.1 as usize] != NONE {
                v_entries.push((rp, ind_pos[e.1 as usize], k));
            }
        }
        let values = vec![0.0; pattern.nnz()];
        Some(Split {
            id: part.id,
            rows: part.rows.len(),
            triplets: entries.len(),
            pattern,
            symbolic,
            u_slot,
            v_entries,
            values,
        })
    }

    /// Whether this split was built for `part` and a Jacobian of `triplets` entries.
    pub(crate) fn fits(&self, part: &Partition, triplets: usize) -> bool {
        self.triplets == triplets && self.id == part.id
    }

    /// Refills `Φ_u` from `entries` and factors it; `Φ_v` is copied.
    pub(crate) fn factor(&mut self, entries: &[Triplet]) -> SparseFactors {
        self.values.iter_mut().for_each(|v| *v = 0.0);
        for (k, e) in entries.iter().enumerate() {
            let s = self.u_slot[k];
            if s != Ix::MAX {
                self.values[s as usize] += e.2;
            }
        }
        let lu = if self.rows == 0 {
            None
        } else {
            Lu::try_new_with_symbolic(self.symbolic.clone(), self.pattern.matrix(&self.values)).ok()
        };
        SparseFactors {
            lu,
            phi_v: self
                .v_entries
                .iter()
                .map(|&(r, c, k)| (r as u32, c as u32, entries[k].2))
                .collect(),
        }
    }
}

impl SparseFactors {
    fn solve_with(&self, b: &mut [f64], transpose: bool) -> bool {
        if b.is_empty() {
            return true;
        }
        let Some(lu) = &self.lu else { return false };
        let n = b.len();
        let m = MatMut::from_column_major_slice_mut(b, n, 1);
        if transpose {
            lu.solve_transpose_in_place_with_conj(Conj::No, m);
        } else {
            lu.solve_in_place_with_conj(Conj::No, m);
        }
        b.iter().all(|x| x.is_finite())
    }

    /// `Φ_u x = b` in place; `false` if `Φ_u` is singular.
    pub(crate) fn solve(&self, b: &mut [f64]) -> bool {
        self.solve_with(b, false)
    }

    /// `Φ_uᵀ x = b` in place; `false` if `Φ_u` is singular.
    pub(crate) fn solve_transpose(&self, b: &mut [f64]) -> bool {
        self.solve_with(b, true)
    }

    /// `Φ_v x` (length: independent rows).
    pub(crate) fn phi_v_mul(&self, x: &[f64], r: usize) -> Vec<f64> {
        triplets_mul(&self.phi_v, x, r)
    }

    /// `Φ_vᵀ y` (length: degrees of freedom).
    pub(crate) fn phi_v_tr_mul(&self, y: &[f64], dof: usize) -> Vec<f64> {
        triplets_tr_mul(&self.phi_v, y, dof)
    }
}

/// `A x` for `A` given by its `(row, column, value)` triplets, `rows` long (`Φ_v x` of the
/// sparse and the tree factors).
pub(crate) fn triplets_mul(a: &[Triplet], x: &[f64], rows: usize) -> Vec<f64> {
    let mut y = vec![0.0; rows];
    for &(i, j, v) in a {
        y[i as usize] += v * x[j as usize];
    }
    y
}

/// `Aᵀ y` for `A` given by its `(row, column, value)` triplets, `columns` long.
pub(crate) fn triplets_tr_mul(a: &[Triplet], y: &[f64], columns: usize) -> Vec<f64> {
    let mut x = vec![0.0; columns];
    for &(i, j, v) in a {
        x[j as usize] += v * y[i as usize];
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The partition of an `r × (r + 1)` Jacobian: rows and the first `r` columns dependent.
    fn partition(r: usize) -> Partition {
        Partition {
            id: crate::solver::partition::next_id(),
            dependent: (0..r).collect(),
            independent: vec![r],
            rows: (0..r).collect(),
            redundant: vec![],
            second_pass: vec![],
        }
    }

    /// `Φ_u x = b` and `Φ_uᵀ x = b` by faer's sparse LU, or `None` where refused.
    fn solves(r: usize, entries: &[Triplet]) -> (Option<Vec<f64>>, Option<Vec<f64>>) {
        let mut split = Split::new(&partition(r), r, r + 1, entries).unwrap();
        let f = split.factor(entries);
        let b: Vec<f64> = (0..r).map(|i| 1.0 + i as f64).collect();
        let (mut x, mut y) = (b.clone(), b);
        (
            f.solve(&mut x).then_some(x),
            f.solve_transpose(&mut y).then_some(y),
        )
    }

    /// faer's sparse LU on an exactly singular `Φ_u` (two equal rows; a structural entry of
    /// value zero; a chain's bidiagonal with a zero pivot in the middle, simplicial; a dense
    /// block of rank one, super-nodal) gives non-finite values, which the solves refuse: no
    /// finite wrong answer and no panic (sarah-quinones/faer-rs#232). Nonsingular ones with
    /// entries of 10⁻¹⁸ beside 1 are solved to rounding.
    #[test]
    fn singular_phi_u_is_refused_and_badly_scaled_solved() {
        let chain = |n: usize, zero: Option<usize>| {
            let mut e = vec![];
            for i in 0..n {
                let d = if Some(i) == zero { 0.0 } else { 1.0 };
                e.push((i as u32, i as u32, d));
                if i > 0 {
                    e.push((i as u32, i as u32 - 1, 0.5));
                }
                e.push((i as u32, n as u32, 1.0));
            }
            e
        };
        let rank_one = |n: usize| {
            let mut e = vec![];
            for i in 0..n {
                for j in 0..n {
                    e.push((i as u32, j as u32, (i as f64 + 1.0) * (j as f64 + 1.0)));
                }
            }
            e
        };
        let singular: Vec<(usize, Vec<Triplet>)> = vec![
            (2, vec![(0, 0, 1.0), (0, 1, 2.0), (1, 0, 1.0), (1, 1, 2.0)]),
            (3, vec![(0, 0, 1.0), (1, 1, 1.0), (2, 2, 0.0), (0, 2, 0.0)]),
            (200, chain(200, Some(100))),
            (300, rank_one(300)),
        ];
        for (r, e) in &singular {
            let (x, y) = solves(*r, e);
            assert!(x.is_none() && y.is_none(), "r = {r}: {x:?} {y:?}");
        }
        let scaled: Vec<(usize, Vec<Triplet>)> = vec![
            (
                2,
                vec![(0, 0, 1.0), (0, 1, 1e-18), (1, 0, 1e-18), (1, 1, 1e-18)],
            ),
            (200, chain(200, None)),
        ];
        for (r, e) in &scaled {
            let (x, y) = solves(*r, e);
            let (x, y) = (x.unwrap(), y.unwrap());
            let u: Vec<Triplet> = e.iter().copied().filter(|t| (t.1 as usize) < *r).collect();
            let ax = triplets_mul(&u, &x, *r);
            let aty = triplets_tr_mul(&u, &y, *r);
            for i in 0..*r {
                let b = 1.0 + i as f64;
                assert!((ax[i] - b).abs() <= 1e-12 * b, "r = {r}: {} vs {b}", ax[i]);
                assert!(
                    (aty[i] - b).abs() <= 1e-12 * b,
                    "r = {r}: {} vs {b}",
                    aty[i]
                );
            }
        }
    }
}
