//! One body's step of the sparse partition on dense copies (module `fill_free`): the active
//! rows touching body `b`, each as first expanded (module `rows`) or as an earlier body's step
//! left it ([`Changed`]). Copy `i` is row `rows[i]` (ascending), its entry on column
//! `7 bodies[j] + k` at `a[i w + 7 j + k]` (`bodies[0] = b`, `w = 7 len(bodies)`), zero where
//! the row has none. A copy holds the whole row (every body it touches), so its maximum is the
//! row's. Each copy also carries its span, the bodies where it may be nonzero (those of its
//! row, and those of every pivot copy that updated it): a pivot reads and writes the copies
//! there only, and a copy is kept from there.
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

/// The rows an earlier body's step changed and left active, as that step left them: each copy
/// its row's bodies and its entries on their columns (7 a body, in that order) in two arenas
/// (a row changed again gets a new copy; the old one is left unread), and its largest entry.
#[derive(Default)]
pub(crate) struct Changed {
    /// The index of each row's copy in `copies` (`u32::MAX`: the row is unchanged).
    slot: Vec<u32>,
    /// Each copy: where its bodies start in `bodies` (its entries at 7 times that in
    /// `values`), how many, and its largest entry.
    copies: Vec<(usize, usize, f64)>,
    bodies: Vec<usize>,
    values: Vec<f64>,
    /// The changed rows reached at each body (may repeat a row), as lists linked through
    /// `links`: `head[b]` the last one reached at `b` (`u32::MAX`: none), each link a row and
    /// the one before it.
    head: Vec<u32>,
    links: Vec<(usize, u32)>,
}

impl Changed {
    /// None changed yet, of `m` rows on `nb` bodies.
    pub(crate) fn new(m: usize, nb: usize) -> Self {
        Changed {
            slot: vec![u32::MAX; m],
            head: vec![u32::MAX; nb],
            ..Changed::default()
        }
    }

    /// Adds to `cands` (the rows first touching `b`, ascending) the changed rows reached at
    /// `b`, keeping them ascending and distinct.
    pub(crate) fn touching(&mut self, b: usize, cands: &mut Vec<usize>) {
        let mut at = std::mem::replace(&mut self.head[b], u32::MAX);
        if at == u32::MAX {
            return;
        }
        while at != u32::MAX {
            let (r, before) = self.links[at as usize];
            cands.push(r);
            at = before;
        }
        cands.sort_unstable();
        cands.dedup();
    }

    /// Row `r`'s changed copy (its bodies, its entries, its largest entry), if an earlier step
    /// changed it.
    fn get(&self, r: usize) -> Option<(&[usize], &[f64], f64)> {
        let &(start, len, rmax) = self.copies.get(self.slot[r] as usize)?;
        Some((
            &self.bodies[start..start + len],
            &self.values[7 * start..7 * (start + len)],
            rmax,
        ))
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
    /// The bodies (bit `j`: `bodies[j]`, for `j < 64`) where each copy may have a nonzero
    /// entry: it is zero on every other.
    spans: Vec<u64>,
}

/// The bit of the body at slot `j` in a copy's span (none beyond 64 bodies, more than a step
/// may span: the route gives up there before reading a span).
fn bit(j: usize) -> u64 {
    1u64.checked_shl(j as u32).unwrap_or(0)
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
            let bodies = changed.get(r).map_or(rows.bodies(r), |c| c.0);
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
        self.spans.clear();
        for (copy, &r) in self.a.chunks_exact_mut(w).zip(&self.rows) {
            let mut span = 0;
            if let Some((bodies, a, rmax)) = changed.get(r) {
                for (&body, seg) in bodies.iter().zip(a.chunks_exact(7)) {
                    let j = slot(&mut self.bodies, body);
                    span |= bit(j);
                    copy[7 * j..7 * j + 7].copy_from_slice(seg);
                }
                self.rmax.push(rmax);
            } else {
                let (mut last, mut base) = (usize::MAX, 0);
                for &(c, v) in rows.row(r) {
                    let body = c / 7;
                    if body != last {
                        last = body;
                        let j = slot(&mut self.bodies, body);
                        span |= bit(j);
                        base = 7 * j;
                    }
                    copy[base + (c - 7 * body)] = v;
                }
                self.rmax.push(rows.rmax[r]);
            }
            self.spans.push(span);
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
            let start = changed.bodies.len();
            let mut span = self.spans[i];
            while span != 0 {
                let j = span.trailing_zeros() as usize;
                span &= span - 1;
                let (body, seg) = (self.bodies[j], &row[7 * j..7 * j + 7]);
                if seg.iter().any(|&v| v != 0.0) {
                    changed.bodies.push(body);
                    changed.values.extend_from_slice(seg);
                    changed.links.push((r, changed.head[body]));
                    changed.head[body] = (changed.links.len() - 1) as u32;
                }
            }
            changed.slot[r] = changed.copies.len() as u32;
            let len = changed.bodies.len() - start;
            changed.copies.push((start, len, self.rmax[i]));
        }
    }

