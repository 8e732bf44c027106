//! The structure of the tree KKT matrix as `Shape::new` and `merge::kkt_nodes` built it
//! through session 27, triplet by triplet (`O(N)` with a large constant): the reference the
//! construction by runs is compared against, field by field (`shape_tests`).

use super::border::Border;
use super::fused::Run;
use super::merge::MAX_NODE;
use super::shape::{Shape, FIRST, MAX_BORDER, SKIP};
use crate::solver::partition::Partition;
use crate::solver::sparse::hessian::BlockHessian;
use std::collections::HashMap;

/// The structure for `part` of an `m × n` Jacobian given by `entries` and the blocks of
/// `hess`; `None` if the border would exceed [`MAX_BORDER`].
pub(super) fn reference(
    part: &Partition,
    m: usize,
    n: usize,
    entries: &[(usize, usize, f64)],
    hess: &BlockHessian,
) -> Option<Shape> {
    let rows = part.rows.len();
    let dim = n + rows;
    let nb = n / 7;
    let mut row_pos = vec![u32::MAX; m];
    for (k, &r) in part.rows.iter().enumerate() {
        row_pos[r] = k as u32;
    }
    // Nodes in elimination order; `owner[u]`: the node of unknown `u` (MAX: border row).
    let mut body_node = vec![u32::MAX; nb];
    let mut members: Vec<Vec<usize>> = Vec::new();
    let mut owner = vec![u32::MAX; dim];
    for (k, &c) in part.dependent.iter().enumerate() {
        let b = c / 7;
        if body_node[b] == u32::MAX {
            body_node[b] = members.len() as u32;
            members.push((7 * b..7 * b + 7).collect());
        }
        let i = body_node[b] as usize;
        if i + 1 == members.len() {
            members[i].push(n + k);
        }
    }
    for b in 0..nb {
        if body_node[b] == u32::MAX {
            body_node[b] = members.len() as u32;
            members.push((7 * b..7 * b + 7).collect());
        }
    }
    for (i, m) in members.iter().enumerate() {
        for &u in m {
            owner[u] = i as u32;
        }
    }
    let nodes = members.len();
    // Node couplings: every pair of unknowns with a value (listed straight into `later`,
    // in the same order, without a list of all pairs first).
    let mut later: Vec<Vec<u32>> = vec![Vec::new(); nodes];
    let mut couple = |a: u32, b: u32| {
        if a != u32::MAX && b != u32::MAX && a != b {
            let (lo, hi) = (a.min(b), a.max(b));
            later[lo as usize].push(hi);
        }
    };
    for &(a, b) in &hess.keys {
        couple(body_node[a], body_node[b]);
    }
    for e in entries {
        if row_pos[e.0] != u32::MAX {
            couple(owner[n + row_pos[e.0] as usize], body_node[e.1 / 7]);
        }
    }
    let mut in_border = vec![false; nodes];
    let mut parent = vec![u32::MAX; nodes];
    for i in 0..nodes {
        if in_border[i] {
            continue;
        }
        let l = &mut later[i];
        l.sort_unstable();
        l.dedup();
        let mut kept = None;
        for &j in l.iter() {
            if in_border[j as usize] {
                continue;
            }
            match kept {
                None => kept = Some(j),
                Some(_) => in_border[j as usize] = true,
            }
        }
        parent[i] = kept.unwrap_or(u32::MAX);
    }
    // Parents bordered after their children were kept: none.
    for i in 0..nodes {
        if parent[i] != u32::MAX && in_border[parent[i] as usize] {
            parent[i] = u32::MAX;
        }
    }
    let mut border_unknowns: Vec<usize> = (0..dim).filter(|&u| owner[u] == u32::MAX).collect();
    for (i, m) in members.iter().enumerate() {
        if in_border[i] {
            border_unknowns.extend_from_slice(m);
        }
    }
    if border_unknowns.len() > MAX_BORDER {
        // Too large for a dense Schur complement: the nodes a loop couples are merged into
        // super-nodes instead (module `merge`), and nothing is bordered.
        (members, parent) = kkt_nodes_reference(part, n, &row_pos, entries, &hess.keys)?;
        in_border = vec![false; members.len()];
        border_unknowns.clear();
    }
    let nodes = members.len();
    // Tree-space positions: kept nodes in order, then the border.
    let mut tpos = vec![0usize; dim];
    let mut perm = Vec::with_capacity(dim);
    let mut node_map = vec![u32::MAX; nodes];
    let (mut at, mut d, mut par) = (Vec::new(), Vec::new(), Vec::new());
    for (i, m) in members.iter().enumerate() {
        if in_border[i] {
            continue;
        }
        node_map[i] = at.len() as u32;
        at.push(perm.len());
        d.push(m.len());
        for &u in m {
            tpos[u] = perm.len();
            perm.push(u);
        }
    }
    for i in 0..nodes {
        if !in_border[i] {
            par.push(if parent[i] == u32::MAX {
                u32::MAX
            } else {
                node_map[parent[i] as usize]
            });
        }
    }
    let tree_len = perm.len();
    for &u in &border_unknowns {
        tpos[u] = perm.len();
        perm.push(u);
    }
    let kept = at.len();
    let mut node_of = vec![u32::MAX; dim];
    for i in 0..kept {
        for t in at[i]..at[i] + d[i] {
            node_of[t] = i as u32;
        }
    }
    // Coupling widths: the parent's leading unknowns reached.
    let mut w = vec![0usize; kept];
    let mut reach = |u1: usize, u2: usize| {
        let (t1, t2) = (tpos[u1], tpos[u2]);
        let (a, b) = (node_of[t1], node_of[t2]);
        if a != u32::MAX && b != u32::MAX && a != b {
            let (c, p, tp) = if par[a as usize] == b {
                (a, b, t2)
            } else {
                (b, a, t1)
            };
            w[c as usize] = w[c as usize].max(tp - at[p as usize] + 1);
        }
    };
    for &(a, b) in &hess.keys {
        reach(7 * a + 6, 7 * b + 6);
    }
    for e in entries {
        if row_pos[e.0] != u32::MAX {
            reach(n + row_pos[e.0] as usize, e.1);
        }
    }
    let mut diag_at = Vec::with_capacity(kept + 1);
    let mut coup_at = Vec::with_capacity(kept + 1);
    let mut flat = 0;
    for i in 0..kept {
        diag_at.push(flat);
        flat += d[i] * d[i];
    }
    for i in 0..kept {
        coup_at.push(flat);
        flat += d[i] * w[i];
    }
    let mut border = Border::new(&(tree_len..dim).collect::<Vec<_>>(), dim);
    let mut border_slot: HashMap<(usize, usize), u32> = HashMap::new();
    // The slot of the tree-space pair `(t1, t2)`, both in the tree: its node's diagonal
    // block, its coupling to the parent, `SKIP` for the mirror of a coupling, or `None`.
    let tree_slot = |t1: usize, t2: usize| -> Option<u32> {
        let (a, b) = (node_of[t1] as usize, node_of[t2] as usize);
        let (l1, l2) = (t1 - at[a], t2 - at[b]);
        if a == b {
            Some((diag_at[a] + l1 * d[a] + l2) as u32)
        } else if par[a] == b as u32 {
            Some((coup_at[a] + l1 * w[a] + l2) as u32)
        } else if par[b] == a as u32 {
            Some(SKIP)
        } else {
            None
        }
    };
    let mut locate = |u1: usize, u2: usize| -> Option<u32> {
        let (t1, t2) = (tpos[u1], tpos[u2]);
        if t1 >= tree_len || t2 >= tree_len {
            let next = border_slot.len() as u32;
            let s = *border_slot.entry((t1, t2)).or_insert(next);
            if s == next {
                border.add(t1, t2);
            }
            return Some(flat as u32 + s);
        }
        tree_slot(t1, t2)
    };
    let mut block_slots = Vec::with_capacity(hess.keys.len());
    let mut block_runs = Vec::with_capacity(hess.keys.len());
    for &(a, b) in &hess.keys {
        let mut s = [SKIP; 49];
        // A body's 7 coordinates lead its node, in order (or all lie in the border): a
        // block between two tree nodes is one dense run of slots, or all mirrors.
        let (ta, tb) = (tpos[7 * a], tpos[7 * b]);
        if ta < tree_len && tb < tree_len {
            let (na, nb) = (node_of[ta] as usize, node_of[tb] as usize);
            let (start, stride) = if na == nb {
                (diag_at[na] + (ta - at[na]) * d[na] + (tb - at[nb]), d[na])
            } else if par[na] == nb as u32 {
                (coup_at[na] + (ta - at[na]) * w[na] + (tb - at[nb]), w[na])
            } else if par[nb] == na as u32 {
                block_slots.push(s);
                block_runs.push(Run::Skip);
                continue;
            } else {
                return None;
            };
            for i in 0..7 {
                for j in 0..7 {
                    s[7 * i + j] = (start + i * stride + j) as u32;
                }
            }
            block_runs.push(Run::Dense { start, stride });
        } else {
            for i in 0..7 {
                for j in 0..7 {
                    s[7 * i + j] = locate(7 * a + i, 7 * b + j)?;
                }
            }
            block_runs.push(Run::Scattered);
        }
        block_slots.push(s);
    }
    let mut jac_slots = Vec::with_capacity(entries.len());
    for e in entries {
        jac_slots.push(match row_pos[e.0] {
            u32::MAX => [SKIP, SKIP],
            k => {
                let r = n + k as usize;
                let (t1, t2) = (tpos[r], tpos[e.1]);
                if t1 < tree_len && t2 < tree_len {
                    [tree_slot(t1, t2)?, tree_slot(t2, t1)?]
                } else {
                    [locate(r, e.1)?, locate(e.1, r)?]
                }
            }
        });
    }
    let diag_slots = (0..n).map(|c| locate(c, c)).collect::<Option<Vec<_>>>()?;
    let total = flat + border_slot.len();
    if total >= FIRST as usize {
        return None;
    }
    // Flag each slot's first triplet; list the diagonal slots no block reaches.
    let mut reached = vec![false; total];
    for slots in &mut jac_slots {
        for slot in slots.iter_mut().filter(|s| **s != SKIP) {
            if !std::mem::replace(&mut reached[*slot as usize], true) {
                *slot |= FIRST;
            }
        }
    }
    for s in block_slots.iter().flatten().filter(|&&s| s != SKIP) {
        reached[*s as usize] = true;
    }
    let bare_diag = diag_slots
        .iter()
        .copied()
        .filter(|&s| !reached[s as usize])
        .collect();
    Some(Shape {
        n,
        rows,
        perm,
        at,
        d,
        parent: par,
        w,
        diag_at,
        coup_at,
        flat_len: flat,
        tree_len,
        border,
        block_slots,
        block_runs,
        jac_slots,
        diag_slots,
        bare_diag,
    })
}

