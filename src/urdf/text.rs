//! From the bytes of a file to XML text that the parser accepts, the way ROS's parser
//! (urdfdom, on TinyXML2) accepts it: Latin-1 decoding when the declaration says so, an XML
//! declaration after leading whitespace or comments, namespace prefixes used without being
//! declared. Each repair leaves a warning. Also the resource bounds of the importer: file size
//! and nesting depth, checked before the (recursive) XML parser sees the text.
//!
//! Repairs keep every byte offset of the original text where they can (a misplaced declaration
//! is blanked, not removed), so that line and column numbers in messages are those of the file.

use super::dom::Document;
use crate::error::{Error, Result};

/// Largest URDF file read \[bytes\] (256 MiB): a description of 100,000 links is ~50 MB.
pub const MAX_FILE_BYTES: u64 = 256 << 20;

/// Deepest element nesting accepted. URDF nests at most ~6 levels (robot, link, visual,
/// geometry, mesh); the XML parser recurses once per level, so a hostile file of 100,000
/// levels would overflow the stack.
pub const MAX_DEPTH: usize = 1_000;

/// The xacro hint.
const XACRO: &str = "xacro macros are not expanded URDF: name the file `*.xacro` to have \
     restpose expand it (feature `xacro`), or run `xacro FILE.urdf.xacro > FILE.urdf` first";

/// Encoding names (lower case) read as Latin-1, where every byte is the code point of that
/// value. `windows-1252` differs only in 0x80–0x9F, which URDF files do not use for markup.
const LATIN1: [&str; 8] = [
    "iso-8859-1",
    "iso_8859-1",
    "iso8859-1",
    "latin1",
    "latin-1",
    "l1",
    "windows-1252",
    "cp1252",
];

/// The encoding declared in a leading `<?xml … encoding="…"?>`, lower case.
fn declared_encoding(bytes: &[u8]) -> Option<String> {
    let head = &bytes[..bytes.len().min(1024)];
    let head: String = head.iter().map(|&b| b as char).collect();
    let at = head.find("<?xml")?;
    let end = at + head[at..].find("?>")?;
    let decl = &head[at..end];
    let e = decl.find("encoding")? + "encoding".len();
    let rest = decl[e..].trim_start().strip_prefix('=')?.trim_start();
    let quote = rest.chars().next().filter(|c| *c == '"' || *c == '\'')?;
    let value = &rest[1..];
    Some(value[..value.find(quote)?].to_ascii_lowercase())
}

/// Decodes the bytes of `file`: UTF-8 (with or without a byte-order mark), or Latin-1 when
/// the declaration names it. UTF-8 without a mark keeps the bytes' buffer (no copy).
///
/// # Errors
/// [`Error::Input`] if the bytes are neither valid UTF-8 nor in a declared encoding restpose
/// reads.
pub(crate) fn decode(mut bytes: Vec<u8>, file: &str) -> Result<String> {
    if bytes.starts_with(b"\xEF\xBB\xBF") {
        bytes.drain(..3);
    }
    let encoding = declared_encoding(&bytes);
    if encoding
        .as_deref()
        .is_some_and(|e| LATIN1.contains(&e) || e == "us-ascii" || e == "ascii")
    {
        return Ok(bytes.iter().map(|&b| b as char).collect());
    }
    String::from_utf8(bytes).map_err(|e| not_utf8(e.as_bytes(), e.utf8_error(), encoding, file))
}

/// The error for bytes that are not UTF-8, at the first bad byte.
fn not_utf8(bytes: &[u8], e: std::str::Utf8Error, encoding: Option<String>, file: &str) -> Error {
    let at = e.valid_up_to();
    let before = &bytes[..at];
    let line = before.iter().filter(|&&b| b == b'\n').count() + 1;
    let line_start = before
        .iter()
        .rposition(|&b| b == b'\n')
        .map_or(0, |p| p + 1);
    let col = String::from_utf8_lossy(&before[line_start..])
        .chars()
        .count()
        + 1;
    Error::Input {
                file: file.to_string(),
                line: line as u32,
                col: col as u32,
                message: format!(
                    "byte 0x{:02X} is not UTF-8 and the file declares {} (restpose reads UTF-8, and ISO-8859-1 when declared)",
                    bytes[at],
                    encoding.map_or("no encoding".to_string(), |e| format!("encoding \"{e}\""))
                ),
                element: String::new(),
            }
}