    /// The partition's pivot on copy `i` in column `k` of the body: the column eliminated
    /// from the other active copies, `a_j ← a_j − (a_jk / a_ik) a_i`; a copy left with no
    /// entry above `tol` is redundant. `active` follows the copies' rows. The update runs over
    /// the pivot copy's span: elsewhere `a_jl − f · 0` leaves a nonzero `a_jl` as it is (the
    /// module's note on zeros), and only the maximum reads copy `j` there (on its own span).
    pub(crate) fn pivot(&mut self, i: usize, k: usize, active: &mut [bool], tol: f64) {
        let w = self.w;
        self.live[i] = false;
        active[self.rows[i]] = false;
        let (head, rest) = self.a.split_at_mut(i * w);
        let (pivot_row, tail) = rest.split_at_mut(w);
        let a_ik = pivot_row[k];
        // Slot 0 (body `b`, where `a_ik ≠ 0`) is in the pivot's span.
        let pivot_span = self.spans[i] | 1;
        for j in 0..self.live.len() {
            if j == i || !self.live[j] {
                continue;
            }
            let row = if j < i {
                &mut head[j * w..(j + 1) * w]
            } else {
                &mut tail[(j - i - 1) * w..(j - i) * w]
            };
            if row[k] == 0.0 {
                continue;
            }
            let f = row[k] / a_ik;
            row[k] = 0.0;
            // `fold(0, f64::max)` of the magnitudes (NaN ignored), in any order; zero outside
            // the spans.
            let mut max = 0.0f64;
            let mut at_most = |e: f64| {
                if e.abs() > max {
                    max = e.abs();
                }
            };
            for (l, (e, &v)) in row[..7].iter_mut().zip(&pivot_row[..7]).enumerate() {
                if l != k {
                    *e -= f * v;
                }
                at_most(*e);
            }
            let span = self.spans[j] | pivot_span;
            let mut rest = span & !1;
            while rest != 0 {
                let s = rest.trailing_zeros() as usize;
                rest &= rest - 1;
                let seg = &mut row[7 * s..7 * s + 7];
                if pivot_span & (1 << s) != 0 {
                    for (e, &v) in seg.iter_mut().zip(&pivot_row[7 * s..7 * s + 7]) {
                        *e -= f * v;
                        at_most(*e);
                    }
                } else {
                    seg.iter().for_each(|&e| at_most(e));
                }
            }
            self.spans[j] = span;
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Three rows on bodies 0, 1, 2 (21 columns): the pivot row has no entry on body 2.
    fn three_rows() -> (Rows, usize, usize) {
        let (m, n) = (3, 21);
        let mut t = Vec::new();
        for c in [0, 1, 3, 8, 10] {
            t.push((0, c, 1.0 + c as f64));
        }
        for c in [0, 2, 9, 15, 20] {
            t.push((1, c, -2.0 - c as f64));
        }
        for c in [1, 4, 16] {
            t.push((2, c, 0.5 * c as f64));
        }
        let rows = Rows::new(m, n, &t, &[1.0; 3], &[1.0; 21]).unwrap();
        (rows, m, n)
    }

    #[test]
    fn pivot_leaves_the_bodies_the_pivot_row_misses_and_keeps_their_maximum() {
        let (rows, m, n) = three_rows();
        let mut changed = Changed::new(m, n / 7);
        let mut block = Block::default();
        let mut active = vec![true; m];
        block.load(0, &[0, 1, 2], &active, &rows, &changed);
        let before = block.a.clone();
        let w = block.w;
        block.pivot(0, 0, &mut active, 1e-12);
        // Row 1: `a_1 ← a_1 − (a_10 / a_00) a_0` where row 0 is nonzero, as it was elsewhere.
        let f = -2.0 / 1.0;
        for (l, (&new, &old)) in block.a[w..2 * w].iter().zip(&before[..w]).enumerate() {
            let was = before[w + l];
            let want = if l == 0 { 0.0 } else { was - f * old };
            let body = block.bodies[l / 7];
            if body == 2 {
                assert_eq!(new, was, "column {l}: body 2 untouched");
            } else {
                assert_eq!(new, want, "column {l}");
            }
        }
        // Its maximum counts the untouched body 2 (|−22| at column 20, the row's largest).
        let max = block.a[w..2 * w]
            .iter()
            .fold(0.0f64, |a, &x| a.max(x.abs()));
        assert_eq!(block.rmax[1], max);
        assert_eq!(max, 22.0);
        // Row 2 has no entry in column 0: unchanged.
        assert_eq!(block.a[2 * w..], before[2 * w..]);
        assert!(!active[0] && active[1] && active[2]);
        // Kept twice (a new copy the second time): the last copy is read, each row reached
        // once per body in `touching`.
        block.keep(&mut changed);
        block.keep(&mut changed);
        let (bodies, values, rmax) = changed.get(1).unwrap();
        assert_eq!(rmax, 22.0);
        let slot1 = block.bodies.iter().position(|&b| b == 1).unwrap();
        let at = bodies.iter().position(|&b| b == 1).unwrap();
        assert_eq!(
            values[7 * at..7 * at + 7],
            block.a[w + 7 * slot1..w + 7 * slot1 + 7]
        );
        assert!(changed.get(0).is_none());
        let mut cands = vec![0];
        changed.touching(2, &mut cands);
        assert_eq!(cands, [0, 1, 2]);
        cands.clear();
        changed.touching(2, &mut cands);
        assert!(cands.is_empty(), "a body's reached rows are taken once");
    }
}
