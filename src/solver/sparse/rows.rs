//! The rows of `D Φ_q S` as the solver's sparse partition builds them, in one pass over the
//! Jacobian's triplets (grouped by ascending row): row `r`'s scaled entries
//! `a_rc = row_scale[r] · v · scale[c]` (duplicates summed in triplet order, zeros dropped; in
//! the order of their first nonzero term, which no reader depends on), with what the
//! elimination of module `fill_free` reads of them: each row's largest entry `max_c |a_rc|`, the
//! rows touching each body, the body of each row lying on one body alone and its reach there
//! (its largest entry in the translation columns and in the Euler-parameter columns).
//!
//! A row's structure (which triplets form which of its entries, its runs on bodies, whether it
//! lies on one body) depends only on its triplets' columns and on which terms and sums are
//! zero. [`Rows::refill`] keeps it for the next Jacobian of the same system (the same triplet
//! pattern): it writes each row's values by the same products and the same sums in the same
//! order, and expands afresh, as [`Rows::new`] does, only the rows where a term or a sum turned
//! zero or nonzero (then the rows touching each body are listed again if a row's bodies
//! changed). Each row has room for an entry a triplet and two more runs an entry it may gain,
//! so that it is expanded again in place.

/// The expanded rows: row `r` is `entries[at[r]..at[r] + len[r]]` (room up to `at[r + 1]`),
/// its triplets `first[r]..first[r + 1]`.
pub(crate) struct Rows {
    entries: Vec<(usize, f64)>,
    at: Vec<usize>,
    len: Vec<usize>,
    first: Vec<usize>,
    /// `max_c |a_rc|` of each row (0 for an empty one).
    pub(crate) rmax: Vec<f64>,
    /// The body of each row whose entries all lie on one body (`usize::MAX` otherwise).
    pub(crate) own_of: Vec<usize>,
    /// The reach of those rows on their body: `[translations, Euler parameters]`.
    pub(crate) reach: Vec<[f64; 2]>,
    /// The rows touching body `b` (ascending; a row once per run of its entries on `b`):
    /// `body_rows[body_start[b]..body_start[b + 1]]`.
    pub(crate) body_start: Vec<usize>,
    pub(crate) body_rows: Vec<usize>,
    /// The bodies of each row's runs of entries on one body:
    /// `runs[run_at[r]..run_at[r] + run_len[r]]` (room up to `run_at[r + 1]`).
    runs: Vec<usize>,
    run_at: Vec<usize>,
    run_len: Vec<usize>,
    /// The matrix's size `(m, n)` (`(usize::MAX, 0)`: unusable, to be built afresh).
    size: (usize, usize),
    /// The `(row, column)` of each triplet.
    pattern: Vec<(usize, usize)>,
    /// Where each triplet's term goes: its entry's index in `entries`, with [`ADD`] set where
    /// it is added to an earlier term ([`ZERO`]: the term was zero and skipped).
    slot: Vec<u32>,
    /// Each row's sums: [`PLAIN`] (none), [`SUMS`] (each nonzero), [`CANCELLED`] (one was
    /// zero and dropped: the row is expanded afresh at every refill).
    sums: Vec<u8>,
    /// Scratch of the expansion: where column `c` sits in the row being expanded,
    /// `(expansion count, index in entries)`.
    seen: Vec<(usize, usize)>,
    expansions: usize,
}

/// [`Rows::slot`]'s mark of a term added to an earlier one.
const ADD: u32 = 1 << 31;
/// [`Rows::slot`]'s mark of a zero term.
const ZERO: u32 = u32::MAX;
/// [`Rows::sums`]'s kinds of row.
const PLAIN: u8 = 0;
const SUMS: u8 = 1;
const CANCELLED: u8 = 2;

