//! Coordinate partitioning of a sparse `Φ_q` by Gaussian elimination with threshold pivoting
//! restricted to one body's columns at a time.
//!
//! The dense partition (`solver::partition`) looks for the largest entry of the whole remaining
//! matrix at every step: `O(m n)` per pivot, `O(m² n)` in all. Here the scaled Jacobian
//! `D Φ_q S` is kept as sparse rows and the bodies are eliminated in an order that keeps the
//! fill local: deepest first in a breadth-first search from the ground over all joints (leaves
//! before their parents). At body `b`, among the active rows with entries in `b`'s free columns,
//! the pivot is the largest entry `|a_rc|` that also passes the threshold test
//! `|a_rc| ≥ τ max_k |a_rk|` (τ = 0.1: the pivot is not small against the rest of its row); its
//! column becomes a dependent coordinate, its row an independent row, and it is eliminated from
//! the other active rows, `a_i ← a_i − (a_ic / a_rc) a_r`. Up to seven pivots are taken per
//! body, then (second pass) the rows that started on that body alone (a contact's gap, a stop)
//! on the body's free entry largest against the row's *reach* `ρ_r`, the largest of its
//! starting entries on that body in columns of the same kind (translations or Euler
//! parameters), if `|a_rc| ≥ τ₂ ρ_r` (τ₂ = 0.5): the joint rows pivoted before them move their
//! large entries onto the parent, and left for later they would carry that fill up the whole
//! chain (one dense row per contact). The entry left on the body is the lever of the body's
//! free joint motion on the row (`l cos φ` for a contact at the end of a link of length `l`,
//! `φ` off the horizontal), which vanishes as the link turns vertical: a row that fails the
//! test there goes on to the bodies its fill has reached and is tried again at each (up a
//! chain, with each link's own lever: the coordinates are absolute, so the links below keep
//! their orientation), else in the final full pivoting, on its largest entry. Such a
//! partition lists these choices (`Partition::second_pass`): the minimizer re-partitions
//! when a step changes them. A row whose entries all fall below
//! `RANK_TOLERANCE · max|D Φ_q S|` is redundant. Rows
//! left at the end (loop rows whose bodies were all eliminated) are finished by full pivoting
//! among themselves.
//!
//! For a tree, listing each body's joint rows and normalization row in child-before-parent order
//! makes `Φ_u` block triangular with the 6 × 6 (or smaller) pivot block of each body on its
//! diagonal: no fill at all and `O(N)` work. A closed loop's rows fill in only along the bodies
//! of the loop that are eliminated after them.

use super::super::partition::{Partition, RANK_TOLERANCE};
use crate::constraints::Triplet;
use crate::model::Model;

/// Threshold of the pivot test against the largest entry of its row.
pub(crate) const THRESHOLD: f64 = 0.1;

/// Threshold of the second pass's pivot test against the row's reach on its own body.
pub(crate) const OWN_THRESHOLD: f64 = 0.5;

/// The bodies in elimination order: descending breadth-first depth from the ground over all
/// joints (ties: higher index first); bodies not connected to the ground come last.
pub(crate) fn elimination_order(model: &Model) -> Vec<usize> {
    let nb = model.bodies.len();
    let mut adjacent = vec![Vec::new(); nb];
    let mut depth = vec![usize::MAX; nb];
    let mut queue = std::collections::VecDeque::new();
    for j in model.joints.iter().filter(|j| !j.merged) {
        match (j.bodies[0], j.bodies[1]) {
            (Some(a), Some(b)) => {
                adjacent[a.0].push(b.0);
                adjacent[b.0].push(a.0);
            }
            (Some(a), None) | (None, Some(a)) => {
                if depth[a.0] == usize::MAX {
                    depth[a.0] = 1;
                    queue.push_back(a.0);
                }
            }
            (None, None) => {}
        }
    }
    while let Some(b) = queue.pop_front() {
        for &c in &adjacent[b] {
            if depth[c] == usize::MAX {
                depth[c] = depth[b] + 1;
                queue.push_back(c);
            }
        }
    }
    let mut order: Vec<usize> = (0..nb).collect();
    order.sort_by_key(|&b| {
        (
            std::cmp::Reverse(if depth[b] == usize::MAX { 0 } else { depth[b] }),
            std::cmp::Reverse(b),
        )
    });
    order
}

/// The elimination state: active sparse rows and which rows touch which body.
struct Elimination {
    rows: Vec<Vec<(usize, f64)>>,
    active: Vec<bool>,
    free: Vec<bool>,
    /// Rows that have (or had) entries in a body's columns; may hold stale entries.
    body_rows: Vec<Vec<usize>>,
    tol: f64,
    dependent: Vec<usize>,
    pivot_rows: Vec<usize>,
    redundant: Vec<usize>,
    /// Scratch of [`Elimination::pivot`]: the position of each column in the row being
    /// updated (`u32::MAX`: absent), reset after each row.
    pos: Vec<u32>,
    /// `row_max(r)` of every row, kept current as the rows change (in [`Elimination::pivot`]).
    rmax: Vec<f64>,
}

