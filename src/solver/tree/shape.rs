//! The block structure of the KKT matrix on a tree, built once per partition: its nodes (a
//! body's 7 coordinates and the rows pivoted at it), each node's parent, the border, and the
//! slot of every value.
//!
//! The unknowns are numbered like the KKT solve's right side: coordinates `0 .. n`, then the
//! partition's rows `n + k`. In the elimination order of the sparse LDLᵀ (each body's
//! coordinates when the partition first pivots on it, followed by the rows of that run of
//! pivots) a node couples to later nodes through the Hessian blocks of the terms it shares and
//! through the Jacobian entries of its rows. A node coupled to one later node (its parent) is
//! eliminated without fill; where it is coupled to more, all but the first go to the border
//! (module `border`), with the rows pivoted away from their body's run (loop rows).
//!
//! Built in `O(N)` by runs of triplets: a row's entries on one body come as consecutive
//! columns, which lie at consecutive positions `t, t + 1, …` of one node; along such a run the
//! node pair is the same (one coupling, one reach, the last's), the slot of `(row, t + j)` is
//! that of `(row, t)` plus `j` and its mirror's plus `j` times the width of the column's block.
//! The runs and the pairs of coupled nodes are listed in one pass, shared by the bordered tree
//! and the super-nodes (module `merge`); the border is abandoned as soon as it exceeds
//! [`MAX_BORDER`]. A slot holds one ordered pair of unknowns, so a triplet's slot and its
//! mirror's are first together (one test per triplet, one per run where none of its slots was
//! reached), and a coordinate's diagonal is written by its body's own Hessian block only.
//! The construction triplet by triplet (`Shape::build` with `fast` false) is the tests' reference.

use super::border::Border;
use super::fused::Run;
use super::jac_runs::{push_run, JacRun, EACH};
use super::nodes::{border_nodes, runs_and_pairs, Members};
use crate::constraints::Triplet;
use crate::solver::partition::Partition;
use crate::solver::sparse::hessian::BlockHessian;
use std::collections::HashMap;

/// Borders larger than this (unknowns) are merged into super-nodes instead (module `merge`;
/// the general sparse LDLᵀ where those would be too large).
pub(crate) const MAX_BORDER: usize = 96;

/// Where a value goes: `flat` slots below `flat_len`, border slots above, or nowhere (the
/// mirror of a coupling entry, which the block elimination reads from its transpose).
pub(crate) const SKIP: u32 = u32::MAX;

/// The flag of a Jacobian slot that the triplet is the first to reach (the assembly stores
/// `0 + v` there and adds the later triplets' values: no zeroing pass). Slots stay below it.
pub(crate) const FIRST: u32 = 1 << 31;

/// The structure of the tree KKT matrix.
#[cfg_attr(test, derive(Debug, PartialEq))]
pub(crate) struct Shape {
    /// Coordinates `n` and rows.
    pub(crate) n: usize,
    pub(crate) rows: usize,
    /// `perm[t]`: the unknown at tree-space position `t` (tree nodes, then the border).
    pub(crate) perm: Vec<usize>,
    /// Node `i`: its first tree-space position, its size `d`, its parent (`u32::MAX`: none),
    /// the width `w` of its coupling to the parent (the parent's leading unknowns it reaches).
    pub(crate) at: Vec<usize>,
    pub(crate) d: Vec<usize>,
    pub(crate) parent: Vec<u32>,
    pub(crate) w: Vec<usize>,
    /// Offsets of each node's `d × d` diagonal block and `d × w` coupling in the flat values.
    pub(crate) diag_at: Vec<usize>,
    pub(crate) coup_at: Vec<usize>,
    pub(crate) flat_len: usize,
    /// The tree-space size (the border follows).
    pub(crate) tree_len: usize,
    pub(crate) border: Border,
    /// Where each Hessian block's entries go (module `fused`): a dense run of slots, the
    /// mirror of a coupling (nowhere), or entry by entry at its slots in `scattered_slots`
    /// (a block that reaches the border; the dense runs keep no slot list).
    pub(crate) block_runs: Vec<Run>,
    pub(crate) scattered_slots: Vec<[u32; 49]>,
    /// Where the Jacobian's triplets go, run by run in the triplets' order (see [`JacRun`]),
    /// and the slots of the triplets placed one by one (`(row, column)` and its mirror;
    /// [`FIRST`] set on the first triplet to reach a slot), in order.
    pub(crate) jac_runs: Vec<JacRun>,
    pub(crate) jac_each: Vec<[u32; 2]>,
    /// The slot of each coordinate's diagonal.
    pub(crate) diag_slots: Vec<u32>,
    /// The diagonal slots that no Hessian block writes (zeroed by each assembly: a shift of
    /// the last factorization may be left there).
    pub(crate) bare_diag: Vec<u32>,
}

