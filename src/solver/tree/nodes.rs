//! The nodes of the tree KKT matrix (module `shape`) and how they couple: each node's
//! unknowns (a body's 7 coordinates and the rows of its first run of pivots), the pairs of
//! nodes that share a value (a Hessian block `W_ab`, a Jacobian entry `∂Φ_r/∂q_c`), and the
//! bordered tree they form:
//!
//! ```text
//! later(i) = { j > i : (i, j) coupled },   parent(i) = min later(i),   the rest → border
//! ```
//!
//! (a node already in the border is passed over). Where the border would exceed
//! [`MAX_BORDER`] the same pairs make the super-nodes of module `merge` instead.

use super::shape::MAX_BORDER;
use crate::constraints::Triplet;

/// Two nodes coupled by a value, `(a, b, owned)`: `owned` unless the value is a border row's.
pub(super) type Pair = (u32, u32, bool);

/// The unknowns of each node, node after node: node `i` holds `list[start[i] .. start[i + 1]]`.
#[derive(Default)]
pub(super) struct Members {
    start: Vec<usize>,
    list: Vec<usize>,
}

impl Members {
    /// Room for `nodes` nodes of `unknowns` in all.
    pub(super) fn with_capacity(nodes: usize, unknowns: usize) -> Self {
        Members {
            start: Vec::with_capacity(nodes),
            list: Vec::with_capacity(unknowns),
        }
    }

    /// Number of nodes.
    pub(super) fn count(&self) -> usize {
        self.start.len()
    }

    /// Opens a node (empty).
    pub(super) fn open(&mut self) {
        self.start.push(self.list.len());
    }

    /// Opens a node holding body `b`'s 7 coordinates.
    pub(super) fn open_body(&mut self, b: usize) {
        self.open();
        self.list.extend(7 * b..7 * b + 7);
    }

    /// Adds unknown `u` to the last node.
    pub(super) fn push(&mut self, u: usize) {
        self.list.push(u);
    }

    /// Node `i`'s unknowns.
    pub(super) fn get(&self, i: usize) -> &[usize] {
        let end = self.start.get(i + 1).copied().unwrap_or(self.list.len());
        &self.list[self.start[i]..end]
    }
}

/// The triplets by runs `first .. end` and the pairs of nodes coupled by a value
/// `(a, b, owned)`. Runs (`fast`): a row's consecutive columns on one body, which lie at
/// consecutive positions of one node; else each triplet on its own. Pairs: the Hessian
/// blocks' bodies', then each run's row node (`row_node`) and column body's (`owned`: the row
/// is its node's own, not a border row); a run on the row and body of the run before it (the
/// same pair) is not listed again where `fast` (the pairs are read as sets).
pub(super) fn runs_and_pairs(
    entries: &[Triplet],
    keys: &[(usize, usize)],
    body_node: &[u32],
    row_node: &[u32],
    owned: &[bool],
    row_pos: &[u32],
    fast: bool,
) -> (Vec<(usize, usize)>, Vec<Pair>) {
    let mut runs = Vec::with_capacity(entries.len() / 3 + 1);
    let mut pairs = Vec::with_capacity(keys.len() + entries.len() / 3);
    for &(a, b) in keys {
        let (a, b) = (body_node[a], body_node[b]);
        if a != b {
            pairs.push((a, b, true));
        }
    }
    let mut last = (usize::MAX, usize::MAX);
    let mut first = 0;
    while first < entries.len() {
        let (r, c) = (entries[first].0 as usize, entries[first].1 as usize);
        let body = c / 7;
        let mut end = first + 1;
        if fast {
            let top = 7 * body + 6;
            while end < entries.len()
                && entries[end].0 as usize == r
                && entries[end].1 as usize == c + (end - first)
                && entries[end].1 as usize <= top
            {
                end += 1;
            }
        }
        runs.push((first, end));
        if ((r, body) != last || !fast) && row_pos[r] != u32::MAX {
            let k = row_pos[r] as usize;
            let a = row_node[k];
            if a != body_node[body] {
                pairs.push((a, body_node[body], owned[k]));
            }
        }
        last = (r, body);
        first = end;
    }
    (runs, pairs)
}

/// Each node's parent, the nodes in the border and the border's unknowns (the border rows,
/// then the bordered nodes' unknowns), from the pairs of nodes coupled through owned rows: a
/// node coupled to several later nodes keeps the first as its parent and borders the others
/// (module `shape`). `None` if the border exceeds [`MAX_BORDER`] (`fast`: as soon as it does).
pub(super) fn border_nodes(
    members: &Members,
    pairs: &[Pair],
    owned: &[bool],
    n: usize,
    fast: bool,
) -> Option<(Vec<u32>, Vec<bool>, Vec<usize>)> {
    let nodes = members.count();
    // Each node's later neighbours: `later[at[i] .. at[i + 1]]`.
    let mut at = vec![0usize; nodes + 1];
    for &(a, b, own) in pairs {
        if own {
            at[a.min(b) as usize + 1] += 1;
        }
    }
    for i in 0..nodes {
        at[i + 1] += at[i];
    }
    let mut fill = at.clone();
    let mut later = vec![0u32; at[nodes]];
    for &(a, b, own) in pairs {
        if own {
            let lo = a.min(b) as usize;
            later[fill[lo]] = a.max(b);
            fill[lo] += 1;
        }
    }
    let mut size = owned.iter().filter(|&&o| !o).count();
    let mut in_border = vec![false; nodes];
    let mut parent = vec![u32::MAX; nodes];
    for i in 0..nodes {
        if in_border[i] {
            continue;
        }
        let l = &mut later[at[i]..at[i + 1]];
        l.sort_unstable();
        let mut kept = None;
        let mut prev = u32::MAX;
        for &j in l.iter() {
            if j == prev || in_border[j as usize] {
                continue;
            }
            prev = j;
            match kept {
                None => kept = Some(j),
                Some(_) => {
                    in_border[j as usize] = true;
                    size += members.get(j as usize).len();
                    if fast && size > MAX_BORDER {
                        return None;
                    }
                }
            }
        }
        parent[i] = kept.unwrap_or(u32::MAX);
    }
    if size > MAX_BORDER {
        return None;
    }
    // Parents bordered after their children were kept: none.
    for i in 0..nodes {
        if parent[i] != u32::MAX && in_border[parent[i] as usize] {
            parent[i] = u32::MAX;
        }
    }
    let mut border_unknowns: Vec<usize> = (0..owned.len())
        .filter(|&k| !owned[k])
        .map(|k| n + k)
        .collect();
    for i in 0..nodes {
        if in_border[i] {
            border_unknowns.extend_from_slice(members.get(i));
        }
    }
    Some((parent, in_border, border_unknowns))
}
