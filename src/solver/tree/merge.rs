//! Super-nodes: where a partition's border would be too large for its dense Schur complement
//! (a ladder: a closed loop per rung, 7 of its 20 pivots of `Φ_u` and 13 KKT unknowns per rung
//! in the border), the nodes a loop couples are merged into one node instead, so that the
//! merged nodes form a tree again and the border is empty.
//!
//! - **`Φ_u`** (block upper triangular on a tree: node `i`'s rows reach only its own and later
//!   nodes' columns). A run `r` whose rows reach the columns of an earlier run spans the
//!   interval of runs `[first(r), r]`, `first(r) = min { run(q) : Φ_u[p, q] ≠ 0, run(p) = r }`;
//!   overlapping intervals are merged into one node (their pivot positions are consecutive),
//!   so every entry below the block diagonal lies in a merged node's diagonal block, factored by
//!   LU with partial pivoting like any other.
//! - **KKT** (symmetric, eliminated leaves first). A node whose elimination would couple more
//!   than one later node (fill) merges those later nodes into one, placed at the latest of
//!   them:
//!
//!   ```text
//!   later(i) = { find(j) : j adjacent to a member of i, find(j) after i }
//!   |later(i)| > 1  ⇒  union(later(i)),   parent(i) = find(later(i))
//!   ```
//!
//!   Eliminating a node then fills nothing (its one later neighbour is its parent), and a merge
//!   never touches a node already eliminated (it merges later nodes only): a tree of
//!   super-nodes. Rows pivoted away from their body's run (a loop's) join the node being built
//!   when they are pivoted, as in the sparse LDLᵀ's order; a merged node lists its members'
//!   coordinates, then their rows (its children reach the coordinates: narrow couplings). The
//!   LDLᵀ of another symmetric order of the same matrix has the same inertia (Sylvester).
//!
//! A super-node larger than [`MAX_NODE`] unknowns or pivots refuses the tree factors (the
//! sparse ones are used). On a ladder the model's `Φ_u` has a merged node of 14 pivots and a
//! run of 6 per rung, the self-check's (module `verify::held`: a lock row per coordinate) one of
//! 21 pivots per rung; its KKT matrix a rung's node (14 unknowns, coupled to 18 of its parent's)
//! and a rung's two posts merged (27 unknowns, coupled to 7), a chain of 2 nodes per rung.

use super::nodes::{Members, Pair};
use crate::constraints::Triplet;
use crate::solver::partition::Partition;

/// Super-nodes larger than this (unknowns or pivots) are not factored here.
pub(crate) const MAX_NODE: usize = 64;

/// The runs of pivots of `Φ_u` (consecutive pivots on one body's columns): each position's
/// run and their number.
pub(crate) fn runs(part: &Partition) -> (Vec<u32>, usize) {
    let order = part.rows.len();
    let mut run_of = vec![0u32; order];
    let mut runs = 0u32;
    for k in 0..order {
        if k > 0 && part.dependent[k] / 7 != part.dependent[k - 1] / 7 {
            runs += 1;
        }
        run_of[k] = runs;
    }
    (run_of, if order == 0 { 0 } else { runs as usize + 1 })
}

