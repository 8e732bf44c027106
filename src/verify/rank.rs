//! `check`'s degrees of freedom `n − rank(D Φ_q S)` without the general sparse partition when
//! the elimination has no fill between bodies (trees): the same pivots, the same arithmetic,
//! on a few rows at a time.
//!
//! The solver's sparse partition (`solver::sparse::partition`) eliminates the bodies in its
//! order (deepest first); at body `b` it pivots up to seven times on the largest threshold-
//! passing entry `|a_rc| ≥ τ max_k |a_rk|` (τ = 0.1) of `b`'s free columns among the active
//! rows touching `b`, eliminating `a_i ← a_i − (a_ic / a_rc) a_r` from the other rows touching
//! `b`, then pivots the rows that started on `b` alone on the free entry of `b` largest against
//! the row's reach there (its largest starting entry on `b` in columns of the same kind), if at
//! least `OWN_THRESHOLD` of it.
//! When every row touching `b` is a pivot row or redundant after that, the rows changed there
//! are never read again: `b`'s step depends only on the original entries of its own rows. This
//! module repeats exactly those steps body by body on copies of the rows touching `b` (so the
//! same pivots are chosen, in the same order, with the same floating-point operations on every
//! entry), and gives up (`None`) at the first body where a row touching it stays active (a
//! loop's rows, which carry fill to other bodies): the caller then runs the full partition.
//! The number of free columns left, `n − pivots`, is the partition's `independent.len()`; a
//! test checks both agree on every model of the test set.

use crate::model::Model;
use crate::solver::partition::RANK_TOLERANCE;
use crate::solver::sparse::partition::{elimination_order, OWN_THRESHOLD, THRESHOLD};

/// The rows of a Jacobian whose triplets are grouped by row: row `r` is
/// `entries[start[r]..start[r + 1]]`, expanded on demand with its scales.
struct Rows<'e> {
    entries: &'e [(usize, usize, f64)],
    start: Vec<usize>,
    row_scale: &'e [f64],
    scale: &'e [f64],
    /// Where column `c` sits in the row being expanded: `(expansion, position)`.
    seen: Vec<(usize, usize)>,
    expansion: usize,
}

impl<'e> Rows<'e> {
    /// The rows of `entries`, `None` unless they are grouped by ascending row.
    fn new(
        m: usize,
        n: usize,
        entries: &'e [(usize, usize, f64)],
        row_scale: &'e [f64],
        scale: &'e [f64],
    ) -> Option<Self> {
        let mut start = vec![0usize; m + 1];
        let mut last = 0;
        for (k, &(r, c, _)) in entries.iter().enumerate() {
            if r < last || r >= m || c >= n {
                return None;
            }
            for s in &mut start[last + 1..=r] {
                *s = k;
            }
            last = r;
        }
        for s in &mut start[last + 1..] {
            *s = entries.len();
        }
        Some(Rows {
            entries,
            start,
            row_scale,
            scale,
            seen: vec![(usize::MAX, 0); n],
            expansion: 0,
        })
    }

    /// Row `r` into `out` as the partition builds it: the scaled entries
    /// `row_scale[r] · v · scale[c]`, duplicates summed in triplet order into the first one,
    /// zeros dropped, the others in triplet order.
    fn expand(&mut self, r: usize, out: &mut Vec<(usize, f64)>) {
        out.clear();
        self.expansion += 1;
        for &(_, c, v) in &self.entries[self.start[r]..self.start[r + 1]] {
            let a = v * self.row_scale[r] * self.scale[c];
            if self.seen[c].0 == self.expansion {
                out[self.seen[c].1].1 += a;
            } else {
                self.seen[c] = (self.expansion, out.len());
                out.push((c, a));
            }
        }
        out.retain(|e| e.1 != 0.0);
    }
}

/// The elimination at one body: copies of its rows (`slot[i]` is row `cands[i]`).
struct Local {
    cands: Vec<usize>,
    rows: Vec<Vec<(usize, f64)>>,
    /// Scratch: one row's entries in the body's free columns.
    entries: Vec<(usize, f64)>,
}