/// `merge::kkt_nodes` as built through session 27 (every triplet coupled, module `merge`'s doc): `(members, parent)`, each node's
/// unknowns (coordinates `0 .. n`, rows `n + k`) in elimination order and its parent
/// (`u32::MAX`: a root); `None` if a super-node exceeds [`MAX_NODE`] unknowns.
fn kkt_nodes_reference(
    part: &Partition,
    n: usize,
    row_pos: &[u32],
    entries: &[(usize, usize, f64)],
    keys: &[(usize, usize)],
) -> Option<(Vec<Vec<usize>>, Vec<u32>)> {
    let nb = n / 7;
    let mut body_node = vec![u32::MAX; nb];
    let mut members: Vec<Vec<usize>> = Vec::new();
    for (k, &c) in part.dependent.iter().enumerate() {
        let b = c / 7;
        if body_node[b] == u32::MAX {
            body_node[b] = members.len() as u32;
            members.push((7 * b..7 * b + 7).collect());
        }
        if let Some(m) = members.last_mut() {
            m.push(n + k);
        }
    }
    for b in 0..nb {
        if body_node[b] == u32::MAX {
            body_node[b] = members.len() as u32;
            members.push((7 * b..7 * b + 7).collect());
        }
    }
    let nodes = members.len();
    let mut row_node = vec![u32::MAX; part.rows.len()];
    for (i, m) in members.iter().enumerate() {
        for &u in m.iter().filter(|&&u| u >= n) {
            row_node[u - n] = i as u32;
        }
    }
    let mut adj: Vec<Vec<u32>> = vec![Vec::new(); nodes];
    let mut couple = |a: u32, b: u32| {
        if a != b && a != u32::MAX && b != u32::MAX {
            adj[a as usize].push(b);
            adj[b as usize].push(a);
        }
    };
    for &(a, b) in keys {
        couple(body_node[a], body_node[b]);
    }
    for e in entries {
        if row_pos[e.0] != u32::MAX {
            couple(row_node[row_pos[e.0] as usize], body_node[e.1 / 7]);
        }
    }
    // Union-find whose representative is the set's latest node; `set[r]`: its member nodes.
    let mut rep: Vec<u32> = (0..nodes as u32).collect();
    let mut set: Vec<Vec<u32>> = (0..nodes as u32).map(|i| vec![i]).collect();
    let mut size: Vec<usize> = members.iter().map(Vec::len).collect();
    let mut parent = vec![u32::MAX; nodes];
    let mut later = Vec::new();
    for i in 0..nodes {
        if find(&mut rep, i as u32) != i as u32 {
            continue;
        }
        later.clear();
        for &m in &set[i] {
            for &j in &adj[m as usize] {
                let r = find(&mut rep, j);
                if r > i as u32 {
                    later.push(r);
                }
            }
        }
        later.sort_unstable();
        later.dedup();
        let Some(&top) = later.last() else {
            continue;
        };
        for &s in &later[..later.len() - 1] {
            rep[s as usize] = top;
            let moved = std::mem::take(&mut set[s as usize]);
            set[top as usize].extend(moved);
            size[top as usize] += size[s as usize];
        }
        if size[top as usize] > MAX_NODE {
            return None;
        }
        parent[i] = top;
    }
    // The super-nodes in the order of their latest member: the members' coordinates first,
    // then their rows (the children reach the coordinates: narrow couplings).
    let mut index = vec![u32::MAX; nodes];
    let mut merged = Vec::new();
    for i in 0..nodes {
        if rep[i] == i as u32 {
            index[i] = merged.len() as u32;
            let mut own = std::mem::take(&mut set[i]);
            own.sort_unstable();
            let all = || {
                own.iter()
                    .flat_map(|&m| members[m as usize].iter().copied())
            };
            let node: Vec<usize> = if own.len() == 1 {
                all().collect()
            } else {
                all()
                    .filter(|&u| u < n)
                    .chain(all().filter(|&u| u >= n))
                    .collect()
            };
            merged.push(node);
        }
    }
    let mut par = vec![u32::MAX; merged.len()];
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
