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
//! `Φ_q`), and LDLᵀ in the partition's elimination order (LU with partial pivoting as the
//! fallback) factors it in about `O(N)` for chains, trees and ladders, where `Zᵀ W Z` itself is
//! dense (every joint of a chain carries all the
//! bodies below it). The system is solved in the scaled coordinates `q̂ = S⁻¹ q` with the rows
//! scaled by `D`, like the partition. A shift `δ I` on the `W` block (`δ ≥ 0`) makes the
//! reduced matrix `Zᵀ (W + δ S⁻²) Z` positive definite away from a minimum.
//!
//! A second shift `−σ` on the independent coordinates alone ([`Kkt::shift_independent`],
//! `E_v` their selector) gives `Zᵀ (Ŵ − σ E_v) Z = Ĥ − σ I`, since `Z`'s independent block is
//! the identity: by Sylvester's law of inertia (Haynsworth's inertia additivity over the
//! constraint block) the LDLᵀ then has `rows + #{λ(Ĥ) < σ}` negative pivots, an exact count
//! of the reduced Hessian's eigenvalues below `σ` (module `solver::stability::inertia`).

use super::hessian::BlockHessian;
use super::pattern::{Ix, Pattern, NONE};
use super::shifts::Shifts;
use crate::constraints::Triplet;
use crate::solver::partition::Partition;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::ldlt::factor::LdltRegularization;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, simplicial, CholeskySymbolicParams, SymbolicCholesky,
    SymbolicCholeskyRaw, SymmetricOrdering,
};
use faer::sparse::linalg::solvers::{Lu, SymbolicLu};
use faer::sparse::linalg::SupernodalThreshold;
use faer::{Par, Side};
use refine::SolveScratch;
use std::cell::RefCell;

mod refine;

/// The KKT matrix's structure under one partition, its values and its factors.
///
/// The matrix is stored permuted into the elimination order (see [`elimination_order`]) and as
/// its upper triangle only: faer's LDLᵀ then factors the stored values as they are (no
/// permuted copy per factorization, half the memory of the full pattern).
pub(crate) struct Kkt {
    n: usize,
    /// Id of the partition.
    id: usize,
    /// Number of independent (multiplier) rows.
    rows: usize,
    triplets: usize,
    blocks: usize,
    /// Upper triangle of the permuted matrix.
    pattern: Pattern,
    /// `perm[k]`: the original index of permuted position `k`.
    perm: Vec<usize>,
    /// Slot of each entry of each block of `W` (`Ix::MAX`: in the lower triangle, whose
    /// mirror entry of the transposed block holds it).
    block_slots: Vec<[Ix; 49]>,
    /// Slot of `(n + p, c)` (or of its mirror) for each Jacobian triplet in an independent row.
    jac_slots: Vec<Ix>,
    diag_slots: Vec<usize>,
    values: Vec<f64>,
    /// The shifts `δ` and `−σ` now in `values` (see [`Kkt::shift_independent`]).
    shifts: Shifts,
    /// `‖K‖∞` of the factored matrix (for the backward error of solves).
    knorm: f64,
    /// The full (both triangles) permuted matrix for the LU fallback, built on its first use:
    /// its pattern, its values, the two full slots of each upper slot, faer's symbolic LU.
    full: Option<Full>,
    lu: Option<Lu<Ix, f64>>,
    /// Symmetric LDLᵀ in the elimination order of the partition (see [`Kkt::factor`]).
    ldlt: Option<SymbolicCholesky<Ix>>,
    ldlt_values: Vec<f64>,
    /// Which factors hold: LDLᵀ or LU.
    kind: Factored,
    /// LDLᵀ solves were not accurate on this structure: LU from now on.
    lu_only: bool,
    /// faer's scratch for the numeric LDLᵀ, allocated once per structure.
    factor_scratch: Option<MemBuffer>,
    /// Row sums of `|K|` (scratch of [`Kkt::factor`]).
    row_sums: Vec<f64>,
    /// Scratch of the solves (faer's stack, right side, residual), allocated once.
    solve_scratch: RefCell<SolveScratch>,
}

/// The full matrix of the LU fallback.
struct Full {
    pattern: Pattern,
    values: Vec<f64>,
    /// Full slots `(r, c)` and `(c, r)` of each upper slot.
    slots: Vec<(Ix, Ix)>,
    symbolic: Option<SymbolicLu<Ix>>,
}

