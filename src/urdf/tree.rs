//! The spanning tree of the joint graph and the bodies it induces, in O(N + E log E).
//!
//! The tree grows breadth first from the root link (and the undeclared world) along URDF and
//! Drake joints, from adjacency lists; when that front is exhausted, the loop element of
//! lowest document index whose parent is placed and whose child is not becomes a tree edge
//! (a heap of eligible loop edges), and the breadth-first growth resumes. Links joined by
//! URDF `fixed` tree joints form one body (group) whose frame is that of its topmost link:
//! `body_from_child = body_from_parent · origin`.

use super::edges::{Declaration, Edge};
use crate::model::JointKind;
use nalgebra::Isometry3;
use std::cmp::Reverse;
use std::collections::{BinaryHeap, VecDeque};

/// Index of an optional link in the adjacency lists: 0 is the world, `l + 1` link `l`.
fn slot(l: Option<usize>) -> usize {
    l.map_or(0, |l| l + 1)
}

/// The spanning tree: its edges in the order they were placed, and which links it reached.
pub(super) struct Tree {
    /// Edge indices of tree edges, in placement order (parents before children).
    pub(super) order: Vec<usize>,
    /// Whether edge `k` is a tree edge.
    pub(super) in_tree: Vec<bool>,
    /// Whether link `l` is reached from the root.
    pub(super) reached: Vec<bool>,
}

/// Grows the spanning tree from `root` over `edges` between `links` links.
pub(super) fn spanning_tree(edges: &[Edge], links: usize, root: usize) -> Tree {
    let mut preferred: Vec<Vec<usize>> = vec![Vec::new(); links + 1];
    let mut loops: Vec<Vec<usize>> = vec![Vec::new(); links + 1];
    for (k, e) in edges.iter().enumerate() {
        if e.source == Declaration::Loop {
            loops[slot(e.parent)].push(k);
        } else {
            preferred[slot(e.parent)].push(k);
        }
    }
    let mut t = Tree {
        order: Vec::new(),
        in_tree: vec![false; edges.len()],
        reached: vec![false; links],
    };
    // Loop edges whose parent is placed, smallest index first.
    let mut eligible: BinaryHeap<Reverse<usize>> = BinaryHeap::new();
    let mut queue: VecDeque<Option<usize>> = VecDeque::new();
    for l in [None, Some(root)] {
        if let Some(l) = l {
            t.reached[l] = true;
        }
        eligible.extend(loops[slot(l)].iter().map(|&k| Reverse(k)));
        queue.push_back(l);
    }
    loop {
        while let Some(l) = queue.pop_front() {
            for &k in &preferred[slot(l)] {
                if let Some(c) = edges[k].child.filter(|&c| !t.reached[c]) {
                    t.reached[c] = true;
                    t.in_tree[k] = true;
                    t.order.push(k);
                    eligible.extend(loops[c + 1].iter().map(|&k| Reverse(k)));
                    queue.push_back(Some(c));
                }
            }
        }
        let next = std::iter::from_fn(|| eligible.pop())
            .map(|Reverse(k)| k)
            .find(|&k| edges[k].child.is_some_and(|c| !t.reached[c]));
        let Some(k) = next else { break };
        let Some(c) = edges[k].child else { break };
        t.reached[c] = true;
        t.in_tree[k] = true;
        t.order.push(k);
        eligible.extend(loops[c + 1].iter().map(|&k| Reverse(k)));
        queue.push_back(Some(c));
    }
    t
}

/// Bodies: groups of links welded by URDF `fixed` tree joints.
pub(super) struct Groups {
    /// Group of each link; group 0 holds the root.
    pub(super) group: Vec<usize>,
    /// Link frame in its group's frame (in the world frame for links welded to the world).
    pub(super) body_from_link: Vec<Isometry3<f64>>,
    /// The topmost link of each group, whose frame is the group's.
    pub(super) group_root: Vec<usize>,
    /// Links welded to the undeclared world.
    pub(super) world_welded: Vec<bool>,
}

/// Groups the links along the tree (parents are placed before children in `tree.order`).
pub(super) fn group_links(edges: &[Edge], tree: &Tree, links: usize, root: usize) -> Groups {
    let mut g = Groups {
        group: vec![0; links],
        body_from_link: vec![Isometry3::identity(); links],
        group_root: vec![root],
        world_welded: vec![false; links],
    };
    for &k in &tree.order {
        let e = &edges[k];
        let Some(c) = e.child else { continue };
        if e.source == Declaration::Urdf && e.kind == JointKind::Fixed {
            match e.parent {
                Some(p) => {
                    g.group[c] = g.group[p];
                    g.body_from_link[c] = g.body_from_link[p] * e.origin;
                    g.world_welded[c] = g.world_welded[p];
                }
                None => {
                    g.group[c] = 0;
                    g.body_from_link[c] = e.origin;
                    g.world_welded[c] = true;
                }
            }
        } else {
            g.group[c] = g.group_root.len();
            g.group_root.push(c);
        }
    }
    g
}
