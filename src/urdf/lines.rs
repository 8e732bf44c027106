//! The line table of a text: the byte offset at which each line starts (0, then one past each
//! line feed). The text is tested 32 bytes at a time for a line feed (a vector compare), and
//! only the blocks that hold one are searched byte by byte: lines of URDF files are tens of
//! bytes long, so most blocks cost one test.

/// Byte offsets of the line starts of `text`, ascending, the first 0.
pub(super) fn line_starts(text: &str) -> Vec<usize> {
    let b = text.as_bytes();
    let mut out = Vec::with_capacity(b.len() / 64 + 16);
    out.push(0);
    let blocks = b.chunks_exact(32);
    let tail = blocks.remainder().len();
    for (k, block) in blocks.enumerate() {
        // Without an early exit: one vector compare of the block.
        if block.iter().fold(0u8, |a, &c| a | u8::from(c == b'\n')) != 0 {
            let base = 32 * k;
            for (j, &c) in block.iter().enumerate() {
                if c == b'\n' {
                    out.push(base + j + 1);
                }
            }
        }
    }
    let from = b.len() - tail;
    for (j, &c) in b[from..].iter().enumerate() {
        if c == b'\n' {
            out.push(from + j + 1);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The table is that of the plain search, on texts with line feeds at block borders.
    #[test]
    fn same_as_the_plain_search() {
        let plain = |t: &str| -> Vec<usize> {
            std::iter::once(0)
                .chain(t.match_indices('\n').map(|(i, _)| i + 1))
                .collect()
        };
        let mut texts = vec![String::new(), "\n".into(), "a".into(), "\n\n\n".into()];
        for n in [63, 64, 65, 127, 128, 129, 200] {
            for every in [1, 2, 7, 63, 64, 65] {
                let t: String = (0..n)
                    .map(|i| if i % every == every - 1 { '\n' } else { 'x' })
                    .collect();
                texts.push(t);
            }
        }
        texts.push("é\nü\n".repeat(40));
        for t in &texts {
            assert_eq!(line_starts(t), plain(t), "{t:?}");
        }
    }
}
