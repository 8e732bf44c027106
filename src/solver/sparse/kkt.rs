//! The Newton step from the sparse KKT system instead of the dense reduced Hessian.
//!
//! At a feasible `q` with multipliers `μ`, the reduced Newton step `δv = −(Zᵀ W Z)⁻¹ ∇f`
//! (`W = V_qq − Σ μ_k ∇²Φ_k`, `Z = [H; I]` the null-space basis of the partition) is the
//! independent part of the solution of
//!
//! ```text
//! [ W    Φ_qᵀ ] [ δq ]   [ −V_qᵀ ]
//! [ Φ_q  0    ] [ λ  ] = [   0   ]
//! ```
//!
//! over the independent rows of `Φ_q`: the second row gives `δq = Z δv`, and multiplying the
//! first by `Zᵀ` (with `Zᵀ Φ_qᵀ = 0`) gives `Zᵀ W Z δv = −Zᵀ V_qᵀ = −∇f`. The matrix has
//! `O(N)` nonzeros (7 × 7 blocks of `W` per pair of bodies sharing a term, the triplets of
//! `Φ_q`), and a sparse LU with a fill-reducing ordering factors it in about `O(N)` for chains,
//! trees and ladders, where `Zᵀ W Z` itself is dense (every joint of a chain carries all the
//! bodies below it). The system is solved in the scaled coordinates `q̂ = S⁻¹ q` with the rows
//! scaled by `D`, like the partition. A shift `δ I` on the `W` block (`δ ≥ 0`) makes the
//! reduced matrix `Zᵀ (W + δ S⁻²) Z` positive definite away from a minimum.

use super::hessian::BlockHessian;
use super::pattern::{Pattern, NONE};
use crate::solver::partition::Partition;
use faer::linalg::solvers::SolveCore;
use faer::sparse::linalg::solvers::{Lu, SymbolicLu};
use faer::{Conj, MatMut};

/// The KKT matrix's structure under one partition, its values and its factors.
pub(crate) struct Kkt {
    n: usize,
    rows: Vec<usize>,
    triplets: usize,
    blocks: usize,
    pattern: Pattern,
    symbolic: SymbolicLu<usize>,
    block_slots: Vec<[usize; 49]>,
    /// Slots of `(n + p, c)` and `(c, n + p)` for each Jacobian triplet in an independent row.
    jac_slots: Vec<(usize, usize)>,
    diag_slots: Vec<usize>,
    values: Vec<f64>,
    shifted: Vec<f64>,
    lu: Option<Lu<usize, f64>>,
}

impl Kkt {
    /// The structure for partition `part` of an `m × n` Jacobian given by `entries`, and the
    /// blocks of `hess`; `None` if faer's symbolic analysis fails.
    pub(crate) fn new(
        part: &Partition,
        m: usize,
        n: usize,
        entries: &[(usize, usize, f64)],
        hess: &BlockHessian,
    ) -> Option<Self> {
        let mut row_pos = vec![NONE; m];
        for (k, &r) in part.rows.iter().enumerate() {
            row_pos[r] = k;
        }
        let dim = n + part.rows.len();
        let mut positions: Vec<(usize, usize)> = Vec::with_capacity(49 * hess.keys.len());
        for &(a, b) in &hess.keys {
            for i in 0..7 {
                for j in 0..7 {
                    positions.push((7 * a + i, 7 * b + j));
                }
            }
        }
        for e in entries {
            if row_pos[e.0] != NONE {
                positions.push((n + row_pos[e.0], e.1));
                positions.push((e.1, n + row_pos[e.0]));
            }
        }
        positions.extend((0..n).map(|i| (i, i)));
        let pattern = Pattern::new(dim, dim, positions);
        let symbolic = SymbolicLu::try_new(pattern.symbolic()).ok()?;
        let block_slots = hess
            .keys
            .iter()
            .map(|&(a, b)| {
                let mut s = [NONE; 49];
                for i in 0..7 {
                    for j in 0..7 {
                        s[7 * i + j] = pattern.slot(7 * a + i, 7 * b + j);
                    }
                }
                s
            })
            .collect();
        let jac_slots = entries
            .iter()
            .map(|e| match row_pos[e.0] {
                NONE => (NONE, NONE),
                p => (pattern.slot(n + p, e.1), pattern.slot(e.1, n + p)),
            })
            .collect();
        let diag_slots = (0..n).map(|i| pattern.slot(i, i)).collect();
        let nnz = pattern.nnz();
        Some(Kkt {
            n,
            rows: part.rows.clone(),
            triplets: entries.len(),
            blocks: hess.keys.len(),
            pattern,
            symbolic,
            block_slots,
            jac_slots,
            diag_slots,
            values: vec![0.0; nnz],
            shifted: vec![0.0; nnz],
            lu: None,
        })
    }