impl Rows {
    /// The rows of the `m × n` triplets `entries` with their scales, `None` unless the
    /// triplets are grouped by ascending row and inside the matrix (and fewer than `2³¹`).
    pub(crate) fn new(
        m: usize,
        n: usize,
        entries: &[(usize, usize, f64)],
        row_scale: &[f64],
        scale: &[f64],
    ) -> Option<Self> {
        let t = entries.len();
        if t >= ADD as usize {
            return None;
        }
        let mut first = Vec::with_capacity(m + 1);
        first.push(0);
        let mut rest = entries;
        for r in 0..m {
            let len = rest.iter().take_while(|e| e.0 == r).count();
            rest = &rest[len..];
            first.push(first[r] + len);
        }
        // Triplets left over: a row out of order or beyond `m`.
        if !rest.is_empty() {
            return None;
        }
        let mut rows = Rows {
            entries: Vec::with_capacity(t),
            at: Vec::with_capacity(m + 1),
            len: vec![0; m],
            first,
            rmax: vec![0.0; m],
            own_of: vec![usize::MAX; m],
            reach: vec![[0.0; 2]; m],
            body_start: Vec::new(),
            body_rows: Vec::new(),
            runs: Vec::with_capacity(2 * m + 2 * t),
            run_at: Vec::with_capacity(m + 1),
            run_len: vec![0; m],
            size: (m, n),
            pattern: entries.iter().map(|e| (e.0, e.1)).collect(),
            slot: Vec::with_capacity(t),
            sums: vec![PLAIN; m],
            seen: vec![(usize::MAX, 0); n],
            expansions: 0,
        };
        rows.slot.resize(t, ZERO);
        for r in 0..m {
            rows.at.push(rows.entries.len());
            rows.run_at.push(rows.runs.len());
            rows.expand(r, entries, row_scale[r], scale)?;
            // Room for a later expansion where a zero term or a cancelled sum is nonzero: an
            // entry for each triplet, two more runs for each of those entries (one splits a
            // run in two).
            let slack = rows.first[r + 1] - rows.first[r] - rows.len[r];
            for _ in 0..slack {
                rows.entries.push((0, 0.0));
                rows.runs.extend([usize::MAX; 2]);
            }
        }
        rows.at.push(rows.entries.len());
        rows.run_at.push(rows.runs.len());
        rows.list_bodies();
        Some(rows)
    }

    /// Row `r` expanded from its triplets (in `entries`, all of them) with its row scale, its
    /// entries and runs pushed after the others; `None` if a column lies beyond the matrix.
    fn expand(
        &mut self,
        r: usize,
        entries: &[(usize, usize, f64)],
        row_scale: f64,
        scale: &[f64],
    ) -> Option<()> {
        let n = self.size.1;
        let (start, runs) = (self.entries.len(), self.runs.len());
        self.expansions += 1;
        let stamp = self.expansions;
        // Zeros skipped (`x + 0 = x`: a sum keeps its value without them), duplicates summed
        // in triplet order; the largest entry and the runs by body as they come (`c` in
        // `lo..hi` on the last run's body).
        let (mut summed, mut max) = (false, 0.0f64);
        let (mut lo, mut hi) = (usize::MAX, 0);
        for k in self.first[r]..self.first[r + 1] {
            let (_, c, v) = entries[k];
            if c >= n {
                return None;
            }
            let a = v * row_scale * scale[c];
            if a == 0.0 {
                self.slot[k] = ZERO;
                continue;
            }
            let s = &mut self.seen[c];
            if s.0 == stamp {
                self.entries[s.1].1 += a;
                self.slot[k] = s.1 as u32 | ADD;
                summed = true;
                continue;
            }
            *s = (stamp, self.entries.len());
            self.slot[k] = self.entries.len() as u32;
            self.entries.push((c, a));
            // `max_c |a_rc|` as `fold(0, f64::max)` gives it (NaN ignored).
            if a.abs() > max {
                max = a.abs();
            }
            if c < lo || c >= hi {
                lo = c - c % 7;
                hi = lo + 7;
                self.runs.push(c / 7);
            }
        }
        self.sums[r] = PLAIN;
        if summed {
            self.sums[r] = SUMS;
            // Counted again without the sums that cancelled (the order kept).
            self.runs.truncate(runs);
            let (mut kept, mut last) = (start, usize::MAX);
            max = 0.0;
            for i in start..self.entries.len() {
                let e = self.entries[i];
                if e.1 != 0.0 {
                    self.entries[kept] = e;
                    kept += 1;
                    max = max.max(e.1.abs());
                    if e.0 / 7 != last {
                        last = e.0 / 7;
                        self.runs.push(last);
                    }
                }
            }
            if kept != self.entries.len() {
                // The slots no longer point at the entries: expanded afresh at each refill.
                self.sums[r] = CANCELLED;
            }
            self.entries.truncate(kept);
        }
        self.len[r] = self.entries.len() - start;
        self.run_len[r] = self.runs.len() - runs;
        self.rmax[r] = max;
        self.own_of[r] = usize::MAX;
        self.reach[r] = [0.0; 2];
        // A row on one body alone (its entries in one run, or in several on that body).
        let bodies = &self.runs[runs..];
        if let Some(&body) = bodies.first() {
            if bodies.iter().all(|&x| x == body) {
                self.own_of[r] = body;
                self.reach[r] = reach(&self.entries[start..]);
            }
        }
        Some(())
    }

    /// Lists the rows touching each body from the rows' runs.
    fn list_bodies(&mut self) {
        let (m, nb) = (self.size.0, self.size.1 / 7);
        self.body_start.clear();
        self.body_start.resize(nb + 1, 0);
        for r in 0..m {
            let (start, len) = (self.run_at[r], self.run_len[r]);
            for &body in &self.runs[start..start + len] {
                self.body_start[body + 1] += 1;
            }
        }
        for b in 0..nb {
            self.body_start[b + 1] += self.body_start[b];
        }
        self.body_rows.clear();
        self.body_rows.resize(self.body_start[nb], usize::MAX);
        let mut fill = self.body_start.clone();
        for r in 0..m {
            let (start, len) = (self.run_at[r], self.run_len[r]);
            for &body in &self.runs[start..start + len] {
                self.body_rows[fill[body]] = r;
                fill[body] += 1;
            }
        }
    }

