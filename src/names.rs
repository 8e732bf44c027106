//! "Did you mean": the closest known name to a misspelt one, for every message that names
//! something the input does not have (joints on the command line or in a pose, `mech:`
//! elements and attributes).
//!
//! The distance is Levenshtein's `d(a, b)` (insertions, deletions, substitutions; case
//! ignored). A candidate is suggested when `d ≤ max(2, ⌊|name| / 3⌋)` (the nearest; ties go
//! to the first), else when it is the only candidate that starts with the name.
//!
//! Also the maps from names to indices (`NameMap`): hashed eight bytes at a time,
//! `h ← (rotl(h, 5) ⊕ w) · K` (the multiply-rotate hash of rustc's `FxHasher`), about four times
//! cheaper than the standard library's SipHash on short names. Input names are not an attack
//! surface for a command-line tool, which is what SipHash's keyed hashing is for. A product's
//! bit `i` depends only on its factors' bits `≤ i`, so the low bits of `h` see little of a
//! name's later bytes, and the map places entries by the low bits: the result is
//! `f(f(h) · K)` with `f(x) = x ⊕ (x ≫ 32)`, the high half folded into the low one before and
//! after a product (without it, `link0` … `link9999` fell in a few dozen places of a 16,384-slot
//! table, about twelve probe groups a lookup). The last word is padded with zero bytes, which
//! names do not hold (a length written into its top bits made `link123` and `link1238` equal).

use std::hash::{BuildHasherDefault, Hasher};

/// A map keyed by names with [`NameHasher`].
pub(crate) type NameMap<K, V> = std::collections::HashMap<K, V, BuildHasherDefault<NameHasher>>;

/// The multiply-rotate hash of [`NameMap`].
#[derive(Clone, Copy, Default)]
pub(crate) struct NameHasher(u64);

impl NameHasher {
    const K: u64 = 0x517c_c1b7_2722_0a95;

    fn add(&mut self, w: u64) {
        self.0 = (self.0.rotate_left(5) ^ w).wrapping_mul(Self::K);
    }
}

impl Hasher for NameHasher {
    fn write(&mut self, bytes: &[u8]) {
        let mut chunks = bytes.chunks_exact(8);
        for c in &mut chunks {
            let mut w = [0u8; 8];
            w.copy_from_slice(c);
            self.add(u64::from_le_bytes(w));
        }
        let rest = chunks.remainder();
        if !rest.is_empty() {
            let mut w = [0u8; 8];
            w[..rest.len()].copy_from_slice(rest);
            self.add(u64::from_le_bytes(w));
        }
    }

    fn write_u8(&mut self, i: u8) {
        self.add(u64::from(i));
    }

    fn write_usize(&mut self, i: usize) {
        self.add(i as u64);
    }

    fn finish(&self) -> u64 {
        let h = (self.0 ^ (self.0 >> 32)).wrapping_mul(Self::K);
        h ^ (h >> 32)
    }
}

/// Edit distance between `a` and `b` (insertions, deletions, substitutions), ignoring case.
pub fn distance(a: &str, b: &str) -> usize {
    let a: Vec<char> = a.to_lowercase().chars().collect();
    let b: Vec<char> = b.to_lowercase().chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.iter().enumerate() {
        let mut diag = row[0];
        row[0] = i + 1;
        for (j, cb) in b.iter().enumerate() {
            let next = (diag + usize::from(ca != cb))
                .min(row[j] + 1)
                .min(row[j + 1] + 1);
            diag = row[j + 1];
            row[j + 1] = next;
        }
    }
    row[b.len()]
}

/// The candidate closest to `name` (see the module docs), if one is close.
pub fn closest<'a>(
    name: &str,
    candidates: impl Iterator<Item = &'a str> + Clone,
) -> Option<&'a str> {
    let limit = (name.chars().count() / 3).max(2);
    let near = candidates
        .clone()
        .map(|c| (distance(name, c), c))
        .filter(|(d, _)| *d <= limit)
        .min_by_key(|(d, _)| *d)
        .map(|(_, c)| c);
    near.or_else(|| {
        let lower = name.to_lowercase();
        let mut prefixed = candidates.filter(|c| c.to_lowercase().starts_with(&lower));
        match (prefixed.next(), prefixed.next()) {
            (Some(c), None) if !name.is_empty() => Some(c),
            _ => None,
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn edit_distance() {
        assert_eq!(distance("kitten", "sitting"), 3);
        assert_eq!(distance("", "abc"), 3);
        assert_eq!(distance("Pivot", "pivot"), 0);
        assert_eq!(distance("pivto", "pivot"), 2);
        assert_eq!(distance("pivt", "pivot"), 1);
        assert_eq!(distance("wrist_3_joint", "wrist_2_joint"), 1);
    }

    /// Names that differ only in their last bytes spread over a table's slots (the low bits
    /// of the hash) and tags (its top seven bits) as random hashes would: 10,000 random
    /// 14-bit numbers take about 7,500 distinct values (main's hash: 32 for `link{k}`).
    #[test]
    fn hashes_spread_over_slots_and_tags() {
        use std::hash::BuildHasher;
        let build = BuildHasherDefault::<NameHasher>::default();
        for prefix in ["link", "joint"] {
            let hashes: Vec<u64> = (0..10_000)
                .map(|k| build.hash_one(format!("{prefix}{k}").as_str()))
                .collect();
            let slots: std::collections::HashSet<u64> = hashes.iter().map(|h| h & 0x3fff).collect();
            let tags: std::collections::HashSet<u64> = hashes.iter().map(|h| h >> 57).collect();
            assert!(
                slots.len() > 7_200,
                "{prefix}: {} distinct slots",
                slots.len()
            );
            assert_eq!(tags.len(), 128, "{prefix}");
        }
        // A length written into the last word's top bits made these two equal.
        assert_ne!(build.hash_one("link123"), build.hash_one("link1238"));
    }

    #[test]
    fn closest_name() {
        let names = ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint"];
        let c = || names.iter().copied();
        assert_eq!(closest("shoulder_lift", c()), Some("shoulder_lift_joint"));
        assert_eq!(closest("shoulder", c()), None);
        assert_eq!(
            closest("shoulder_lift_jiont", c()),
            Some("shoulder_lift_joint")
        );
        assert_eq!(closest("pivto", ["pivot"].into_iter()), Some("pivot"));
        assert_eq!(
            closest("refrence", ["reference", "stiffness"].into_iter()),
            Some("reference")
        );
        assert_eq!(closest("xyz", ["pivot"].into_iter()), None);
        assert_eq!(closest("elbo_joint", c()), Some("elbow_joint"));
        assert_eq!(closest("zzz", c()), None);
    }
}