/// What the last [`Kkt::factor`] produced.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Factored {
    /// Nothing usable (singular).
    None,
    /// LDLᵀ without pivoting, with the number of negative pivots.
    Ldlt { negative: usize },
    /// LU with partial pivoting (the fallback).
    Lu,
}

/// The KKT ordering: the partition's bodies in elimination order (leaves first), each body's
/// seven coordinates followed by the rows pivoted in its columns; then the coordinates of
/// bodies without pivots.
fn elimination_order(part: &Partition, n: usize) -> Vec<usize> {
    let mut seen = vec![false; n / 7];
    let mut order = Vec::with_capacity(n + part.rows.len());
    for (k, &c) in part.dependent.iter().enumerate() {
        let b = c / 7;
        if !seen[b] {
            seen[b] = true;
            order.extend(7 * b..7 * b + 7);
        }
        order.push(n + k);
    }
    for b in 0..n / 7 {
        if !seen[b] {
            order.extend(7 * b..7 * b + 7);
        }
    }
    order
}

impl Kkt {
    /// The structure for partition `part` of an `m × n` Jacobian given by `entries`, and the
    /// blocks of `hess`; `None` if faer's symbolic analysis fails.
    pub(crate) fn new(
        part: &Partition,
        m: usize,
        n: usize,
        entries: &[Triplet],
        hess: &BlockHessian,
    ) -> Option<Self> {
        let mut row_pos = vec![NONE; m];
        for (k, &r) in part.rows.iter().enumerate() {
            row_pos[r] = k;
        }
        let dim = n + part.rows.len();
        let perm = elimination_order(part, n);
        let mut inv = vec![0usize; dim];
        for (k, &o) in perm.iter().enumerate() {
            inv[o] = k;
        }
        // Position (i, j) of the original matrix in the stored upper triangle.
        let upper = |i: usize, j: usize| {
            let (a, b) = (inv[i], inv[j]);
            (a.min(b), a.max(b))
        };
        // Each body's seven coordinates are consecutive in the elimination order, so the block
        // of bodies `a`, `b` is the dense 7 × 7 block at `(inv[7a], inv[7b])`: in the stored
        // upper triangle when `inv[7a] < inv[7b]`, mirrored (filled by the transposed block
        // `(b, a)`) when above, its upper triangle when `a = b`.
        assert!(
            (0..n).all(|c| inv[c] == inv[c - c % 7] + c % 7),
            "elimination order keeps each body's coordinates together"
        );
        // The (row, column) ranges a block fills: column `bb + j`, rows `ba .. ba + rows(j)`.
        let filled = |a: usize, b: usize| {
            let (ba, bb) = (inv[7 * a], inv[7 * b]);
            let rows = move |j: usize| match (ba < bb, a == b) {
                (_, true) => j + 1,
                (true, false) => 7,
                (false, false) => 0,
            };
            (ba, bb, rows)
        };
        let blocks = hess.keys.iter().flat_map(|&(a, b)| {
            let (ba, bb, rows) = filled(a, b);
            (0..7).flat_map(move |j| (0..rows(j)).map(move |i| (ba + i, bb + j)))
        });
        let jacobian = entries
            .iter()
            .filter(|e| row_pos[e.0 as usize] != NONE)
            .map(|e| upper(n + row_pos[e.0 as usize], e.1 as usize));
        let pattern = Pattern::with_capacity(
            dim,
            dim,
            28 * hess.keys.len() + entries.len() + n,
            blocks.chain(jacobian).chain((0..n).map(|i| upper(i, i))),
        );
        // The rows of a filled column range are consecutive, hence so are their slots.
        let block_slots = hess
            .keys
            .iter()
            .map(|&(a, b)| {
                let mut s = [Ix::MAX; 49];
                let (ba, bb, rows) = filled(a, b);
                for j in 0..7 {
                    if rows(j) > 0 {
                        // Every block position is in the pattern (it was built from them).
                        let first = pattern.slot(ba, bb + j) as Ix;
                        for i in 0..rows(j) {
                            s[7 * i + j] = first + i as Ix;
                        }
                    }
                }
                s
            })
            .collect();
        let jac_slots = entries
            .iter()
            .map(|e| match row_pos[e.0 as usize] {
                NONE => Ix::MAX,
                p => {
                    let (a, b) = upper(n + p, e.1 as usize);
                    pattern.slot(a, b) as Ix
                }
            })
            .collect();
        let diag_slots = (0..n).map(|i| pattern.slot(inv[i], inv[i])).collect();
        let nnz = pattern.nnz();
        let ldlt = factorize_symbolic_cholesky(
            pattern.symbolic(),
            Side::Upper,
            SymmetricOrdering::Identity,
            CholeskySymbolicParams {
                supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SIMPLICIAL,
                ..Default::default()
            },
        )
        .ok();
        let ldlt_values = vec![0.0; ldlt.as_ref().map_or(0, |l| l.len_val())];
        let factor_scratch =
            MemBuffer::try_new(simplicial::factorize_simplicial_numeric_ldlt_scratch::<
                Ix,
                f64,
            >(dim))
            .ok();
        let solve_scratch = RefCell::new(SolveScratch {
            stack: ldlt.as_ref().and_then(|sym| {
                MemBuffer::try_new(sym.solve_in_place_scratch::<f64>(1, Par::Seq)).ok()
            }),
            x: Vec::with_capacity(dim),
            b: Vec::with_capacity(dim),
            r: Vec::with_capacity(dim),
        });
        Some(Kkt {
            n,
            id: part.id,
            rows: part.rows.len(),
            triplets: entries.len(),
            blocks: hess.keys.len(),
            pattern,
            perm,
            block_slots,
            jac_slots,
            diag_slots,
            values: vec![0.0; nnz],
            shifts: Shifts::default(),
            knorm: 0.0,
            full: None,
            lu: None,
            ldlt,
            ldlt_values,
            kind: Factored::None,
            lu_only: false,
            factor_scratch,
            row_sums: vec![0.0; dim],
            solve_scratch,
        })
    }