/// Reads and decodes a URDF file, refusing one larger than [`MAX_FILE_BYTES`].
///
/// # Errors
/// [`Error::Io`] if the file cannot be read, [`Error::Input`] if it is too large or not
/// decodable.
pub fn read_file(path: &std::path::Path) -> Result<String> {
    let io = |cause| Error::Io {
        path: path.display().to_string(),
        cause,
    };
    let len = std::fs::metadata(path).map_err(io)?.len();
    if len > MAX_FILE_BYTES {
        return Err(Error::Input {
            file: path.display().to_string(),
            line: 1,
            col: 1,
            message: format!(
                "the file has {len} bytes, more than the {MAX_FILE_BYTES} bytes (256 MiB) restpose reads"
            ),
            element: String::new(),
        });
    }
    let bytes = std::fs::read(path).map_err(io)?;
    decode(bytes, &path.display().to_string())
}

/// Line and column (from 1, column in characters) of byte offset `at` of `text`.
fn line_col(text: &str, at: usize) -> (u32, u32) {
    let before = &text[..at.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let start = before.rfind('\n').map_or(0, |p| p + 1);
    (line as u32, before[start..].chars().count() as u32 + 1)
}

/// The byte range of an XML declaration that follows leading whitespace or comments (TinyXML2
/// accepts it there; XML does not).
fn late_declaration(text: &str) -> Option<std::ops::Range<usize>> {
    let mut at = 0;
    let b = text.as_bytes();
    if b.starts_with(b"<?xml") {
        return None;
    }
    loop {
        while at < b.len() && b[at].is_ascii_whitespace() {
            at += 1;
        }
        if b[at..].starts_with(b"<!--") {
            at += text[at..].find("-->")? + 3;
        } else if b[at..].starts_with(b"<?xml")
            && b.get(at + 5).is_some_and(|c| c.is_ascii_whitespace())
        {
            let e = text[at..].find("?>")?;
            return Some(at..at + e + 2);
        } else {
            return None;
        }
    }
}

/// Blanks a late XML declaration ([`late_declaration`]), keeping offsets. Returns whether it
/// did.
fn blank_late_declaration(text: &mut String) -> bool {
    let Some(r) = late_declaration(text) else {
        return false;
    };
    let blank: String = text[r.clone()]
        .chars()
        .map(|c| if c == '\n' { '\n' } else { ' ' })
        .collect();
    text.replace_range(r, &blank);
    true
}

/// Refuses text nested deeper than [`MAX_DEPTH`], by a scan that skips comments, CDATA,
/// processing instructions, the DOCTYPE and quoted attribute values. Malformed text is left
/// to the parser, which reports it.
fn check_depth(text: &str, file: &str) -> Result<()> {
    let b = text.as_bytes();
    let mut depth = 0usize;
    let mut i = 0;
    let skip_to = |from: usize, end: &str| text[from..].find(end).map(|e| from + e + end.len());
    while i < b.len() {
        if b[i] != b'<' {
            // To the next `<` (a fast byte search; `i` is always at a character boundary).
            match text.get(i..).map(|t| t.find('<')) {
                Some(Some(k)) => i += k,
                Some(None) => return Ok(()),
                None => i += 1,
            }
            continue;
        }
        let rest = &b[i..];
        let next = if rest.starts_with(b"<!--") {
            skip_to(i, "-->")
        } else if rest.starts_with(b"<![CDATA[") {
            skip_to(i, "]]>")
        } else if rest.starts_with(b"<?") {
            skip_to(i, "?>")
        } else if rest.starts_with(b"<!") {
            // DOCTYPE with an optional internal subset in brackets.
            let mut k = i + 2;
            let mut brackets = 0i32;
            while k < b.len() && !(b[k] == b'>' && brackets <= 0) {
                match b[k] {
                    b'[' => brackets += 1,
                    b']' => brackets -= 1,
                    _ => {}
                }
                k += 1;
            }
            Some(k + 1)
        } else if rest.starts_with(b"</") {
            depth = depth.saturating_sub(1);
            skip_to(i, ">")
        } else {
            // A start tag: skip quoted values (a byte search for the closing quote; `k + 1`
            // follows an ASCII quote, so it is a character boundary), then see whether it
            // closes itself.
            let mut k = i + 1;
            while k < b.len() {
                match b[k] {
                    q @ (b'"' | b'\'') => match text[k + 1..].find(q as char) {
                        Some(e) => k += e + 2,
                        None => k = b.len(),
                    },
                    b'>' => break,
                    _ => k += 1,
                }
            }
            if k < b.len() && b[k - 1] != b'/' {
                depth += 1;
                if depth > MAX_DEPTH {
                    let (line, col) = line_col(text, i);
                    return Err(Error::Input {
                        file: file.to_string(),
                        line,
                        col,
                        message: format!(
                            "elements are nested more than {MAX_DEPTH} levels deep (URDF needs about 6)"
                        ),
                        element: String::new(),
                    });
                }
            }
            Some(k + 1)
        };
        match next {
            Some(n) => i = n,
            None => return Ok(()),
        }
    }
    Ok(())
}

/// The URI given to a prefix used without a declaration, other than `mech:` and `drake:`.
fn undeclared_uri(prefix: &str) -> String {
    format!("urn:restpose:undeclared:{prefix}")
}

/// Parses `text` the way urdfdom reads it: checks the nesting depth, blanks a late XML
/// declaration, declares prefixes used without a declaration (`mech:` and `drake:` to their
/// namespaces, others to a placeholder) on `<robot>`, and refuses xacro. Each repair adds a
/// warning.
///
/// A file that needs no repair is parsed once, in place; a repaired copy is kept in `store`
/// (which the document then borrows).
///
/// # Errors
/// [`Error::Input`] for text nested too deeply, not well-formed XML or a xacro file.
pub(crate) fn parse<'a>(
    text: &'a str,
    file: &str,
    warnings: &mut Vec<String>,
    store: &'a mut Option<String>,
) -> Result<Document<'a>> {
    // Plain XML (most files) is read by the lean reader, which bounds the nesting itself
    // and declines a late declaration; everything else is checked and read as before.
    if let Some(doc) = super::lean::parse(text) {
        refuse_xacro(&doc, file)?;
        return Ok(doc);
    }
    check_depth(text, file)?;
    let late = late_declaration(text).is_some();
    let doc = if late {
        let mut out = text.to_string();
        blank_late_declaration(&mut out);
        warnings.push(format!(
            "{file}: the XML declaration is not at the start of the file; read as if it were"
        ));
        let out = declare_prefixes(out, file, warnings)?;
        super::xml::parse_document(store.insert(out), file)?
    } else {
        match roxmltree::Document::parse_with_options(text, options()) {
            Err(roxmltree::Error::UnknownNamespace(..)) => {
                let out = declare_prefixes(text.to_string(), file, warnings)?;
                super::xml::parse_document(store.insert(out), file)?
            }
            parsed => super::xml::located(parsed, file)?,
        }
    };
    refuse_xacro(&doc, file)?;
    Ok(doc)
}