fn row_max(row: &[(usize, f64)]) -> f64 {
    row.iter().fold(0.0, |a, &(_, v)| a.max(v.abs()))
}

/// The number of free columns `n − rank` the sparse partition leaves for the `m × n` Jacobian
/// `entries` with row and column scales, or `None` if the elimination has fill between bodies
/// (then only the partition itself gives it).
pub(super) fn free_columns(
    model: &Model,
    m: usize,
    n: usize,
    entries: &[(usize, usize, f64)],
    row_scale: &[f64],
    scale: &[f64],
) -> Option<usize> {
    let nb = n / 7;
    let mut rows = Rows::new(m, n, entries, row_scale, scale)?;
    let mut row = Vec::with_capacity(14);
    // Every row expanded once, kept row after row (`expanded[at[r]..at[r + 1]]`): the passes
    // below and each body's copies read it instead of expanding again.
    let mut expanded: Vec<(usize, f64)> = Vec::with_capacity(entries.len());
    let mut at = Vec::with_capacity(m + 1);
    at.push(0);
    // Each row's largest entry; the rows touching each body (ascending, each once, counted
    // then filled); the body of the rows lying on one body alone.
    let mut rmax = vec![0.0f64; m];
    let mut body_start = vec![0usize; nb + 1];
    let mut own_of = vec![usize::MAX; m];
    let mut reach = vec![[0.0f64; 2]; m];
    for r in 0..m {
        rows.expand(r, &mut row);
        expanded.extend_from_slice(&row);
        at.push(expanded.len());
        rmax[r] = row_max(&row);
        let mut last = usize::MAX;
        for &(c, _) in &row {
            if c / 7 != last {
                last = c / 7;
                body_start[last + 1] += 1;
            }
        }
        if let Some(&(c0, _)) = row.first() {
            if row.iter().all(|e| e.0 / 7 == c0 / 7) {
                own_of[r] = c0 / 7;
                for &(c, v) in &row {
                    let k = usize::from(c % 7 >= 3);
                    reach[r][k] = reach[r][k].max(v.abs());
                }
            }
        }
    }
    let amax = rmax.iter().fold(0.0f64, |a, &x| a.max(x));
    let tol = (RANK_TOLERANCE * amax).max(f64::MIN_POSITIVE);
    let mut active: Vec<bool> = rmax.iter().map(|&x| x > tol).collect();
    for (r, o) in own_of.iter_mut().enumerate() {
        if !active[r] {
            *o = usize::MAX;
        }
    }
    for b in 0..nb {
        body_start[b + 1] += body_start[b];
    }
    let mut body_rows = vec![usize::MAX; body_start[nb]];
    let mut body_fill = body_start.clone();
    for r in 0..m {
        let mut last = usize::MAX;
        for &(c, _) in &expanded[at[r]..at[r + 1]] {
            if c / 7 != last {
                last = c / 7;
                body_rows[body_fill[last]] = r;
                body_fill[last] += 1;
            }
        }
    }
    let mut free = vec![true; n];
    let mut pivots = 0usize;
    let mut local = Local {
        cands: Vec::new(),
        rows: Vec::new(),
        entries: Vec::with_capacity(14),
    };
    let (mut all, mut own) = (Vec::new(), Vec::new());
    for b in elimination_order(model) {
        local.cands.clear();
        local
            .cands
            .extend_from_slice(&body_rows[body_start[b]..body_fill[b]]);
        local.cands.dedup();
        let k = local.cands.len();
        if local.rows.len() < k {
            local.rows.resize_with(k, Vec::new);
        }
        for (slot, &r) in local.cands.iter().enumerate() {
            let copy = &mut local.rows[slot];
            copy.clear();
            copy.extend_from_slice(&expanded[at[r]..at[r + 1]]);
        }
        let in_b = |c: usize| c / 7 == b;
        all.clear();
        all.extend(0..k);
        let mut taken = 0;
        while taken < 7 {
            match best_pivot(&mut local, &all, &active, &free, tol, in_b) {
                Some((slot, c)) => pivot(&mut local, slot, c, &mut active, &mut free, tol),
                None => break,
            }
            pivots += 1;
            taken += 1;
        }
        own.clear();
        own.extend((0..k).filter(|&s| own_of[local.cands[s]] == b));
        while taken < 7 {
            match best_own_pivot(&mut local, &own, &active, &free, tol, b, &reach) {
                Some((slot, c)) => pivot(&mut local, slot, c, &mut active, &mut free, tol),
                None => break,
            }
            pivots += 1;
            taken += 1;
        }
        if local.cands.iter().any(|&r| active[r]) {
            return None;
        }
    }
    if active.iter().any(|&a| a) {
        return None;
    }
    Some(n - pivots)
}