impl Elimination {
    fn row_max(&self, r: usize) -> f64 {
        self.rows[r].iter().fold(0.0, |a, &(_, v)| a.max(v.abs()))
    }

    /// Pivots on `(r, c)`: eliminates column `c` from every other active row.
    fn pivot(&mut self, r: usize, c: usize) {
        self.active[r] = false;
        self.free[c] = false;
        self.dependent.push(c);
        self.pivot_rows.push(r);
        let pivot_row = std::mem::take(&mut self.rows[r]);
        let a_rc = pivot_row.iter().find(|e| e.0 == c).map_or(0.0, |e| e.1);
        let mut touched = std::mem::take(&mut self.body_rows[c / 7]);
        touched.sort_unstable();
        touched.dedup();
        for &i in &touched {
            if !self.active[i] {
                continue;
            }
            let Some(k) = self.rows[i].iter().position(|e| e.0 == c) else {
                continue;
            };
            let f = self.rows[i][k].1 / a_rc;
            self.rows[i].swap_remove(k);
            // A row's columns are distinct: the position map finds the entry a search would.
            let (row, pos) = (&mut self.rows[i], &mut self.pos);
            for (j, e) in row.iter().enumerate() {
                pos[e.0] = j as u32;
            }
            for &(col, v) in &pivot_row {
                if col == c {
                    continue;
                }
                match pos[col] {
                    u32::MAX => {
                        pos[col] = row.len() as u32;
                        row.push((col, -f * v));
                        self.body_rows[col / 7].push(i);
                    }
                    j => row[j as usize].1 -= f * v,
                }
            }
            for e in row.iter() {
                pos[e.0] = u32::MAX;
            }
            self.rmax[i] = self.row_max(i);
            if self.rmax[i] <= self.tol {
                self.active[i] = false;
                self.redundant.push(i);
            }
        }
        touched.retain(|&i| self.active[i]);
        self.body_rows[c / 7] = touched;
        self.rows[r] = pivot_row;
    }

    /// The best threshold-passing pivot among active rows `cands` in the free columns `cols`
    /// (`entries`: scratch).
    fn best_pivot(
        &self,
        cands: &[usize],
        threshold: f64,
        cols: impl Fn(usize) -> bool,
        entries: &mut Vec<(usize, f64)>,
    ) -> Option<(usize, usize)> {
        let mut best: Option<(usize, usize, f64)> = None;
        for &r in cands {
            if !self.active[r] {
                continue;
            }
            let rmax = self.rmax[r];
            entries.clear();
            entries.extend(
                self.rows[r]
                    .iter()
                    .copied()
                    .filter(|&(c, _)| self.free[c] && cols(c)),
            );
            entries.sort_unstable_by_key(|e| e.0);
            for &(c, v) in entries.iter() {
                let a = v.abs();
                if a > self.tol
                    && a >= threshold * rmax
                    && best.is_none_or(|b| a > b.2 * (1.0 + 1e-9))
                {
                    best = Some((r, c, a));
                }
            }
        }
        best.map(|(r, c, _)| (r, c))
    }
}

impl Elimination {
    /// Row `r`'s entries on the free columns of body `b`, by column offset `c − 7 b`, and the
    /// mask of the offsets present (a row's columns are distinct): the entries a filter and
    /// a sort by column would list, in that order.
    fn on_body(&self, r: usize, b: usize) -> ([f64; 7], u8) {
        let (mut vals, mut mask) = ([0.0; 7], 0u8);
        for &(c, v) in &self.rows[r] {
            let k = c.wrapping_sub(7 * b);
            if k < 7 && self.free[c] {
                vals[k] = v;
                mask |= 1 << k;
            }
        }
        (vals, mask)
    }

    /// [`Elimination::best_pivot`] in the free columns of body `b` (same test, same order).
    fn best_pivot_at(&self, cands: &[usize], threshold: f64, b: usize) -> Option<(usize, usize)> {
        let mut best: Option<(usize, usize, f64)> = None;
        for &r in cands {
            if !self.active[r] {
                continue;
            }
            let rmax = self.rmax[r];
            // No entry of the row exceeds `rmax`: a row whose `rmax` cannot beat the best so
            // far is not read (the same choice as reading it).
            if best.is_some_and(|x| rmax <= x.2 * (1.0 + 1e-9)) {
                continue;
            }
            let (vals, mask) = self.on_body(r, b);
            for k in (0..7).filter(|k| mask & (1 << k) != 0) {
                let a = vals[k].abs();
                if a > self.tol
                    && a >= threshold * rmax
                    && best.is_none_or(|x| a > x.2 * (1.0 + 1e-9))
                {
                    best = Some((r, 7 * b + k, a));
                }
            }
        }
        best.map(|(r, c, _)| (r, c))
    }
}