    /// Row `r` expanded afresh from `entries` and moved into its room; `false` where it does
    /// not fit there (more entries or runs than when built).
    fn expand_in_place(
        &mut self,
        r: usize,
        entries: &[(usize, usize, f64)],
        row_scale: f64,
        scale: &[f64],
    ) -> bool {
        let (start, runs) = (self.entries.len(), self.runs.len());
        if self.expand(r, entries, row_scale, scale).is_none()
            || self.at[r] + self.len[r] > self.at[r + 1]
            || self.run_at[r] + self.run_len[r] > self.run_at[r + 1]
        {
            return false;
        }
        self.entries.copy_within(start.., self.at[r]);
        self.entries.truncate(start);
        self.runs.copy_within(runs.., self.run_at[r]);
        self.runs.truncate(runs);
        // The slots moved with the entries (`start ≥ at[r]`).
        let shift = (start - self.at[r]) as u32;
        for slot in &mut self.slot[self.first[r]..self.first[r + 1]] {
            if *slot != ZERO {
                *slot -= shift;
            }
        }
        true
    }

    /// The rows of new triplets `entries` of the same `m × n` system written into this
    /// structure, as [`Rows::new`] would build them; `false` (the rows left unusable: build
    /// them afresh) for another matrix size or triplet pattern, or a row that no longer fits
    /// its room.
    pub(crate) fn refill(
        &mut self,
        m: usize,
        n: usize,
        entries: &[(usize, usize, f64)],
        row_scale: &[f64],
        scale: &[f64],
    ) -> bool {
        if self.size != (m, n) || entries.len() != self.pattern.len() {
            return false;
        }
        let mut bodies_changed = false;
        for r in 0..m {
            let row_scale = row_scale[r];
            let tri = self.first[r]..self.first[r + 1];
            let (terms, pattern) = (&entries[tri.clone()], &self.pattern[tri.clone()]);
            if terms.iter().zip(pattern).any(|(e, p)| (e.0, e.1) != *p) {
                self.size = (usize::MAX, 0);
                return false;
            }
            let mut same = self.sums[r] != CANCELLED;
            let out = &mut self.entries;
            for (&(_, c, v), &slot) in terms.iter().zip(&self.slot[tri]) {
                if !same {
                    break;
                }
                let a = v * row_scale * scale[c];
                if slot == ZERO {
                    same = a == 0.0;
                } else if a == 0.0 {
                    same = false;
                } else if slot & ADD == 0 {
                    out[slot as usize].1 = a;
                } else {
                    out[(slot & !ADD) as usize].1 += a;
                }
            }
            let row = self.at[r]..self.at[r] + self.len[r];
            if same && self.sums[r] == SUMS {
                same = self.entries[row.clone()].iter().all(|e| e.1 != 0.0);
            }
            if same {
                let row = &self.entries[row];
                // `max_c |a_rc|` as `fold(0, f64::max)` gives it (NaN ignored).
                self.rmax[r] = row.iter().fold(0.0f64, |x, e| x.max(e.1.abs()));
                if self.own_of[r] != usize::MAX {
                    self.reach[r] = reach(row);
                }
                continue;
            }
            let before: Vec<usize> = self.bodies(r).to_vec();
            if !self.expand_in_place(r, entries, row_scale, scale) {
                self.size = (usize::MAX, 0);
                return false;
            }
            bodies_changed |= before != self.bodies(r);
        }
        if bodies_changed {
            self.list_bodies();
        }
        true
    }

    /// Row `r`'s entries.
    pub(crate) fn row(&self, r: usize) -> &[(usize, f64)] {
        &self.entries[self.at[r]..self.at[r] + self.len[r]]
    }

    /// The bodies row `r` touches (a body once per run of its entries there).
    pub(crate) fn bodies(&self, r: usize) -> &[usize] {
        &self.runs[self.run_at[r]..self.run_at[r] + self.run_len[r]]
    }

    /// The rows touching body `b`, each once (ascending).
    pub(crate) fn touching(&self, b: usize, out: &mut Vec<usize>) {
        out.clear();
        out.extend_from_slice(&self.body_rows[self.body_start[b]..self.body_start[b + 1]]);
        out.dedup();
    }
}

/// The reach of a row on one body: its largest entry on the translation columns and on the
/// Euler-parameter columns.
fn reach(row: &[(usize, f64)]) -> [f64; 2] {
    let mut reach = [0.0f64; 2];
    for &(c, v) in row {
        let kind = usize::from(c % 7 >= 3);
        reach[kind] = reach[kind].max(v.abs());
    }
    reach
}

#[cfg(test)]
#[path = "rows_tests.rs"]
mod tests;