impl Shape {
    /// The structure for `part` of an `m × n` Jacobian given by `entries` and the blocks of
    /// `hess`; `None` if the border would exceed [`MAX_BORDER`].
    pub(crate) fn new(
        part: &Partition,
        m: usize,
        n: usize,
        entries: &[Triplet],
        hess: &BlockHessian,
    ) -> Option<Self> {
        Self::build(part, m, n, entries, hess, true)
    }

    /// [`Shape::new`] (`fast`), or the reference construction (`shape_tests` compares the
    /// two): each triplet read on its own, the border completed before its size is tested,
    /// each slot of a triplet flagged on its own, the bare diagonal found from every block
    /// slot. The same structure either way.
    pub(crate) fn build(
        part: &Partition,
        m: usize,
        n: usize,
        entries: &[Triplet],
        hess: &BlockHessian,
        fast: bool,
    ) -> Option<Self> {
        let rows = part.rows.len();
        let dim = n + rows;
        let nb = n / 7;
        let mut row_pos = vec![u32::MAX; m];
        for (k, &r) in part.rows.iter().enumerate() {
            row_pos[r] = k as u32;
        }
        // Nodes in elimination order: a body's coordinates and the rows of its first run of
        // pivots (`owned`). A row pivoted at a body after another body's run (a loop's) is a
        // border row, or joins the node of the run it is pivoted in among super-nodes
        // (`row_node`: that node for every row).
        let mut body_node = vec![u32::MAX; nb];
        let mut members = Members::with_capacity(nb, dim);
        let mut row_node = vec![0u32; rows];
        let mut owned = vec![false; rows];
        for (k, &c) in part.dependent.iter().enumerate() {
            let b = c / 7;
            if body_node[b] == u32::MAX {
                body_node[b] = members.count() as u32;
                members.open_body(b);
            }
            row_node[k] = members.count() as u32 - 1;
            if body_node[b] == row_node[k] {
                members.push(n + k);
                owned[k] = true;
            }
        }
        for b in 0..nb {
            if body_node[b] == u32::MAX {
                body_node[b] = members.count() as u32;
                members.open_body(b);
            }
        }
        let (mut runs, pairs) = runs_and_pairs(
            entries, &hess.keys, &body_node, &row_node, &owned, &row_pos, fast,
        );
        let bordered = border_nodes(&members, &pairs, &owned, n, fast);
        let (members, parent, in_border, border_unknowns) = match bordered {
            Some((parent, in_border, border_unknowns)) => {
                (members, parent, in_border, border_unknowns)
            }
            None => {
                // Too large for a dense Schur complement: the nodes a loop couples are merged
                // into super-nodes instead (module `merge`), and nothing is bordered.
                let (members, parent) = super::merge::kkt_nodes(part, n, &pairs)?;
                let in_border = vec![false; members.count()];
                (members, parent, in_border, Vec::new())
            }
        };
        let nodes = members.count();
        // Tree-space positions: kept nodes in order, then the border.
        let mut tpos = vec![0usize; dim];
        let mut perm = Vec::with_capacity(dim);
        let mut node_map = vec![u32::MAX; nodes];
        let (mut at, mut d, mut par) = (Vec::new(), Vec::new(), Vec::new());
        for i in 0..nodes {
            if in_border[i] {
                continue;
            }
            let m = members.get(i);
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
        // A run's slots follow from its first where its body's 7 coordinates lie in order at
        // consecutive positions of one node (`lined`: as the nodes list them); elsewhere (the
        // border's bodies) each triplet is placed on its own.
        let lined = |b: usize| {
            let t = tpos[7 * b];
            fast && t < tree_len
                && (1..7).all(|k| tpos[7 * b + k] == t + k && node_of[t + k] == node_of[t])
        };
        let lined: Vec<bool> = (0..nb).map(lined).collect();
        if !lined.iter().all(|&l| l) {
            runs = runs
                .iter()
                .flat_map(|&(first, end)| {
                    let whole = lined[entries[first].1 as usize / 7];
                    let cut = if whole { end - first } else { 1 };
                    (first..end)
                        .step_by(cut)
                        .map(move |f| (f, (f + cut).min(end)))
                })
                .collect();
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
        // Along a run the column's position grows and the nodes stay: its last triplet reaches
        // furthest.
        for &(_, end) in &runs {
            let e = &entries[end - 1];
            if row_pos[e.0 as usize] != u32::MAX {
                reach(n + row_pos[e.0 as usize] as usize, e.1 as usize);
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
        let mut scattered_slots = Vec::new();
        let mut block_runs = Vec::with_capacity(hess.keys.len());
        for &(a, b) in &hess.keys {
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
                    block_runs.push(Run::Skip);
                    continue;
                } else {
                    return None;
                };
                block_runs.push(Run::Dense { start, stride });
            } else {
                let mut s = [SKIP; 49];
                for i in 0..7 {
                    for j in 0..7 {
                        s[7 * i + j] = locate(7 * a + i, 7 * b + j)?;
                    }
                }
                block_runs.push(Run::Scattered {
                    at: scattered_slots.len() as u32,
                });
                scattered_slots.push(s);
            }
        }
        if flat >= FIRST as usize {
            return None;
        }
        // Each slot's first triplet flagged as it is listed (`reached`: the slots listed so
        // far, the border's appended as they come).
        let mut reached = vec![false; flat];
        let mut jac_runs: Vec<JacRun> = Vec::with_capacity(runs.len());
        let mut jac_each: Vec<[u32; 2]> = Vec::new();
        // Along a run in the tree, the next column's slot is the next one in the row's block,
        // and its mirror's one row further in the column's block (`step`: the block's width),
        // or both stay the mirror of a coupling ([`SKIP`]).
        for &(first, end) in &runs {
            let e = &entries[first];
            let k = row_pos[e.0 as usize];
            let len = (end - first) as u32;
            if k == u32::MAX {
                push_run(&mut jac_runs, len, SKIP, SKIP, 0);
                continue;
            }
            let r = n + k as usize;
            let (t1, t2) = (tpos[r], tpos[e.1 as usize]);
            if t1 < tree_len && t2 < tree_len {
                let (a, b) = (node_of[t2] as usize, node_of[t1] as usize);
                let step = if a == b { d[a] } else { w[a] } as u32;
                let [s1, s2] = [tree_slot(t1, t2)?, tree_slot(t2, t1)?];
                let at = |s: u32, j: u32, by: u32| if s == SKIP { SKIP } else { s + j * by };
                if fast {
                    // One test per triplet, at the pair's slot that is not the mirror of a
                    // coupling (`flag_pair`; in the tree, inside `reached`).
                    if s1 != SKIP {
                        let span = &mut reached[s1 as usize..(s1 + len) as usize];
                        if !span.contains(&true) {
                            // No slot of the run reached before: all first, one run.
                            span.fill(true);
                            push_run(&mut jac_runs, len, s1, s2, step);
                            continue;
                        }
                    }
                    let (key, by) = if s1 != SKIP { (s1, 1) } else { (s2, step) };
                    for j in 0..len {
                        let seen = std::mem::replace(&mut reached[(key + j * by) as usize], true);
                        let first = if seen { 0 } else { FIRST };
                        jac_each.push([at(s1, j, 1) | first, at(s2, j, step) | first]);
                    }
                } else {
                    for j in 0..len {
                        let (a, b) = (at(s1, j, 1), at(s2, j, step));
                        jac_each.push(flag_each(&mut reached, a, b));
                    }
                }
            } else {
                for e in &entries[first..end] {
                    let (a, b) = (locate(r, e.1 as usize)?, locate(e.1 as usize, r)?);
                    jac_each.push(if fast {
                        flag_pair(&mut reached, a, b)
                    } else {
                        flag_each(&mut reached, a, b)
                    });
                }
            }
            push_run(&mut jac_runs, len, 0, 0, EACH);
        }
        let mut diag_slots = Vec::with_capacity(n);
        for c in 0..n {
            diag_slots.push(locate(c, c)?);
        }
        let total = flat + border_slot.len();
        if total >= FIRST as usize {
            return None;
        }
        // The diagonal slots no block reaches: a slot holds one pair of unknowns, so the
        // diagonal of coordinate `c` is reached by the block `(b, b)` of its body only (`fast`),
        // or found from every block slot.
        let bare_diag = if fast {
            let mut own_block = vec![false; nb];
            for &(a, b) in &hess.keys {
                own_block[a] |= a == b;
            }
            (0..n)
                .filter(|&c| !own_block[c / 7])
                .map(|c| diag_slots[c])
                .collect()
        } else {
            reached.resize(total, false);
            for run in &block_runs {
                for s in run_slots(run, &scattered_slots).filter(|&s| s != SKIP) {
                    reached[s as usize] = true;
                }
            }
            diag_slots
                .iter()
                .copied()
                .filter(|&s| !reached[s as usize])
                .collect()
        };
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
            block_runs,
            scattered_slots,
            jac_runs,
            jac_each,
            diag_slots,
            bare_diag,
        })
    }
}