/// The parser's options (a DTD is allowed, as TinyXML2 skips it).
fn options() -> roxmltree::ParsingOptions {
    roxmltree::ParsingOptions {
        allow_dtd: true,
        ..Default::default()
    }
}

/// Refuses a xacro file: an element in a xacro namespace or an attribute with `${`.
fn refuse_xacro(doc: &Document, file: &str) -> Result<()> {
    // Neither can appear without a `$` in the text and a namespace URI with `xacro` (every
    // element's namespace is one of the document's URIs), or an entity reference that would
    // spell one (byte searches; the element scan walks every attribute of the file).
    let text = doc.input_text();
    let b = text.as_bytes();
    if !holds_either(b, b'$', b'&') && !doc.mentions_uri("xacro") {
        return Ok(());
    }
    for n in doc.descendants().filter(|n| n.is_element()) {
        let xacro = n
            .tag_name()
            .namespace()
            .is_some_and(|u| u.contains("xacro"));
        if xacro || n.attributes().any(|a| a.value().contains("${")) {
            let (line, col) = line_col(text, n.range().start);
            return Err(Error::Input {
                file: file.to_string(),
                line,
                col,
                message: XACRO.into(),
                element: n.tag_name().name().to_string(),
            });
        }
    }
    Ok(())
}

/// Whether `b` holds byte `x` or `y`: 32 bytes a test without an early exit inside (vector
/// compares), where `memchr` goes a word at a time.
fn holds_either(b: &[u8], x: u8, y: u8) -> bool {
    let blocks = b.chunks_exact(32);
    let tail = blocks.remainder();
    let hit = |c: &[u8]| c.iter().fold(false, |a, &c| a | (c == x) | (c == y));
    blocks.into_iter().any(hit) || hit(tail)
}

