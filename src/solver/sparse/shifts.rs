//! The two diagonal shifts of a KKT matrix's `W` block, applied in place to its stored values
//! and shared by the sparse matrix (module `kkt`) and the tree one (`solver::tree::kkt`):
//!
//! - `δ` on every coordinate (`W + δ S⁻²` in the original coordinates), which makes the
//!   reduced matrix `Zᵀ (W + δ S⁻²) Z` positive definite away from a minimum;
//! - `−σ` on the independent coordinates alone, which turns the reduced matrix into
//!   `Ĥ − σ I`, so that the LDLᵀ's negative pivots count the eigenvalues of `Ĥ` below `σ`
//!   (module `solver::stability::inertia`).
//!
//! Each is replaced, not accumulated: a new shift adds the change since the last one, and
//! [`Shifts::max_diagonal`] reads the diagonal without them.

/// An index into a matrix's stored values (`usize` in the sparse matrix, `u32` in the tree's).
pub(crate) trait Slot: Copy {
    /// The index as `usize`.
    fn index(self) -> usize;
}

impl Slot for usize {
    fn index(self) -> usize {
        self
    }
}

impl Slot for u32 {
    fn index(self) -> usize {
        self as usize
    }
}

/// The shifts now in a matrix's values: `δ`, `σ` and the coordinates `σ` applies to.
#[derive(Clone, Debug, Default)]
pub(crate) struct Shifts {
    delta: f64,
    sigma: f64,
    sigma_columns: Vec<usize>,
}

impl Shifts {
    /// No shift (the values were just assembled).
    pub(crate) fn clear(&mut self) {
        self.delta = 0.0;
        self.sigma = 0.0;
        self.sigma_columns.clear();
    }

    /// The largest diagonal entry `|W_cc|` of the unshifted `W` block, whose diagonal is at
    /// `slots` of `values`.
    pub(crate) fn max_diagonal<S: Slot>(&self, slots: &[S], values: &[f64]) -> f64 {
        let mut shifted = vec![0.0; slots.len()];
        for &c in &self.sigma_columns {
            shifted[c] = self.sigma;
        }
        slots.iter().zip(&shifted).fold(0.0f64, |a, (&s, &sigma)| {
            a.max((values[s.index()] - self.delta + sigma).abs())
        })
    }

    /// Subtracts `σ` from the diagonal of `W` at the coordinates `columns`, in place of the
    /// last such shift.
    pub(crate) fn shift_independent<S: Slot>(
        &mut self,
        slots: &[S],
        values: &mut [f64],
        columns: &[usize],
        sigma: f64,
    ) {
        for &c in &self.sigma_columns {
            values[slots[c].index()] += self.sigma;
        }
        self.sigma_columns.clear();
        self.sigma_columns.extend_from_slice(columns);
        self.sigma = sigma;
        for &c in &self.sigma_columns {
            values[slots[c].index()] -= sigma;
        }
    }

    /// Adds `δ` to the whole diagonal of `W`, in place of the last such shift.
    pub(crate) fn shift_all<S: Slot>(&mut self, slots: &[S], values: &mut [f64], delta: f64) {
        for &s in slots {
            values[s.index()] += delta - self.delta;
        }
        self.delta = delta;
    }
}