/// The slots of a block's 49 entries, row-major, by its run ([`SKIP`]: none).
pub(crate) fn run_slots<'a>(
    run: &'a Run,
    scattered_slots: &'a [[u32; 49]],
) -> impl Iterator<Item = u32> + 'a {
    (0..49).map(move |e| match *run {
        Run::Skip => SKIP,
        Run::Dense { start, stride } => (start + (e / 7) * stride + e % 7) as u32,
        Run::Scattered { at } => scattered_slots[at as usize][e],
    })
}

/// A triplet's slot `a` and its mirror's `b`, each flagged [`FIRST`] if no triplet before
/// reached it (`reached`, grown to the border's slots as they come); [`SKIP`] as it is.
fn flag_each(reached: &mut Vec<bool>, a: u32, b: u32) -> [u32; 2] {
    [flag_first(reached, a), flag_first(reached, b)]
}

/// [`flag_each`] by one test: a slot holds one ordered pair of unknowns and the mirror's pair
/// `(column, row)` comes from no other triplet, so both are first when the pair is; the pair
/// is known by the slot of the two that is not [`SKIP`] (one is, for a coupling's mirror).
#[inline]
fn flag_pair(reached: &mut Vec<bool>, a: u32, b: u32) -> [u32; 2] {
    let key = if a != SKIP { a } else { b };
    let first = flag_first(reached, key) & FIRST;
    [a | first, b | first]
}

/// `slot`, flagged [`FIRST`] if no triplet before reached it (`reached`, grown to the border's
/// slots as they come); [`SKIP`] as it is.
#[inline]
fn flag_first(reached: &mut Vec<bool>, slot: u32) -> u32 {
    if slot == SKIP {
        return SKIP;
    }
    let i = slot as usize;
    if i >= reached.len() {
        reached.resize(i + 1, false);
    }
    if std::mem::replace(&mut reached[i], true) {
        slot
    } else {
        slot | FIRST
    }
}
