//! The border of a tree-structured matrix: the few unknowns (rows closing a loop, the bodies
//! a loop couples) that do not fit the tree, eliminated after it through the dense Schur
//! complement.
//!
//! With the tree part `T` (solved by the caller's block solve) and the border `B`,
//!
//! ```text
//! [ T  C ] [x_T]   [r_T]        S = D − R T⁻¹ C  (k × k, dense, LU with partial pivoting)
//! [ R  D ] [x_B] = [r_B],       x_B = S⁻¹ (r_B − R T⁻¹ r_T),   x_T = T⁻¹ (r_T − C x_B)
//! ```
//!
//! and for the transposed system `Sᵀ` with `Tᵀ`: two tree solves per solve, `k` to form `S`.
//! A column of `C` reaches one or two bodies (a loop or contact row): its solve `T⁻¹ c` is
//! zero outside the nodes it can reach from there, and the caller's block solve starts at the
//! column's first (or last) tree entry instead of the end of the tree.
//!
//! A ladder (a loop per rung) borders 7 pivots of `Φ_u` and 14 KKT unknowns per rung, above
//! the limits of `phi_u` and `shape` from 10 rungs: it takes the sparse factors. Its `S` is
//! banded (bandwidth 7 for `Φ_u`, about 23 for the KKT matrix, measured up to 100 rungs), but
//! stored dense here and formed with solves that each run down to the lowest position any
//! border row reaches, `O(k N)` (docs/benchmarks-history.md, session 25, h/ladder).

use super::dense;

/// Which unknowns form the border and where its entries sit.
#[cfg_attr(test, derive(Debug, PartialEq))]
pub(crate) struct Border {
    /// The border's unknowns (indices in the caller's numbering), in border order.
    positions: Vec<usize>,
    /// Border index of each unknown (`u32::MAX`: in the tree).
    index: Vec<u32>,
    /// `(row, column)` of the entries with a border row or column (`C`, `R`, `D`).
    entries: Vec<(u32, u32)>,
}

impl Border {
    /// The border `positions` among `order` unknowns, without entries yet.
    pub(crate) fn new(positions: &[usize], order: usize) -> Self {
        let mut index = vec![u32::MAX; order];
        for (k, &p) in positions.iter().enumerate() {
            index[p] = k as u32;
        }
        Border {
            positions: positions.to_vec(),
            index,
            entries: Vec::new(),
        }
    }

    /// Registers the entry `(p, q)` (one of them in the border); its value slot.
    pub(crate) fn add(&mut self, p: usize, q: usize) -> usize {
        self.entries.push((p as u32, q as u32));
        self.entries.len() - 1
    }

    /// No border.
    pub(crate) fn is_empty(&self) -> bool {
        self.positions.is_empty()
    }

    /// Number of border unknowns `k`.
    pub(crate) fn size(&self) -> usize {
        self.positions.len()
    }

    /// The smallest and largest magnitude of the pivots of `S` in the factored `values`
    /// ([`Border::factor`]).
    pub(crate) fn pivot_range(&self, values: &[f64]) -> (f64, f64) {
        let (k, s) = (self.size(), &values[self.entries.len()..]);
        (0..k).fold((f64::INFINITY, 0.0), |(lo, hi), b| {
            let v = s[b * k + b].abs();
            (lo.min(v), hi.max(v))
        })
    }

    /// Length of the values: the entries, then `S` (`k × k`, row-major).
    pub(crate) fn len(&self) -> usize {
        self.entries.len() + self.positions.len().pow(2)
    }

