//! One body's step of the sparse partition on dense copies (module `fill_free`): the active
//! rows touching body `b`, each as first expanded (module `rows`) or as an earlier body's step
//! left it ([`Changed`]). Copy `i` is row `rows[i]` (ascending), its entry on column
//! `7 bodies[j] + k` at `a[i w + 7 j + k]` (`bodies[0] = b`, `w = 7 len(bodies)`), zero where
//! the row has none. A copy holds the whole row (every body it touches), so its maximum is the
//! row's.
//!
//! The steps are the solver's on the rows' sparse copies, to the bit: a pivot on `a_ik`
//! updates `a_jl ← a_jl − (a_jk / a_ik) a_il` on every column, where the sparse step updates
//! the columns the pivot row has an entry in; elsewhere `a_il = 0` and the update leaves a
//! nonzero `a_jl` as it was (a zero may change sign, which neither a test `|a| > τ` nor a
//! later product or difference sees). A row whose entry in the pivot's column is zero is
//! skipped (the sparse step, where the row holds that zero, changes no nonzero entry either),
//! and a pivot or an active row's maximum is never zero. A row the step changed and left
//! active is kept on the bodies where its copy has a nonzero entry: the sparse row may also
//! hold zeros elsewhere (a sum that cancelled), which no pivot choice or update reads.

use super::partition::{OWN_THRESHOLD, THRESHOLD};
use super::rows::Rows;

/// The rows an earlier body's step changed and left active, as that step left them.
#[derive(Default)]
pub(crate) struct Changed {
    /// The index of each row's copy in `copies` (`u32::MAX`: the row is unchanged).
    slot: Vec<u32>,
    /// Each copy: its row's bodies, its entries on their columns (7 a body, in that order) and
    /// its largest entry.
    copies: Vec<(Vec<usize>, Vec<f64>, f64)>,
    /// The changed rows reached at each body (may repeat a row).
    reached: Vec<Vec<usize>>,
}

impl Changed {
    /// None changed yet, of `m` rows on `nb` bodies.
    pub(crate) fn new(m: usize, nb: usize) -> Self {
        Changed {
            slot: vec![u32::MAX; m],
            copies: Vec::new(),
            reached: vec![Vec::new(); nb],
        }
    }

    /// Adds to `cands` (the rows first touching `b`, ascending) the changed rows reached at
    /// `b`, keeping them ascending and distinct.
    pub(crate) fn touching(&mut self, b: usize, cands: &mut Vec<usize>) {
        let reached = std::mem::take(&mut self.reached[b]);
        if !reached.is_empty() {
            cands.extend_from_slice(&reached);
            cands.sort_unstable();
            cands.dedup();
        }
    }

    /// Row `r`'s changed copy, if an earlier step changed it.
    fn get(&self, r: usize) -> Option<&(Vec<usize>, Vec<f64>, f64)> {
        self.copies.get(self.slot[r] as usize)
    }
}

/// The copies at one body; buffers kept from body to body.
#[derive(Default)]
pub(crate) struct Block {
    /// The row of each copy (ascending).
    pub(crate) rows: Vec<usize>,
    bodies: Vec<usize>,
    w: usize,
    a: Vec<f64>,
    /// `max_l |a_il|` of each copy, kept current as the copies change (in [`Block::pivot`]).
    rmax: Vec<f64>,
    /// Whether each copy is still active.
    pub(crate) live: Vec<bool>,
}

/// The index of body `body` in `bodies`, added at the end if absent.
fn slot(bodies: &mut Vec<usize>, body: usize) -> usize {
    match bodies.iter().position(|&x| x == body) {
        Some(j) => j,
        None => {
            bodies.push(body);
            bodies.len() - 1
        }
    }
}

impl Block {
    /// The copies of the active rows among `cands` (ascending) at body `b`: `changed`'s copy
    /// of a changed row, else the row as expanded in `rows`.
    pub(crate) fn load(
        &mut self,
        b: usize,
        cands: &[usize],
        active: &[bool],
        rows: &Rows,
        changed: &Changed,
    ) {
        self.rows.clear();
        self.rows
            .extend(cands.iter().copied().filter(|&r| active[r]));
        self.bodies.clear();
        self.bodies.push(b);
        for &r in &self.rows {
            let bodies = changed.get(r).map_or(rows.bodies(r), |c| &c.0);
            for &body in bodies {
                slot(&mut self.bodies, body);
            }
        }
        let w = 7 * self.bodies.len();
        self.w = w;
        self.a.clear();
        self.a.resize(self.rows.len() * w, 0.0);
        self.rmax.clear();
        self.live.clear();
        for (copy, &r) in self.a.chunks_exact_mut(w).zip(&self.rows) {
            if let Some((bodies, a, rmax)) = changed.get(r) {
                for (&body, seg) in bodies.iter().zip(a.chunks_exact(7)) {
                    let base = 7 * slot(&mut self.bodies, body);
                    copy[base..base + 7].copy_from_slice(seg);
                }
                self.rmax.push(*rmax);
            } else {
                let (mut last, mut base) = (usize::MAX, 0);
                for &(c, v) in rows.row(r) {
                    let body = c / 7;
                    if body != last {
                        last = body;
                        base = 7 * slot(&mut self.bodies, body);
                    }
                    copy[base + (c - 7 * body)] = v;
                }
                self.rmax.push(rows.rmax[r]);
            }
            self.live.push(true);
        }
    }

    /// The number of bodies the copies span.
    pub(crate) fn bodies(&self) -> usize {
        self.bodies.len()
    }