    /// Whether this structure fits `part`, a Jacobian of `triplets` entries and `blocks` blocks.
    pub(crate) fn fits(&self, part: &Partition, triplets: usize, blocks: usize) -> bool {
        self.triplets == triplets && self.blocks == blocks && self.id == part.id
    }

    /// Fills the values (scaled) from the Jacobian triplets and the Hessian blocks.
    pub(crate) fn assemble(
        &mut self,
        entries: &[Triplet],
        row_scale: &[f64],
        scale: &[f64],
        hess: &BlockHessian,
    ) {
        self.values.iter_mut().for_each(|v| *v = 0.0);
        self.shifts.clear();
        hess.scatter_scaled(&self.block_slots, scale, &mut self.values);
        for (e, &slot) in entries.iter().zip(&self.jac_slots) {
            if slot != Ix::MAX {
                self.values[slot as usize] += e.2 * row_scale[e.0 as usize] * scale[e.1 as usize];
            }
        }
    }

    /// The largest diagonal entry of the (scaled) `W` block.
    pub(crate) fn max_diagonal(&self) -> f64 {
        self.shifts.max_diagonal(&self.diag_slots, &self.values)
    }

    /// Subtracts `σ` from the diagonal of the (scaled) `W` block at the coordinates `columns`
    /// (the partition's independent ones), in place of the last such shift, for the next
    /// [`Kkt::factor`]: the reduced matrix becomes `Ĥ − σ I` (module doc), so the LDLᵀ's
    /// negative pivots minus `rows` count the eigenvalues of `Ĥ` below `σ`. Cleared by
    /// [`Kkt::assemble`].
    pub(crate) fn shift_independent(&mut self, columns: &[usize], sigma: f64) {
        self.shifts
            .shift_independent(&self.diag_slots, &mut self.values, columns, sigma);
    }