    /// Forms `S = D − R T⁻¹ C` from the entry values at the front of `values` (`solve(x, lo,
    /// hi, need)`: `x ← T⁻¹ x` where `x` is zero outside the positions `lo ..= hi`, so that the
    /// caller's block solve may skip the nodes whose part of the result is zero, and where only
    /// the positions from `need` on are read: those `R` reaches, whose values the block solve
    /// finishes before it reaches the nodes below, which it may leave undone) and factors
    /// it (LU with partial pivoting); `None` if singular. With `inertia` (a symmetric matrix), also the number of negative eigenvalues
    /// of `S` (LDLᵀ without pivoting of its symmetric part; `None` on a zero pivot): the
    /// border's share of the matrix's inertia (Haynsworth).
    pub(crate) fn factor(
        &self,
        values: &mut [f64],
        piv: &mut [u16],
        solve: impl Fn(&mut [f64], usize, usize, usize),
        inertia: bool,
    ) -> Option<Option<usize>> {
        let k = self.size();
        let ne = self.entries.len();
        let (vals, s) = values.split_at_mut(ne);
        s.iter_mut().for_each(|v| *v = 0.0);
        let mut col = vec![0.0; self.index.len()];
        // The lowest tree position `R` reaches (a border row's entry in the tree): the solves
        // below are read there and above only (none: `S = D`).
        let need = self
            .entries
            .iter()
            .filter(|&&(p, q)| {
                self.index[p as usize] != u32::MAX && self.index[q as usize] == u32::MAX
            })
            .map(|&(_, q)| q as usize)
            .min();
        for (b, &pb) in self.positions.iter().enumerate() {
            col.iter_mut().for_each(|v| *v = 0.0);
            // The column's tree entries lie in `lo ..= hi` (a contact or a loop row reaches
            // one or two bodies): the solve starts or ends there.
            let (mut lo, mut hi) = (usize::MAX, 0);
            for (e, &(p, q)) in self.entries.iter().enumerate() {
                let (p, q) = (p as usize, q as usize);
                if q == pb {
                    match self.index[p] {
                        u32::MAX => {
                            col[p] += vals[e];
                            (lo, hi) = (lo.min(p), hi.max(p));
                        }
                        a => s[a as usize * k + b] += vals[e],
                    }
                }
            }
            if let Some(need) = need.filter(|_| lo <= hi) {
                solve(&mut col, lo, hi, need);
            }
            for (e, &(p, q)) in self.entries.iter().enumerate() {
                let (a, q) = (self.index[p as usize], q as usize);
                if a != u32::MAX && self.index[q] == u32::MAX {
                    s[a as usize * k + b] -= vals[e] * col[q];
                }
            }
        }
        let negative = if inertia {
            let mut sym: Vec<f64> = (0..k * k)
                .map(|x| 0.5 * (s[x] + s[(x % k) * k + x / k]))
                .collect();
            dense::ldlt(&mut sym, k)
        } else {
            None
        };
        (dense::lu(s, k, piv) && s.iter().all(|v| v.is_finite())).then_some(negative)
    }

    /// Solves `[T C; R D] x = r` (or its transpose) in place with the factors of
    /// [`Border::factor`]; `solve(x, t)` as there.
    pub(crate) fn solve(
        &self,
        values: &[f64],
        piv: &[u16],
        x: &mut [f64],
        transpose: bool,
        solve: impl Fn(&mut [f64], bool),
    ) {
        let k = self.size();
        let (vals, s) = values.split_at(self.entries.len());
        // y = T⁻¹ r_T (border unknowns zero).
        let mut y: Vec<f64> = x.to_vec();
        for &p in &self.positions {
            y[p] = 0.0;
        }
        solve(&mut y, transpose);
        let mut rb: Vec<f64> = self.positions.iter().map(|&p| x[p]).collect();
        for (e, &(p, q)) in self.entries.iter().enumerate() {
            let (p, q) = (p as usize, q as usize);
            // Entry (p, q) of the matrix; transposed it links equation q to unknown p.
            let (eq, un) = if transpose { (q, p) } else { (p, q) };
            let a = self.index[eq];
            if a != u32::MAX && self.index[un] == u32::MAX {
                rb[a as usize] -= vals[e] * y[un];
            }
        }
        if transpose {
            dense::lu_solve_transpose(s, piv, k, &mut rb);
        } else {
            dense::lu_solve(s, piv, k, &mut rb, 1);
        }
        // x_T = T⁻¹ (r_T − C x_B).
        for &p in &self.positions {
            x[p] = 0.0;
        }
        for (e, &(p, q)) in self.entries.iter().enumerate() {
            let (p, q) = (p as usize, q as usize);
            let (eq, un) = if transpose { (q, p) } else { (p, q) };
            if self.index[eq] == u32::MAX {
                let b = self.index[un];
                if b != u32::MAX {
                    x[eq] -= vals[e] * rb[b as usize];
                }
            }
        }
        solve(x, transpose);
        for (b, &p) in self.positions.iter().enumerate() {
            x[p] = rb[b];
        }
    }

    /// Adds `|value|` of every entry to the sum of its row (`‖K‖∞`).
    pub(crate) fn add_row_sums(&self, values: &[f64], rows: &mut [f64]) {
        for (e, &(p, _)) in self.entries.iter().enumerate() {
            rows[p as usize] += values[e].abs();
        }
    }

    /// `r −= E x` for the entries `E` (a residual's border part).
    pub(crate) fn sub_product(&self, values: &[f64], x: &[f64], r: &mut [f64]) {
        for (e, &(p, q)) in self.entries.iter().enumerate() {
            r[p as usize] -= values[e] * x[q as usize];
        }
    }
}