impl Elimination {
    /// The second pass's pivot at body `b` among the rows `cands` that started on one body:
    /// the entry on a free column of `b` largest relative to the row's `reach` on its own body
    /// in columns of the same kind (translations, Euler parameters), if at least `OWN_THRESHOLD`
    /// of it.
    fn best_own_pivot(
        &self,
        cands: &[usize],
        b: usize,
        reach: &[[f64; 2]],
    ) -> Option<(usize, usize)> {
        let mut best: Option<(usize, usize, f64)> = None;
        for &r in cands {
            if !self.active[r] {
                continue;
            }
            let (vals, mask) = self.on_body(r, b);
            for k in (0..7).filter(|k| mask & (1 << k) != 0) {
                let (c, v) = (7 * b + k, vals[k]);
                let reference = reach[r][usize::from(c % 7 >= 3)];
                let ratio = v.abs() / reference.max(f64::MIN_POSITIVE);
                if v.abs() > self.tol
                    && ratio >= OWN_THRESHOLD
                    && best.is_none_or(|x| ratio > x.2 * (1.0 + 1e-9))
                {
                    best = Some((r, c, ratio));
                }
            }
        }
        best.map(|(r, c, _)| (r, c))
    }
}

/// Partitions the Jacobian given as triplets (`(row, col, value)`, duplicates summed) of an
/// `m × n` matrix, with row scales `row_scale` and column scales `scale`.
pub(crate) fn partition(
    model: &Model,
    m: usize,
    n: usize,
    entries: &[Triplet],
    row_scale: &[f64],
    scale: &[f64],
) -> Partition {
    let nb = n / 7;
    // Each row allocated once, at its number of entries (no regrowth on trees, and no room
    // beyond: on 10,000 links the rows are tens of megabytes, first touched page by page).
    let mut count = vec![0usize; m];
    for &(r, _, _) in entries {
        count[r as usize] += 1;
    }
    let mut rows: Vec<Vec<(usize, f64)>> = count.iter().map(|&k| Vec::with_capacity(k)).collect();
    // Duplicates summed in the order they come, found through the position of each column in
    // the row being filled (`pos`; the triplets come row by row, and a row met again later is
    // mapped afresh): the sums a search of the row would make, without the search.
    let mut pos = vec![u32::MAX; n];
    let mut current = usize::MAX;
    for &(r, c, v) in entries {
        let (r, c) = (r as usize, c as usize);
        let a = v * row_scale[r] * scale[c];
        if r != current {
            if let Some(row) = rows.get(current) {
                row.iter().for_each(|e| pos[e.0] = u32::MAX);
            }
            current = r;
            for (j, e) in rows[r].iter().enumerate() {
                pos[e.0] = j as u32;
            }
        }
        match pos[c] {
            u32::MAX => {
                pos[c] = rows[r].len() as u32;
                rows[r].push((c, a));
            }
            j => rows[r][j as usize].1 += a,
        }
    }
    if let Some(row) = rows.get(current) {
        row.iter().for_each(|e| pos[e.0] = u32::MAX);
    }
    for row in &mut rows {
        row.retain(|e| e.1 != 0.0);
    }
    let amax = rows.iter().flatten().fold(0.0f64, |a, e| a.max(e.1.abs()));
    let mut body_rows = vec![Vec::new(); nb];
    for (r, row) in rows.iter().enumerate() {
        for &(c, _) in row {
            // Once per run of a row's entries on one body (readers sort and deduplicate).
            if body_rows[c / 7].last() != Some(&r) {
                body_rows[c / 7].push(r);
            }
        }
    }
    let tol = (RANK_TOLERANCE * amax).max(f64::MIN_POSITIVE);
    let mut el = Elimination {
        active: rows.iter().map(|r| !r.is_empty()).collect(),
        redundant: (0..m).filter(|&r| rows[r].is_empty()).collect(),
        rows,
        free: vec![true; n],
        body_rows,
        tol,
        dependent: Vec::new(),
        pivot_rows: Vec::new(),
        pos,
        rmax: Vec::new(),
    };
    el.rmax = (0..m).map(|r| el.row_max(r)).collect();
    for r in 0..m {
        if el.active[r] && el.rmax[r] <= tol {
            el.active[r] = false;
            el.redundant.push(r);
        }
    }
    // Rows whose entries all lie on one body (their "own" body), and the size of their
    // entries there, per kind of column (translations, Euler parameters).
    let mut own: Vec<Vec<usize>> = vec![Vec::new(); nb];
    let mut reach = vec![[0.0f64; 2]; m];
    for (r, row) in el.rows.iter().enumerate() {
        if let Some(&(c0, _)) = row.first() {
            if el.active[r] && row.iter().all(|e| e.0 / 7 == c0 / 7) {
                own[c0 / 7].push(r);
                for &(c, v) in row {
                    let k = usize::from(c % 7 >= 3);
                    reach[r][k] = reach[r][k].max(v.abs());
                }
            }
        }
    }
    // The rows pivoted in the second pass and the bodies they were pivoted at, and the rows
    // carried on and the bodies that refused them.
    let mut second_pass = Vec::new();
    let (mut cands, mut entries) = (Vec::new(), Vec::new());
    for b in elimination_order(model) {
        let mut taken = 0;
        // The rows on `b` once: a pivot at `b` leaves there the active ones among them
        // (`Elimination::pivot`), which the search below skips when inactive.
        cands.clear();
        cands.extend_from_slice(&el.body_rows[b]);
        cands.sort_unstable();
        cands.dedup();
        while taken < 7 {
            match el.best_pivot_at(&cands, THRESHOLD, b) {
                Some((r, c)) => el.pivot(r, c),
                None => break,
            }
            taken += 1;
        }
        // Second pass: a row that started on body `b` alone (a contact's gap, a stop) but lost
        // its large entries to the joint rows pivoted before it now reaches the parent bodies
        // through that fill, with entries there far larger than the one left on `b` (the lever
        // arm of the contact point about the joint). Left for later it would carry the fill
        // up the whole chain: one dense row per contact, O(N²) work and an LDLᵀ of the KKT
        // system with O(N²) fill. It is pivoted here on `b`'s free entry largest against its
        // reach, if at least `OWN_THRESHOLD` of it: like a joint row, it is eliminated with its
        // body, and the dependent coordinate it takes (the joint angle that keeps the contact
        // point on the ground) is well determined by it. A pivot on a small lever (a link near
        // vertical above its contact) would leave `Φ_u` nearly singular and fold the manifold
        // over `v` within a fraction of the link's length: the corrector then fails on all but
        // tiny steps.
        while taken < 7 {
            match el.best_own_pivot(&own[b], b, &reach) {
                Some((r, c)) => {
                    el.pivot(r, c);
                    second_pass.push((r, b, true));
                }
                None => break,
            }
            taken += 1;
        }
        // A row whose entry on `b` is too small against its reach (a contact point straight
        // below the joint of a vertical link) goes on to the bodies its fill reached. (A row
        // left without entries on `b`'s free columns, all taken by the first pass, stays
        // where it is, for the first pass at other bodies or the final full pivoting.)
        for r in std::mem::take(&mut own[b]) {
            let on_b = |&(c, v): &(usize, f64)| c / 7 == b && el.free[c] && v.abs() > el.tol;
            if !el.active[r] || !el.rows[r].iter().any(on_b) {
                continue;
            }
            second_pass.push((r, b, false));
            let mut bodies: Vec<usize> = el.rows[r].iter().map(|e| e.0 / 7).collect();
            bodies.sort_unstable();
            bodies.dedup();
            for a in bodies.into_iter().filter(|&a| a != b) {
                own[a].push(r);
            }
        }
    }
    // Rows left over: full pivoting among them over all free columns.
    let mut left: Vec<usize> = (0..m).filter(|&r| el.active[r]).collect();
    loop {
        left.retain(|&r| el.active[r]);
        if left.is_empty() {
            break;
        }
        match el.best_pivot(&left, THRESHOLD, |_| true, &mut entries) {
            Some((r, c)) => el.pivot(r, c),
            None => {
                // No entry passes the threshold test: plain full pivoting.
                let mut best: Option<(usize, usize, f64)> = None;
                for &r in &left {
                    for &(c, v) in &el.rows[r] {
                        if el.free[c] && best.is_none_or(|b| v.abs() > b.2) {
                            best = Some((r, c, v.abs()));
                        }
                    }
                }
                match best {
                    Some((r, c, a)) if a > tol => el.pivot(r, c),
                    _ => {
                        for &r in &left {
                            el.active[r] = false;
                            el.redundant.push(r);
                        }
                    }
                }
            }
        }
    }
    let mut independent: Vec<usize> = (0..n).filter(|&c| el.free[c]).collect();
    independent.sort_unstable();
    el.redundant.sort_unstable();
    Partition {
        id: super::super::partition::next_id(),
        dependent: el.dependent,
        independent,
        rows: el.pivot_rows,
        redundant: el.redundant,
        second_pass: {
            second_pass.sort_unstable();
            second_pass
        },
    }
}