/// Declares on `<robot>` each prefix the parser finds used without a declaration, until it
/// finds none (the text may still be malformed otherwise: the caller's parse reports that).
fn declare_prefixes(mut out: String, file: &str, warnings: &mut Vec<String>) -> Result<String> {
    // Each round declares one prefix; a file uses a handful.
    for _ in 0..64 {
        let (prefix, pos) = match roxmltree::Document::parse_with_options(&out, options()) {
            Err(roxmltree::Error::UnknownNamespace(prefix, pos)) => (prefix, pos),
            _ => return Ok(out),
        };
        let uri = match prefix.as_str() {
            "mech" => super::xml::MECH_NS.to_string(),
            "drake" => super::edges::DRAKE_NS.to_string(),
            "xacro" => {
                return Err(Error::Input {
                    file: file.to_string(),
                    line: pos.row,
                    col: pos.col,
                    message: XACRO.into(),
                    element: String::new(),
                })
            }
            other => undeclared_uri(other),
        };
        let Some(at) = out.find("<robot").map(|p| p + "<robot".len()) else {
            return Ok(out);
        };
        out.insert_str(at, &format!(" xmlns:{prefix}=\"{uri}\""));
        warnings.push(format!(
            "{file}:{}:{}: the `{prefix}:` prefix is used but not declared; assumed xmlns:{prefix}=\"{uri}\"",
            pos.row, pos.col
        ));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    /// The block test finds a byte at every offset of blocks and tails, and no other.
    #[test]
    fn holds_either_finds_every_position() {
        for n in [0, 1, 31, 32, 33, 64, 95, 100] {
            let plain = vec![b'x'; n];
            assert!(!super::holds_either(&plain, b'$', b'&'));
            for k in 0..n {
                for c in [b'$', b'&'] {
                    let mut t = plain.clone();
                    t[k] = c;
                    assert!(super::holds_either(&t, b'$', b'&'), "{n} {k}");
                }
            }
        }
    }

    use super::*;

    #[test]
    fn late_declaration_is_blanked_in_place() {
        let mut t = "<!-- c -->\n  <?xml version=\"1.0\"?>\n<robot/>".to_string();
        let before = t.len();
        assert!(blank_late_declaration(&mut t));
        assert_eq!(t.len(), before);
        assert!(!t.contains("<?xml"));
        assert!(roxmltree::Document::parse(&t).is_ok());
        let mut ok = "<?xml version=\"1.0\"?><robot/>".to_string();
        assert!(!blank_late_declaration(&mut ok));
    }

    #[test]
    fn latin1_is_decoded_when_declared() {
        let bytes = b"<?xml version=\"1.0\" encoding=\"ISO-8859-1\"?><robot name=\"r\xE9\"/>";
        let s = decode(bytes.to_vec(), "f").unwrap();
        assert!(s.contains("r\u{e9}"));
        let err = decode(b"<robot name=\"r\xE9\"/>".to_vec(), "f").unwrap_err();
        assert!(err.to_string().starts_with("f:1:15:"), "{err}");
    }

    /// xacro is refused whether written plainly or through a character reference (the byte
    /// search that skips the element scan must not miss it).
    #[test]
    fn xacro_is_refused_also_through_references() {
        let refused = |t: &str| {
            let doc = roxmltree::Document::parse_with_options(t, options()).unwrap();
            refuse_xacro(&Document::from_roxmltree(&doc), "f").is_err()
                && super::super::lean::parse(t).is_none_or(|d| refuse_xacro(&d, "f").is_err())
        };
        assert!(refused(r#"<robot><link name="${a}"/></robot>"#));
        assert!(refused(r#"<robot><link name="&#36;{a}"/></robot>"#));
        assert!(refused(
            r#"<robot xmlns:x="http://www.ros.org/wiki/&#120;acro"><x:macro name="m"/></robot>"#
        ));
        assert!(!refused(r#"<robot><link name="a"/></robot>"#));
        assert!(!refused(r#"<robot><link name="a&amp;b"/></robot>"#));
    }

    #[test]
    fn depth_scan_counts_elements_only() {
        let deep = |n: usize| format!("{}{}", "<a>".repeat(n), "</a>".repeat(n));
        assert!(check_depth(&deep(MAX_DEPTH), "f").is_ok());
        let e = check_depth(&deep(MAX_DEPTH + 1), "f").unwrap_err();
        assert!(e.to_string().contains("nested more than"), "{e}");
        // Self-closing tags, comments, attribute values with `>` and CDATA do not nest.
        let flat = format!(
            "<r>{}<!-- <a> --><b v=\"<a>\"/><![CDATA[<a><a>]]></r>",
            "<c/>".repeat(5000)
        );
        assert!(check_depth(&flat, "f").is_ok());
    }
}
