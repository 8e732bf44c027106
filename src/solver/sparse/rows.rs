//! The rows of `D Φ_q S` as the solver's sparse partition builds them, in one pass over the
//! Jacobian's triplets (grouped by ascending row): row `r`'s scaled entries
//! `a_rc = row_scale[r] · v · scale[c]` (duplicates summed in triplet order, zeros dropped; in
//! the order of their first nonzero term, which no reader depends on), with what the
//! elimination of module `fill_free` reads of them: each row's largest entry `max_c |a_rc|`, the
//! rows touching each body, the body of each row lying on one body alone and its reach there
//! (its largest entry in the translation columns and in the Euler-parameter columns).

use crate::constraints::Triplet;

/// The expanded rows: row `r` is `entries[at[r]..at[r + 1]]`.
pub(crate) struct Rows {
    pub(crate) entries: Vec<(usize, f64)>,
    pub(crate) at: Vec<usize>,
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
    /// The bodies of each row's runs of entries on one body: `runs[run_at[r]..run_at[r + 1]]`.
    runs: Vec<usize>,
    run_at: Vec<usize>,
}

impl Rows {
    /// The rows of the `m × n` triplets `entries` with their scales, `None` unless the
    /// triplets are grouped by ascending row and inside the matrix.
    pub(crate) fn new(
        m: usize,
        n: usize,
        entries: &[Triplet],
        row_scale: &[f64],
        scale: &[f64],
    ) -> Option<Self> {
        let nb = n / 7;
        let mut out: Vec<(usize, f64)> = Vec::with_capacity(entries.len());
        let mut at = Vec::with_capacity(m + 1);
        at.push(0);
        // Where column `c` sits in the row being expanded: `(row, position in out)`.
        let mut seen = vec![(usize::MAX, 0usize); n];
        let mut rmax = vec![0.0f64; m];
        let mut own_of = vec![usize::MAX; m];
        let mut reach = vec![[0.0f64; 2]; m];
        // The bodies of each row's runs of entries (`runs[run_at[r]..run_at[r + 1]]`), counted
        // by body in `body_start`.
        let mut runs = Vec::with_capacity(2 * m);
        let mut run_at = Vec::with_capacity(m + 1);
        run_at.push(0);
        let mut body_start = vec![0usize; nb + 1];
        let mut rest = entries;
        for r in 0..m {
            let len = rest.iter().take_while(|e| e.0 as usize == r).count();
            let (seg, tail) = rest.split_at(len);
            rest = tail;
            let start = out.len();
            let row_scale = row_scale[r];
            // Zeros skipped (`x + 0 = x`: a sum keeps its value without them), duplicates
            // summed in triplet order; the largest entry and the runs by body as they come
            // (`c` in `lo..hi` on the last run's body).
            let (mut summed, mut max) = (false, 0.0f64);
            let (mut lo, mut hi) = (usize::MAX, 0);
            for &(_, c, v) in seg {
                let c = c as usize;
                if c >= n {
                    return None;
                }
                let a = v * row_scale * scale[c];
                if a == 0.0 {
                    continue;
                }
                let s = &mut seen[c];
                if s.0 == r {
                    out[s.1].1 += a;
                    summed = true;
                    continue;
                }
                *s = (r, out.len());
                out.push((c, a));
                // `max_c |a_rc|` as `fold(0, f64::max)` gives it (NaN ignored).
                if a.abs() > max {
                    max = a.abs();
                }
                if c < lo || c >= hi {
                    lo = c - c % 7;
                    hi = lo + 7;
                    runs.push(c / 7);
                    body_start[c / 7 + 1] += 1;
                }
            }
            if summed {
                // Counted again without the sums that cancelled (the order kept).
                for &body in &runs[run_at[r]..] {
                    body_start[body + 1] -= 1;
                }
                runs.truncate(run_at[r]);
                let (mut kept, mut last) = (start, usize::MAX);
                max = 0.0;
                for i in start..out.len() {
                    let e = out[i];
                    if e.1 != 0.0 {
                        out[kept] = e;
                        kept += 1;
                        max = max.max(e.1.abs());
                        if e.0 / 7 != last {
                            last = e.0 / 7;
                            runs.push(last);
                            body_start[last + 1] += 1;
                        }
                    }
                }
                out.truncate(kept);
            }
            at.push(out.len());
            rmax[r] = max;
            let first_run = run_at[r];
            run_at.push(runs.len());
            // A row on one body alone (its entries in one run, or in several on that body).
            if let Some(&body) = runs.get(first_run) {
                if runs[first_run..].iter().all(|&x| x == body) {
                    own_of[r] = body;
                    for &(c, v) in &out[start..] {
                        let kind = usize::from(c % 7 >= 3);
                        reach[r][kind] = reach[r][kind].max(v.abs());
                    }
                }
            }
        }
        // Triplets left over: a row out of order or beyond `m`.
        if !rest.is_empty() {
            return None;
        }
        for b in 0..nb {
            body_start[b + 1] += body_start[b];
        }
        let mut body_rows = vec![usize::MAX; body_start[nb]];
        let mut fill = body_start.clone();
        for r in 0..m {
            for &body in &runs[run_at[r]..run_at[r + 1]] {
                body_rows[fill[body]] = r;
                fill[body] += 1;
            }
        }
        Some(Rows {
            entries: out,
            at,
            rmax,
            own_of,
            reach,
            body_start,
            body_rows,
            runs,
            run_at,
        })
    }

    /// Row `r`'s entries.
    pub(crate) fn row(&self, r: usize) -> &[(usize, f64)] {
        &self.entries[self.at[r]..self.at[r + 1]]
    }

    /// The bodies row `r` touches (a body once per run of its entries there).
    pub(crate) fn bodies(&self, r: usize) -> &[usize] {
        &self.runs[self.run_at[r]..self.run_at[r + 1]]
    }

    /// The rows touching body `b`, each once (ascending).
    pub(crate) fn touching(&self, b: usize, out: &mut Vec<usize>) {
        out.clear();
        out.extend_from_slice(&self.body_rows[self.body_start[b]..self.body_start[b + 1]]);
        out.dedup();
    }
}