/// The partition's pivot choice among the rows at `slots` (ascending) in the free columns
/// `cols`: the largest `|a_rc| > tol` with `|a_rc| ≥ THRESHOLD · max_k |a_rk|`, a later one
/// only if larger by a relative `1e-9`.
fn best_pivot(
    local: &mut Local,
    slots: &[usize],
    active: &[bool],
    free: &[bool],
    tol: f64,
    cols: impl Fn(usize) -> bool,
) -> Option<(usize, usize)> {
    let mut best: Option<(usize, usize, f64)> = None;
    let entries = &mut local.entries;
    for &s in slots {
        if !active[local.cands[s]] {
            continue;
        }
        let row = &local.rows[s];
        let rmax = row_max(row);
        entries.clear();
        entries.extend(row.iter().copied().filter(|&(c, _)| free[c] && cols(c)));
        entries.sort_unstable_by_key(|e| e.0);
        for &(c, v) in entries.iter() {
            let a = v.abs();
            if a > tol && a >= THRESHOLD * rmax && best.is_none_or(|b| a > b.2 * (1.0 + 1e-9)) {
                best = Some((s, c, a));
            }
        }
    }
    best.map(|(s, c, _)| (s, c))
}

/// The partition's second-pass pivot at body `b` among the rows at `slots` (ascending) that
/// started on `b` alone: the entry on a free column of `b` largest relative to the row's
/// `reach` there (same kind of column), if at least `OWN_THRESHOLD` of it; a later one only
/// if larger by a relative `1e-9`.
fn best_own_pivot(
    local: &mut Local,
    slots: &[usize],
    active: &[bool],
    free: &[bool],
    tol: f64,
    b: usize,
    reach: &[[f64; 2]],
) -> Option<(usize, usize)> {
    let mut best: Option<(usize, usize, f64)> = None;
    let entries = &mut local.entries;
    for &s in slots {
        let r = local.cands[s];
        if !active[r] {
            continue;
        }
        entries.clear();
        entries.extend(
            local.rows[s]
                .iter()
                .copied()
                .filter(|&(c, _)| free[c] && c / 7 == b),
        );
        entries.sort_unstable_by_key(|e| e.0);
        for &(c, v) in entries.iter() {
            let ratio = v.abs() / reach[r][usize::from(c % 7 >= 3)].max(f64::MIN_POSITIVE);
            if v.abs() > tol
                && ratio >= OWN_THRESHOLD
                && best.is_none_or(|x| ratio > x.2 * (1.0 + 1e-9))
            {
                best = Some((s, c, ratio));
            }
        }
    }
    best.map(|(s, c, _)| (s, c))
}

/// The partition's pivot on `(slot, c)`: column `c` eliminated from the other active rows.
fn pivot(
    local: &mut Local,
    slot: usize,
    c: usize,
    active: &mut [bool],
    free: &mut [bool],
    tol: f64,
) {
    active[local.cands[slot]] = false;
    free[c] = false;
    let pivot_row = std::mem::take(&mut local.rows[slot]);
    let a_rc = pivot_row.iter().find(|e| e.0 == c).map_or(0.0, |e| e.1);
    for s in 0..local.cands.len() {
        if !active[local.cands[s]] {
            continue;
        }
        let row = &mut local.rows[s];
        let Some(k) = row.iter().position(|e| e.0 == c) else {
            continue;
        };
        let f = row[k].1 / a_rc;
        row.swap_remove(k);
        for &(col, v) in &pivot_row {
            if col == c {
                continue;
            }
            match row.iter_mut().find(|e| e.0 == col) {
                Some(e) => e.1 -= f * v,
                None => row.push((col, -f * v)),
            }
        }
        if row_max(row) <= tol {
            active[local.cands[s]] = false;
        }
    }
    local.rows[slot] = pivot_row;
}

