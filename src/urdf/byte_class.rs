//! The classes of bytes the lean reader (module `lean`) tells apart, as bits of a 256-entry
//! table: `CLASS[c] & NAME_CHAR != 0` is one lookup where a chain of comparisons was.

/// A name's first byte: an ASCII letter or `_`.
pub(super) const NAME_START: u8 = 1;
/// A name's other bytes: ASCII letters, digits, `_`, `-`, `.`.
pub(super) const NAME_CHAR: u8 = 2;
/// Whitespace: space, line feed, tab.
pub(super) const SPACE: u8 = 4;
/// A byte an attribute value may not hold (XML would rewrite or refuse it): `<`, tab, line
/// feed.
pub(super) const NOT_IN_VALUE: u8 = 8;

/// The class bits of every byte.
pub(super) const CLASS: [u8; 256] = {
    let mut t = [0u8; 256];
    let mut c = 0;
    while c < 256 {
        let b = c as u8;
        if b.is_ascii_alphabetic() || b == b'_' {
            t[c] |= NAME_START;
        }
        if b.is_ascii_alphanumeric() || matches!(b, b'_' | b'-' | b'.') {
            t[c] |= NAME_CHAR;
        }
        if matches!(b, b' ' | b'\n' | b'\t') {
            t[c] |= SPACE;
        }
        if matches!(b, b'<' | b'\n' | b'\t') {
            t[c] |= NOT_IN_VALUE;
        }
        c += 1;
    }
    t
};

#[cfg(test)]
mod tests {
    use super::*;

    /// Each bit is the predicate it stands for, on every byte.
    #[test]
    fn classes_are_their_predicates() {
        for c in 0..=255u8 {
            let has = |bit: u8| CLASS[c as usize] & bit != 0;
            assert_eq!(has(NAME_START), c.is_ascii_alphabetic() || c == b'_', "{c}");
            let name = c.is_ascii_alphanumeric() || c == b'_' || c == b'-' || c == b'.';
            assert_eq!(has(NAME_CHAR), name, "{c}");
            assert_eq!(has(SPACE), c == b' ' || c == b'\n' || c == b'\t', "{c}");
            assert_eq!(
                has(NOT_IN_VALUE),
                c == b'<' || c == b'\n' || c == b'\t',
                "{c}"
            );
        }
    }
}