    /// Whether a copy of a row that started on body `b` alone is still active with an entry
    /// above `tol` on `b`'s `free` columns: the sparse partition carries such a row on to the
    /// bodies its fill reached (`(row, b, false)` in its second pass), which this route does
    /// not follow.
    pub(crate) fn carries_own_row(
        &self,
        free: &[bool; 7],
        tol: f64,
        b: usize,
        rows: &Rows,
    ) -> bool {
        self.a.chunks_exact(self.w).enumerate().any(|(i, row)| {
            self.live[i]
                && rows.own_of[self.rows[i]] == b
                && (0..7).any(|k| free[k] && row[k].abs() > tol)
        })
    }

    /// Keeps the copies still active after the step in `changed`, each on the bodies where it
    /// has a nonzero entry, and reached at those bodies.
    pub(crate) fn keep(&self, changed: &mut Changed) {
        for (i, row) in self.a.chunks_exact(self.w).enumerate() {
            if !self.live[i] {
                continue;
            }
            let r = self.rows[i];
            if changed.slot[r] == u32::MAX {
                changed.slot[r] = changed.copies.len() as u32;
                changed.copies.push((Vec::new(), Vec::new(), 0.0));
            }
            let copy = &mut changed.copies[changed.slot[r] as usize];
            copy.0.clear();
            copy.1.clear();
            copy.2 = self.rmax[i];
            for (&body, seg) in self.bodies.iter().zip(row.chunks_exact(7)) {
                if seg.iter().any(|&v| v != 0.0) {
                    copy.0.push(body);
                    copy.1.extend_from_slice(seg);
                    changed.reached[body].push(r);
                }
            }
        }
    }

    /// The partition's pivot on copy `i` in column `k` of the body: the column eliminated
    /// from the other active copies, `a_j ← a_j − (a_jk / a_ik) a_i`; a copy left with no
    /// entry above `tol` is redundant. `active` follows the copies' rows.
    pub(crate) fn pivot(&mut self, i: usize, k: usize, active: &mut [bool], tol: f64) {
        let w = self.w;
        self.live[i] = false;
        active[self.rows[i]] = false;
        let (head, rest) = self.a.split_at_mut(i * w);
        let (pivot_row, tail) = rest.split_at_mut(w);
        let a_ik = pivot_row[k];
        let others = head.chunks_exact_mut(w).chain(tail.chunks_exact_mut(w));
        for (j, row) in (0..self.live.len()).filter(|&j| j != i).zip(others) {
            if !self.live[j] || row[k] == 0.0 {
                continue;
            }
            let f = row[k] / a_ik;
            row[k] = 0.0;
            let mut max = 0.0f64;
            for (e, &v) in row[..k].iter_mut().zip(&pivot_row[..k]) {
                *e -= f * v;
                // `fold(0, f64::max)` of the magnitudes (NaN ignored).
                if e.abs() > max {
                    max = e.abs();
                }
            }
            for (e, &v) in row[k + 1..].iter_mut().zip(&pivot_row[k + 1..]) {
                *e -= f * v;
                if e.abs() > max {
                    max = e.abs();
                }
            }
            self.rmax[j] = max;
            if self.rmax[j] <= tol {
                self.live[j] = false;
                active[self.rows[j]] = false;
            }
        }
    }

    /// The partition's pivot choice in the body's `free` columns: the largest `|a_ik| > tol`
    /// with `|a_ik| ≥ THRESHOLD · max_l |a_il|`, a later one only if larger by a relative
    /// `1e-9`.
    pub(crate) fn best_pivot(&self, free: &[bool; 7], tol: f64) -> Option<(usize, usize)> {
        let (mut best, mut bar) = (None, 0.0);
        for (i, row) in self.a.chunks_exact(self.w).enumerate() {
            // No entry of a copy exceeds its maximum: a copy whose maximum cannot pass the bar
            // is not read (the same choice as reading it; `bar` is 0 before the first).
            if !self.live[i] || self.rmax[i] <= bar {
                continue;
            }
            let least = THRESHOLD * self.rmax[i];
            for k in 0..7 {
                let a = row[k].abs();
                // `a > tol > 0`: the first candidate passes `a > bar = 0`.
                if free[k] && a > tol && a >= least && a > bar {
                    best = Some((i, k));
                    bar = a * (1.0 + 1e-9);
                }
            }
        }
        best
    }

    /// The partition's second-pass pivot among the copies of rows that started on the body
    /// `b` alone: the entry on a `free` column largest relative to the row's reach there
    /// (same kind of column), if at least `OWN_THRESHOLD` of it; a later one only if larger
    /// by a relative `1e-9`.
    pub(crate) fn best_own_pivot(
        &self,
        free: &[bool; 7],
        tol: f64,
        b: usize,
        rows: &Rows,
    ) -> Option<(usize, usize)> {
        let (mut best, mut bar) = (None, 0.0);
        for (i, row) in self.a.chunks_exact(self.w).enumerate() {
            let r = self.rows[i];
            if !self.live[i] || rows.own_of[r] != b {
                continue;
            }
            for k in 0..7 {
                let v = row[k].abs();
                let ratio = v / rows.reach[r][usize::from(k >= 3)].max(f64::MIN_POSITIVE);
                // `ratio ≥ OWN_THRESHOLD > 0`: the first candidate passes `ratio > bar = 0`.
                if free[k] && v > tol && ratio >= OWN_THRESHOLD && ratio > bar {
                    best = Some((i, k));
                    bar = ratio * (1.0 + 1e-9);
                }
            }
        }
        best
    }
}