#[cfg(test)]
mod tests {
    use crate::constraints::Constraints;
    use crate::solver::system::{Backend, System};
    use crate::urdf::{load_str, ImportOptions};

    /// `(free columns of this module, of the sparse partition)` at the assembled initial guess.
    fn both(text: &str, options: &ImportOptions) -> (Option<usize>, usize) {
        let model = load_str(text, "m.urdf", options).unwrap().model;
        let locks = crate::solver::lock_values(&model);
        let mut branches = Default::default();
        let q0 = crate::solver::initial_state(&model).q;
        let q = crate::solver::assemble_only(&model, q0, &mut branches, &locks).unwrap();
        let cons = Constraints::new(&model, &locks).on_branches(branches);
        let mut sys = System::new(&model, cons, Backend::Sparse);
        let mut phi = nalgebra::DVector::zeros(sys.problem.cons.len());
        let mut jac = crate::constraints::Triplets::default();
        sys.problem
            .cons
            .evaluate(&model, &q, &mut phi, Some(&mut jac));
        let s = &sys.problem.scaling;
        let fast = super::free_columns(
            &model,
            jac.rows,
            jac.cols,
            &jac.entries,
            &s.rows,
            &s.columns,
        );
        (fast, sys.partition(&q).independent.len())
    }

    /// Same count as the partition wherever the fill-free route answers; it answers on every
    /// tree and gives up on closed loops.
    #[test]
    fn same_free_columns_as_the_sparse_partition() {
        let trees = [
            include_str!("../../robots/pendulum.urdf").to_string(),
            include_str!("../../robots/chain20.urdf").to_string(),
            include_str!("../../robots/panda_class.urdf").to_string(),
            include_str!("../../robots/ur5_class.urdf").to_string(),
            include_str!("../../robots/quadruped_leg.urdf").to_string(),
            include_str!("../../robots/gazebo_transmission.urdf").to_string(),
            include_str!("../../robots/solo12/solo12_ground.urdf").to_string(),
            crate::generate::chain(9, false),
            crate::generate::chain(120, false),
            crate::generate::chain(120, true),
            crate::generate::chain(2000, false),
            crate::generate::rope(12),
        ];
        let loops = [
            include_str!("../../robots/slider_crank.urdf").to_string(),
            include_str!("../../robots/four_bar_spatial.urdf").to_string(),
            include_str!("../../robots/stewart_platform.urdf").to_string(),
            include_str!("../../robots/drake_closed_chain.urdf").to_string(),
            include_str!("../../robots/tractor_trailer.urdf").to_string(),
            crate::generate::ladder(5),
        ];
        let plain = ImportOptions::default();
        let floating = ImportOptions {
            floating_base: true,
            ..Default::default()
        };
        for (k, t) in trees.iter().enumerate() {
            for o in [&plain, &floating] {
                let (fast, partition) = both(t, o);
                assert_eq!(fast, Some(partition), "tree {k}");
            }
        }
        for (k, t) in loops.iter().enumerate() {
            let (fast, partition) = both(t, &plain);
            assert!(fast.is_none_or(|f| f == partition), "loop {k}");
        }
    }

    /// Lock rows (on the joint's own body) and a redundant lock: the same count as the
    /// partition, the redundant row found as there.
    #[test]
    fn locks_and_a_redundant_lock() {
        let chain = crate::generate::chain(60, false);
        let lock = |joint: &str| (joint.to_string(), 0, None);
        let one = ImportOptions {
            locks: vec![lock("joint0"), lock("joint30")],
            ..Default::default()
        };
        let (fast, partition) = both(&chain, &one);
        assert_eq!(fast, Some(partition));
        assert_eq!(partition, 58);
        let twice = ImportOptions {
            locks: vec![lock("joint7"), lock("joint7")],
            ..Default::default()
        };
        let (fast, partition) = both(&chain, &twice);
        assert_eq!(partition, 59);
        assert_eq!(fast, Some(partition));
    }
}
