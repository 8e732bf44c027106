//! The Jacobian's triplets by runs in the tree KKT matrix (module `shape`): a row's entries on
//! one body come as consecutive columns, which lie at consecutive positions `t, t + 1, …` of one
//! node, so along such a run the slot of `(row, t + j)` is that of `(row, t)` plus `j` and its
//! mirror's that of `(t, row)` plus `j` times the width `step` of the column's block:
//!
//! ```text
//! slot(row, t + j) = slot + j,    slot(t + j, row) = mirror + j · step
//! ```
//!
//! A run of triplets that are each the first to reach their slots is stored as those three
//! numbers (`tree::kkt::TreeKkt::store_jacobian` reads its row's scale once and its values and
//! columns' scales in order); the others keep a pair of slots per triplet.

#[cfg(test)]
use super::shape::FIRST;
use super::shape::{Shape, SKIP};

/// `len` consecutive Jacobian triplets (one row's entries on consecutive columns of one body)
/// and where they go: with `step` [`EACH`], each to its own slots, the next ones of
/// [`Shape::jac_each`]; with `slot` [`SKIP`], nowhere (a row the partition does not pivot);
/// else the `j`-th to slot `slot + j` and its mirror to `mirror + j step` (`mirror` [`SKIP`]:
/// the mirror of a coupling, not stored), each the first triplet to reach its slot. A run of
/// the last kind reads no slot per triplet: its row's scale once, its values and columns'
/// scales in order, and stores them at consecutive slots.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct JacRun {
    pub(crate) len: u32,
    pub(crate) slot: u32,
    pub(crate) mirror: u32,
    pub(crate) step: u32,
}

/// The `step` of a [`JacRun`] whose triplets take their slots from [`Shape::jac_each`].
pub(crate) const EACH: u32 = u32::MAX;

/// Appends a [`JacRun`], joined to the last one where both take their slots one by one, or
/// both go nowhere (fewer runs: the one-by-one triplets of the border come in long stretches).
pub(super) fn push_run(runs: &mut Vec<JacRun>, len: u32, slot: u32, mirror: u32, step: u32) {
    if let Some(last) = runs.last_mut() {
        let joined = (step == EACH && last.step == EACH)
            || (slot == SKIP && last.slot == SKIP && step != EACH && last.step != EACH);
        if joined {
            last.len += len;
            return;
        }
    }
    runs.push(JacRun {
        len,
        slot,
        mirror,
        step,
    });
}

impl Shape {
    /// The slots of every Jacobian triplet, in order, as [`Shape::jac_runs`] and
    /// [`Shape::jac_each`] give them (`(row, column)` and its mirror,
    /// [`FIRST`](super::shape::FIRST) set on the first to reach a slot).
    #[cfg(test)]
    pub(crate) fn jac_slots(&self) -> Vec<[u32; 2]> {
        let mut each = self.jac_each.iter();
        let mut out = Vec::new();
        for run in &self.jac_runs {
            for j in 0..run.len {
                out.push(if run.step == EACH {
                    *each.next().expect("a slot for each triplet")
                } else if run.slot == SKIP {
                    [SKIP, SKIP]
                } else {
                    let mirror = if run.mirror == SKIP {
                        SKIP
                    } else {
                        (run.mirror + j * run.step) | FIRST
                    };
                    [(run.slot + j) | FIRST, mirror]
                });
            }
        }
        assert!(each.next().is_none(), "every slot of `jac_each` is used");
        out
    }
}
