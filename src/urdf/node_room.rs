//! Room in the XML parser's node table: a comment after the root element that makes
//! roxmltree size its table once for the whole document.
//!
//! roxmltree (0.20) reserves its node table for `c` nodes, `c` the number of `<` bytes in the
//! text, and shrinks it to the node count after parsing. A URDF written one element per line
//! has about one whitespace text node per line besides its elements, so the nodes outnumber the
//! `<` (the 10,000-link chain of `restpose generate`: 140,007 nodes for 140,005 `<`): the table
//! doubles on its last nodes (a 10 MB copy into 20 MB of fresh pages) and the shrink moves it
//! again. With
//!
//! `N ≈ 2 + (#'<' − #"</") + #{'>' followed by another byte than '<'}`
//!
//! (the root, the start tags, comments and instructions, the text runs, the comment added),
//! an estimate of the node count, the comment `<!--<<…<-->` carries `⌈N (1 + 1/16)⌉ − #'<'`
//! bytes `<` when that is positive: the table is reserved for about `1.06 N` nodes, neither
//! regrows nor moves when shrunk (mimalloc keeps a block shrunk to more than half its size).
//! The estimate only sizes the table: a wrong one costs what the parser cost before.
//!
//! A comment after the root element is a node of the document that no reader of the URDF
//! visits (they read the root element), and it follows the last byte of the file: every
//! position in the file, and so every line and column of a message, is unchanged. Only a
//! file that is not well-formed XML could read differently with it (an unclosed root
//! element or comment); [`super::load_file`] reports the error of the file as it is.

/// Appends the comment of the module doc to `text` where the node table needs it; returns
/// the length of the text before (`text.len()` when nothing is added).
pub(super) fn make_room(text: &mut String) -> usize {
    let len = text.len();
    let b = text.as_bytes();
    let count = |x: u8| b.iter().filter(|&&c| c == x).count();
    let open = count(b'<');
    let closing = b.windows(2).filter(|w| w == b"</").count();
    let runs = b
        .iter()
        .zip(&b[1..])
        .filter(|&(&x, &y)| x == b'>' && y != b'<')
        .count();
    let nodes = 2 + open.saturating_sub(closing) + runs;
    let wanted = nodes + nodes.div_ceil(16);
    // The comment's own `<!--` counts one.
    let Some(pad) = wanted.checked_sub(open + 1).filter(|&p| p > 0) else {
        return len;
    };
    text.reserve(pad + 7);
    text.push_str("<!--");
    text.extend(std::iter::repeat_n('<', pad));
    text.push_str("-->");
    len
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The comment is added after the text (which is kept byte for byte) where the nodes
    /// outnumber the `<`, the padded text parses to the same elements, and the parser's
    /// `<` count then covers the node count.
    #[test]
    fn room_follows_the_text_and_covers_the_nodes() {
        let mut lines = String::from("<?xml version=\"1.0\"?>\n<robot name=\"r\">\n");
        for i in 0..200 {
            lines.push_str(&format!("  <link name=\"l{i}\"><inertial/></link>\n"));
        }
        lines.push_str("</robot>\n");
        let original = lines.clone();
        let mut padded = lines;
        let len = make_room(&mut padded);
        assert_eq!(len, original.len());
        assert!(padded.len() > len, "a text node per line: room is needed");
        assert_eq!(&padded[..len], original);
        let a = roxmltree::Document::parse(&original).unwrap();
        let b = roxmltree::Document::parse(&padded).unwrap();
        let nodes = b.descendants().count();
        assert_eq!(nodes, a.descendants().count() + 1);
        let lt = padded.bytes().filter(|&c| c == b'<').count();
        assert!(lt >= nodes && lt <= 2 * nodes, "{lt} for {nodes} nodes");
        let names = |d: &roxmltree::Document| {
            d.root_element()
                .children()
                .filter(|n| n.is_element())
                .map(|n| n.attribute("name").unwrap_or("").to_string())
                .collect::<Vec<_>>()
        };
        assert_eq!(names(&a), names(&b));
    }

    /// A text with as many `<` as nodes (no text between tags) gets no comment.
    #[test]
    fn no_room_where_the_count_suffices() {
        let mut t = String::from(
            "<robot name=\"r\"><link name=\"a\"></link><link name=\"b\"></link></robot>",
        );
        let before = t.clone();
        assert_eq!(make_room(&mut t), before.len());
        assert_eq!(t, before);
    }
}