    /// Factors the matrix with `δ` added to the diagonal of the `W` block: LDLᵀ without
    /// pivoting in the partition's elimination order (each body's coordinates, then the rows
    /// pivoted at it: the articulated-body order of a tree, `O(N)` fill), whose negative pivots
    /// count the negative eigenvalues of the KKT matrix (Sylvester's law of inertia: exactly
    /// `rows` negative pivots if and only if the reduced Hessian is positive definite); if a
    /// pivot is zero or not finite, LU with partial pivoting instead.
    pub(crate) fn factor(&mut self, delta: f64) -> Factored {
        // The shift in place (no copy of the values): add the change since the last one.
        self.shifts
            .shift_all(&self.diag_slots, &mut self.values, delta);
        // ‖K‖∞: row sums of |K| from the upper triangle (each off-diagonal entry twice).
        let sym = self.pattern.symbolic();
        let (ptr, idx) = (sym.col_ptr(), sym.row_idx());
        self.row_sums.iter_mut().for_each(|x| *x = 0.0);
        for c in 0..ptr.len() - 1 {
            for k in ptr[c] as usize..ptr[c + 1] as usize {
                let (r, v) = (idx[k] as usize, self.values[k].abs());
                self.row_sums[r] += v;
                if r != c {
                    self.row_sums[c] += v;
                }
            }
        }
        self.knorm = self.row_sums.iter().fold(0.0f64, |a, &x| a.max(x));
        self.kind = Factored::None;
        if !self.lu_only {
            if let Some(negative) = self.factor_ldlt() {
                self.kind = Factored::Ldlt { negative };
                return self.kind;
            }
        }
        self.factor_lu()
    }

    /// LU of the current (shifted) values, for this and all later factorizations of this
    /// structure: called when an LDLᵀ solve was not accurate.
    pub(crate) fn fall_back_to_lu(&mut self) -> Factored {
        self.lu_only = true;
        self.factor_lu()
    }

    fn factor_lu(&mut self) -> Factored {
        self.kind = Factored::None;
        let full = self.full.get_or_insert_with(|| {
            let sym = self.pattern.symbolic();
            let (ptr, idx) = (sym.col_ptr(), sym.row_idx());
            let upper = || {
                (0..ptr.len() - 1)
                    .flat_map(move |c| (ptr[c] as usize..ptr[c + 1] as usize).map(move |k| (k, c)))
            };
            let pattern = Pattern::new(
                ptr.len() - 1,
                ptr.len() - 1,
                upper().flat_map(|(k, c)| [(idx[k] as usize, c), (c, idx[k] as usize)]),
            );
            let slots = upper()
                .map(|(k, c)| {
                    let r = idx[k] as usize;
                    (pattern.slot(r, c) as Ix, pattern.slot(c, r) as Ix)
                })
                .collect();
            let symbolic = SymbolicLu::try_new(pattern.symbolic()).ok();
            Full {
                values: vec![0.0; pattern.nnz()],
                pattern,
                slots,
                symbolic,
            }
        });
        full.values.iter_mut().for_each(|v| *v = 0.0);
        for (&(a, b), &v) in full.slots.iter().zip(&self.values) {
            full.values[a as usize] = v;
            full.values[b as usize] = v;
        }
        self.lu = full.symbolic.as_ref().and_then(|sym| {
            Lu::try_new_with_symbolic(sym.clone(), full.pattern.matrix(&full.values)).ok()
        });
        if self.lu.is_some() {
            self.kind = Factored::Lu;
        }
        self.kind
    }

    /// The LDLᵀ factorization; the number of negative pivots, or `None` on a zero pivot.
    fn factor_ldlt(&mut self) -> Option<usize> {
        let sym = self.ldlt.as_ref()?;
        let SymbolicCholeskyRaw::Simplicial(simplicial) = sym.raw() else {
            return None;
        };
        let buf = self.factor_scratch.as_mut()?;
        // The simplicial kernel itself: the stored values are already the upper triangle in
        // the elimination order, and its workspace is `O(dim)` (the general entry point sizes
        // one for a permuted copy of the matrix).
        simplicial::factorize_simplicial_numeric_ldlt(
            &mut self.ldlt_values,
            self.pattern.matrix(&self.values),
            LdltRegularization::default(),
            simplicial,
            MemStack::new(buf),
        )
        .ok()?;
        let ptr = simplicial.col_ptr();
        let mut negative = 0;
        for j in 0..ptr.len() - 1 {
            let d = self.ldlt_values[ptr[j] as usize];
            // The pivots of rows are about `−1/R`, those of coordinates about `R`: no relative
            // size test here; the solve's residual check catches a poor factorization.
            if !d.is_finite() || d == 0.0 {
                return None;
            }
            negative += usize::from(d < 0.0);
        }
        Some(negative)
    }

    /// Number of constraint rows.
    pub(crate) fn rows(&self) -> usize {
        self.rows
    }

    /// Number of coordinates `n`.
    pub(crate) fn coordinates(&self) -> usize {
        self.n
    }
}
