//! Super-nodes of `Φ_u`: where a partition's border would be too large for its dense Schur
//! complement (a ladder: a closed loop per rung, 7 of its 20 pivots per rung in the border),
//! the runs of pivots a loop couples are merged into one node instead, so that `Φ_u` is block
//! upper triangular again, with no border.
//!
//! On a tree, node `i`'s rows reach only its own and later nodes' columns. A run `r` whose
//! rows reach the columns of an earlier run spans the interval of runs `[first(r), r]`,
//!
//! ```text
//! first(r) = min { run(q) : Φ_u[p, q] ≠ 0, run(p) = r },
//! ```
//!
//! and the overlapping intervals are merged into one node (their pivot positions are
//! consecutive): every entry below the block diagonal then lies in a merged node's diagonal
//! block, factored by LU with partial pivoting like any other (no fill, no border). A merged
//! node of more than [`MAX_NODE`] pivots refuses the tree factors (the sparse LU is used). On
//! the ladder of 100 rungs the model's `Φ_u` has a merged node of 14 pivots and a run of 6 per
//! rung, the self-check's (module `verify::held`: a lock row per coordinate) one of 21 pivots
//! per rung.
//!
//! The KKT matrix is not merged: merging the nodes a loop couples (a rung's two posts, 27
//! unknowns) and factoring the dense super-nodes cost more than faer's simplicial LDLᵀ of the
//! same matrix (ladder 1,000: 96 M more instructions in the whole process, callgrind;
//! docs/benchmarks-history.md, session 27, h/ladder), so a ladder's KKT matrix keeps the sparse
//! factors.

use crate::solver::partition::Partition;

/// Super-nodes larger than this (unknowns or pivots) are not factored here.
pub(crate) const MAX_NODE: usize = 64;

/// The runs of pivots of `Φ_u` (consecutive pivots on one body's columns): `(run_of, runs,
/// bordered)`, each position's run, their number and the runs with an entry in an earlier
/// run's column. If those runs hold more than `max_border` pivots, overlapping runs are merged
/// instead (module doc) and none is bordered; `None` if a merged run exceeds [`MAX_NODE`].
pub(crate) fn phi_u_runs(
    part: &Partition,
    entries: &[(usize, usize, f64)],
    row_pos: &[u32],
    col_pos: &[u32],
    max_border: usize,
) -> Option<(Vec<u32>, usize, Vec<bool>)> {
    let order = part.rows.len();
    let mut run_of = vec![0u32; order];
    let mut runs = 0u32;
    for k in 0..order {
        if k > 0 && part.dependent[k] / 7 != part.dependent[k - 1] / 7 {
            runs += 1;
        }
        run_of[k] = runs;
    }
    let runs = if order == 0 { 0 } else { runs as usize + 1 };
    // The earliest run each run's rows reach (itself if none before).
    let mut first: Vec<u32> = (0..runs as u32).collect();
    for e in entries {
        let (p, q) = (row_pos[e.0], col_pos[e.1]);
        if p != u32::MAX && q != u32::MAX {
            let (rp, rq) = (run_of[p as usize] as usize, run_of[q as usize]);
            first[rp] = first[rp].min(rq);
        }
    }
    let bordered: Vec<bool> = (0..runs).map(|r| first[r] < r as u32).collect();
    let border = (0..order).filter(|&k| bordered[run_of[k] as usize]).count();
    if border <= max_border {
        return Some((run_of, runs, bordered));
    }
    // Merge the intervals `[first[r], r]`, from the last run down.
    let mut group = vec![0u32; runs];
    let mut groups = 0u32;
    let mut r = runs;
    while r > 0 {
        let hi = r - 1;
        let mut lo = first[hi] as usize;
        let mut s = hi;
        loop {
            lo = lo.min(first[s] as usize);
            group[s] = groups;
            if s == 0 || s - 1 < lo {
                break;
            }
            s -= 1;
        }
        groups += 1;
        r = s;
    }
    // Groups were numbered from the last run: renumber in position order, and check sizes.
    let groups = groups as usize;
    let mut size = vec![0usize; groups];
    for k in 0..order {
        let g = groups - 1 - group[run_of[k] as usize] as usize;
        run_of[k] = g as u32;
        size[g] += 1;
    }
    if size.iter().any(|&s| s > MAX_NODE) {
        return None;
    }
    Some((run_of, groups, vec![false; groups]))
}
