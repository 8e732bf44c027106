//! Mimic cycles: a `<mimic>` whose reference, followed from joint to referenced joint, comes
//! back to the joint that mimics (`θ_a = k θ_b`, `θ_b = k' θ_a`): no joint of the cycle has an
//! independent value, so the importer refuses it, naming the first such mimic in file order.
//!
//! The map joint → reference is a functional graph; a joint lies on one of its cycles when the
//! walk from it returns to it. Marking the walks (not seen, on the walk, done) visits each joint
//! once: `O(M)` for `M` mimics, where a walk per mimic would be `O(M²)` on a long chain.

use crate::model::{JointId, Mimic};

/// The joint of the first mimic whose reference, followed through the mimics (the first of
/// each joint), comes back to it, if any.
///
/// With one mimic per joint (URDF has one `<mimic>` per joint) that is the first mimic whose
/// joint lies on a cycle of the map joint → reference: each joint is walked once (`O(M)`).
/// With several on one joint, each mimic's walk is followed (at most `M + 1` steps each).
pub(super) fn first_on_cycle(mimics: &[Mimic], joints: usize) -> Option<JointId> {
    let mut next: Vec<Option<JointId>> = vec![None; joints];
    let mut single = true;
    for m in mimics {
        match next.get_mut(m.joint.0) {
            Some(n @ None) => *n = Some(m.reference),
            Some(Some(_)) => single = false,
            None => return None,
        }
    }
    if !single || mimics.iter().any(|m| m.reference.0 >= joints) {
        let first_of = |j: JointId| next[j.0];
        return mimics
            .iter()
            .find(|start| {
                let mut cur = Some(start.reference);
                for _ in 0..=mimics.len() {
                    match cur {
                        Some(c) if c == start.joint => return true,
                        Some(c) => cur = first_of(c),
                        None => return false,
                    }
                }
                false
            })
            .map(|m| m.joint);
    }
    // 0: not seen, 1: on the current walk, 2: done; `on_cycle` marks the cycles' joints.
    let mut state = vec![0u8; joints];
    let mut on_cycle = vec![false; joints];
    let mut walk = Vec::new();
    for m in mimics {
        walk.clear();
        let mut cur = Some(m.joint);
        while let Some(c) = cur {
            match state[c.0] {
                2 => break,
                1 => {
                    let from = walk.iter().position(|&w| w == c.0).unwrap_or(0);
                    for &w in &walk[from..] {
                        on_cycle[w] = true;
                    }
                    break;
                }
                _ => {}
            }
            state[c.0] = 1;
            walk.push(c.0);
            cur = next[c.0];
        }
        for &w in &walk {
            state[w] = 2;
        }
    }
    mimics.iter().find(|m| on_cycle[m.joint.0]).map(|m| m.joint)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn m(joint: usize, reference: usize) -> Mimic {
        Mimic {
            joint: JointId(joint),
            reference: JointId(reference),
            multiplier: 1.0,
            offset: 0.0,
        }
    }

    /// A cycle is found at its first mimic in order, a chain that ends is not one, a joint that
    /// mimics itself is, and several mimics on one joint are followed mimic by mimic.
    #[test]
    fn cycles_and_chains() {
        assert_eq!(first_on_cycle(&[m(0, 1), m(1, 2)], 3), None);
        assert_eq!(
            first_on_cycle(&[m(5, 1), m(1, 2), m(2, 1)], 6),
            Some(JointId(1))
        );
        assert_eq!(first_on_cycle(&[m(3, 3)], 4), Some(JointId(3)));
        assert_eq!(first_on_cycle(&[m(0, 1), m(1, 2), m(0, 2)], 3), None);
        assert_eq!(
            first_on_cycle(&[m(0, 1), m(1, 0), m(0, 2)], 3),
            Some(JointId(0))
        );
        // A long chain closed at its end: every joint on the cycle, the first mimic reported.
        let n = 100_000;
        let mut chain: Vec<Mimic> = (0..n - 1).map(|k| m(k, k + 1)).collect();
        assert_eq!(first_on_cycle(&chain, n), None);
        chain.push(m(n - 1, 0));
        assert_eq!(first_on_cycle(&chain, n), Some(JointId(0)));
    }
}