    /// Whether this structure fits `part`, a Jacobian of `triplets` entries and `blocks` blocks.
    pub(crate) fn fits(&self, part: &Partition, triplets: usize, blocks: usize) -> bool {
        self.triplets == triplets && self.blocks == blocks && self.rows == part.rows
    }

    /// Fills the values (scaled) from the Jacobian triplets and the Hessian blocks.
    pub(crate) fn assemble(
        &mut self,
        entries: &[(usize, usize, f64)],
        row_scale: &[f64],
        scale: &[f64],
        hess: &BlockHessian,
    ) {
        self.values.iter_mut().for_each(|v| *v = 0.0);
        for ((&(a, b), blk), slots) in hess.keys.iter().zip(&hess.values).zip(&self.block_slots) {
            for i in 0..7 {
                for j in 0..7 {
                    self.values[slots[7 * i + j]] +=
                        blk[7 * i + j] * scale[7 * a + i] * scale[7 * b + j];
                }
            }
        }
        for (e, &(s1, s2)) in entries.iter().zip(&self.jac_slots) {
            if s1 != NONE {
                let v = e.2 * row_scale[e.0] * scale[e.1];
                self.values[s1] += v;
                self.values[s2] += v;
            }
        }
    }

    /// The largest diagonal entry of the (scaled) `W` block.
    pub(crate) fn max_diagonal(&self) -> f64 {
        self.diag_slots
            .iter()
            .fold(0.0f64, |a, &s| a.max(self.values[s].abs()))
    }

    /// Factors the matrix with `δ` added to the diagonal of the `W` block.
    pub(crate) fn factor(&mut self, delta: f64) -> bool {
        self.shifted.copy_from_slice(&self.values);
        for &s in &self.diag_slots {
            self.shifted[s] += delta;
        }
        self.lu =
            Lu::try_new_with_symbolic(self.symbolic.clone(), self.pattern.matrix(&self.shifted))
                .ok();
        self.lu.is_some()
    }

    /// Solves with the last factors in place (`rhs` of length `n + rows`), with one step of
    /// iterative refinement (`x += K⁻¹ (b − K x)`, which recovers the digits partial pivoting
    /// loses on the indefinite matrix); `false` if singular.
    pub(crate) fn solve(&self, rhs: &mut [f64]) -> bool {
        let Some(lu) = &self.lu else { return false };
        let len = rhs.len();
        let b = rhs.to_vec();
        lu.solve_in_place_with_conj(Conj::No, MatMut::from_column_major_slice_mut(rhs, len, 1));
        let mut r = b;
        let sym = self.pattern.symbolic();
        let (ptr, idx) = (sym.col_ptr(), sym.row_idx());
        for c in 0..len {
            for k in ptr[c]..ptr[c + 1] {
                r[idx[k]] -= self.shifted[k] * rhs[c];
            }
        }
        lu.solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(&mut r, len, 1),
        );
        for (x, d) in rhs.iter_mut().zip(&r) {
            *x += d;
        }
        rhs.iter().all(|x| x.is_finite())
    }

    /// Number of constraint rows.
    pub(crate) fn rows(&self) -> usize {
        self.rows.len()
    }

    /// Number of coordinates `n`.
    pub(crate) fn coordinates(&self) -> usize {
        self.n
    }
}