/// The runs of pivots of `Φ_u` (consecutive pivots on one body's columns) of the `m × n`
/// Jacobian `entries`: `(run_of, runs, bordered)`, each position's run, their number and the
/// runs with an entry in an earlier run's column. If those runs hold more than `max_border`
/// pivots, overlapping runs are merged instead (module doc) and none is bordered; `None` if a
/// merged run exceeds [`MAX_NODE`].
pub(crate) fn phi_u_runs(
    part: &Partition,
    m: usize,
    n: usize,
    entries: &[Triplet],
    max_border: usize,
) -> Option<(Vec<u32>, usize, Vec<bool>)> {
    let order = part.rows.len();
    let (mut run_of, runs) = runs(part);
    // Each pivot row's and each dependent column's run (`u32::MAX`: none), looked up once.
    let mut row_run = vec![u32::MAX; m];
    for (&r, &k) in part.rows.iter().zip(&run_of) {
        row_run[r] = k;
    }
    let mut col_run = vec![u32::MAX; n];
    for (&c, &k) in part.dependent.iter().zip(&run_of) {
        col_run[c] = k;
    }
    // The earliest run each run's rows reach (itself if none before; a column outside `Φ_u`
    // reads `u32::MAX`, which lowers nothing).
    let mut first: Vec<u32> = (0..runs as u32).collect();
    for e in entries {
        let rp = row_run[e.0 as usize];
        if rp != u32::MAX {
            let f = &mut first[rp as usize];
            *f = (*f).min(col_run[e.1 as usize]);
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

/// The KKT matrix's super-nodes for `part` (module doc): `(members, parent)`, each node's
/// unknowns (coordinates `0 .. n`, rows `n + k`) in elimination order and its parent
/// (`u32::MAX`: a root); `None` if a super-node exceeds [`MAX_NODE`] unknowns. `pairs`: the
/// coupled nodes `(a, b, _)` (module `shape`'s nodes, each row in the node of the run it is
/// pivoted in: those numbered here).
pub(crate) fn kkt_nodes(part: &Partition, n: usize, pairs: &[Pair]) -> Option<(Members, Vec<u32>)> {
    let nb = n / 7;
    let rows = part.rows.len();
    let mut body_node = vec![u32::MAX; nb];
    let mut members = Members::with_capacity(nb, n + rows);
    for (k, &c) in part.dependent.iter().enumerate() {
        let b = c / 7;
        if body_node[b] == u32::MAX {
            body_node[b] = members.count() as u32;
            members.open_body(b);
        }
        members.push(n + k);
    }
    for b in 0..nb {
        if body_node[b] == u32::MAX {
            body_node[b] = members.count() as u32;
            members.open_body(b);
        }
    }
    let nodes = members.count();
    // Each node's neighbours, `adj_at[i] .. adj_at[i + 1]` of `adj` (read as sets).
    let mut adj_at = vec![0usize; nodes + 1];
    for &(a, b, _) in pairs {
        adj_at[a as usize + 1] += 1;
        adj_at[b as usize + 1] += 1;
    }
    for i in 0..nodes {
        adj_at[i + 1] += adj_at[i];
    }
    let mut fill = adj_at.clone();
    let mut adj = vec![0u32; adj_at[nodes]];
    for &(a, b, _) in pairs {
        adj[fill[a as usize]] = b;
        fill[a as usize] += 1;
        adj[fill[b as usize]] = a;
        fill[b as usize] += 1;
    }
    // Union-find whose representative is the set's latest node; a set's member nodes are
    // linked from its representative (`next`, ending at `u32::MAX`; `tail`: the last).
    let mut rep: Vec<u32> = (0..nodes as u32).collect();
    let mut next = vec![u32::MAX; nodes];
    let mut tail: Vec<u32> = (0..nodes as u32).collect();
    let mut size: Vec<usize> = (0..nodes).map(|i| members.get(i).len()).collect();
    let mut parent = vec![u32::MAX; nodes];
    let mut later = Vec::new();
    for i in 0..nodes {
        if find(&mut rep, i as u32) != i as u32 {
            continue;
        }
        later.clear();
        let mut m = i as u32;
        while m != u32::MAX {
            for &j in &adj[adj_at[m as usize]..adj_at[m as usize + 1]] {
                let r = find(&mut rep, j);
                if r > i as u32 {
                    later.push(r);
                }
            }
            m = next[m as usize];
        }
        later.sort_unstable();
        later.dedup();
        let Some(&top) = later.last() else {
            continue;
        };
        let top = top as usize;
        for &s in &later[..later.len() - 1] {
            let s = s as usize;
            rep[s] = top as u32;
            next[tail[top] as usize] = s as u32;
            tail[top] = tail[s];
            size[top] += size[s];
        }
        if size[top] > MAX_NODE {
            return None;
        }
        parent[i] = top as u32;
    }
    // The super-nodes in the order of their latest member: the members' coordinates first,
    // then their rows (the children reach the coordinates: narrow couplings).
    let mut index = vec![u32::MAX; nodes];
    let mut merged = Members::with_capacity(nodes, n + rows);
    let mut own = Vec::new();
    for i in 0..nodes {
        if rep[i] != i as u32 {
            continue;
        }
        index[i] = merged.count() as u32;
        merged.open();
        if next[i] == u32::MAX {
            members.get(i).iter().for_each(|&u| merged.push(u));
            continue;
        }
        own.clear();
        let mut m = i as u32;
        while m != u32::MAX {
            own.push(m as usize);
            m = next[m as usize];
        }
        own.sort_unstable();
        for &m in &own {
            members
                .get(m)
                .iter()
                .filter(|&&u| u < n)
                .for_each(|&u| merged.push(u));
        }
        for &m in &own {
            members
                .get(m)
                .iter()
                .filter(|&&u| u >= n)
                .for_each(|&u| merged.push(u));
        }
    }
    let mut par = vec![u32::MAX; merged.count()];
    for i in 0..nodes {
        if rep[i] == i as u32 && parent[i] != u32::MAX {
            par[index[i] as usize] = index[find(&mut rep, parent[i]) as usize];
        }
    }
    Some((merged, par))
}

/// The representative of `i`'s set (path halving).
fn find(rep: &mut [u32], mut i: u32) -> u32 {
    while rep[i as usize] != i {
        let up = rep[rep[i as usize] as usize];
        rep[i as usize] = up;
        i = up;
    }
    i
}
