//! A reader of plain XML into a [`Document`]: the XML that URDF files are written in, read in
//! one pass over the bytes with every string borrowed from the text.
//!
//! It reads a document whose bytes are printable ASCII, tab or line feed, with no entity or
//! character reference, DTD, CDATA section or processing instruction; names of ASCII letters,
//! digits, `_`, `-`, `.` with at most one prefix; attribute values without `<`, tab or line
//! break (which XML would rewrite). On anything else, well-formed or not, it declines
//! (`None`), as for elements nested deeper than [`super::text::MAX_DEPTH`], and the caller
//! reads the text with `roxmltree`, which reads all of XML and
//! reports every error with its position: what this reader accepts, `roxmltree` accepts too,
//! into the same document (compared node by node in the tests, `super::dom_tests`).
//!
//! A start tag's attributes go straight into the document unless one has a prefix or is
//! `xmlns`; such a tag is read again with its namespace declarations by the child module
//! `namespaces` (`lean_namespaces.rs`).

use super::byte_class::{CLASS, NAME_CHAR, NAME_START, NOT_IN_VALUE, SPACE};
use super::dom::{head, is_blank, AttrData, Document, Kind, NodeData, Str};
use namespaces::Raw;

// A child module (it reads the reader's state), kept beside this file.
#[path = "lean_namespaces.rs"]
mod namespaces;

/// An element whose end tag is awaited.
struct Open {
    id: u32,
    /// Its qualified name as written.
    qname: (usize, usize),
    /// Its last child so far (0: none).
    last: u32,
    /// The namespace of an unprefixed name in its scope (as [`NodeData::ns`]).
    default_ns: u32,
}

struct Reader<'i> {
    b: &'i [u8],
    i: usize,
    doc: Document<'i>,
    open: Vec<Open>,
    raw: Vec<Raw>,
}

/// Reads `text`, or declines (`None`) where `roxmltree` must read it.
pub(super) fn parse(text: &str) -> Option<Document<'_>> {
    let b = text.as_bytes();
    if b.len() > (u32::MAX / 2) as usize {
        return None;
    }
    // Printable ASCII, tab and line feed, no `&`; the `<` and `=` counted for the tables'
    // capacities (by blocks without an early exit, which the compiler vectorizes).
    // Byte-wide counters over blocks of 255: sixteen bytes a vector operation.
    let (mut lt, mut eq) = (0usize, 0usize);
    for block in b.chunks(255) {
        let mut bad = 0u8;
        let (mut l, mut e) = (0u8, 0u8);
        for &c in block {
            let printable = c.wrapping_sub(0x20) < 0x5f && c != b'&';
            bad |= u8::from(!(printable || c == b'\n' || c == b'\t'));
            l += u8::from(c == b'<');
            e += u8::from(c == b'=');
        }
        if bad != 0 {
            return None;
        }
        lt += usize::from(l);
        eq += usize::from(e);
    }
    let mut r = Reader {
        b,
        i: 0,
        doc: Document {
            text,
            owned: String::new(),
            // At most an element or comment per `<` and a text before each; capacity never
            // written costs no memory.
            nodes: Vec::with_capacity(2 * lt + 2),
            attrs: Vec::with_capacity(eq),
            scope: Vec::new(),
        },
        open: Vec::with_capacity(16),
        raw: Vec::with_capacity(16),
    };
    r.doc.nodes.push(NodeData {
        kind: Kind::Root,
        parent: 0,
        next_sibling: 0,
        end: 0,
        range: (0, b.len() as u32),
        name: Str::default(),
        ns: 0,
        attrs: (0, 0),
        scope: (0, 0),
    });
    r.open.push(Open {
        id: 0,
        qname: (0, 0),
        last: 0,
        default_ns: 0,
    });
    if b.starts_with(b"<?xml ") {
        r.declaration()?;
    }
    r.misc()?;
    if !(r.b.get(r.i) == Some(&b'<') && r.b.get(r.i + 1).is_some_and(|&c| name_start(c))) {
        return None;
    }
    r.start_tag()?;
    while r.open.len() > 1 {
        r.content()?;
    }
    r.misc()?;
    if r.i != b.len() {
        return None;
    }
    r.doc.nodes[0].end = r.doc.nodes.len() as u32;
    Some(r.doc)
}

fn name_start(c: u8) -> bool {
    CLASS[c as usize] & NAME_START != 0
}

impl<'i> Reader<'i> {
    /// The length of the run of bytes of class `class` from `self.i`.
    fn run(&self, class: u8) -> usize {
        let rest = self.b.get(self.i..).unwrap_or_default();
        rest.iter()
            .position(|&c| CLASS[c as usize] & class == 0)
            .unwrap_or(rest.len())
    }

    fn skip_space(&mut self) -> bool {
        // Most calls find none: one lookup before the scan.
        let at = self.b.get(self.i).copied().unwrap_or(b'<');
        if CLASS[at as usize] & SPACE == 0 {
            return false;
        }
        self.i += self.run(SPACE);
        true
    }

    fn eat(&mut self, s: &[u8]) -> Option<()> {
        self.b[self.i..].starts_with(s).then(|| self.i += s.len())
    }

    /// A name: letters, digits, `_`, `-`, `.`, not starting with a digit, `-` or `.`.
    fn name(&mut self) -> Option<(usize, usize)> {
        let from = self.i;
        if !name_start(*self.b.get(self.i)?) {
            return None;
        }
        self.i += self.run(NAME_CHAR);
        Some((from, self.i))
    }

    /// A qualified name: (prefix, local), the prefix empty when none.
    fn qname(&mut self) -> Option<((usize, usize), (usize, usize))> {
        let first = self.name()?;
        if self.b.get(self.i) == Some(&b':') {
            self.i += 1;
            let local = self.name()?;
            return Some((first, local));
        }
        Some(((first.0, first.0), first))
    }

    /// A quoted value without `<`, tab or line break: its range inside the quotes.
    fn quoted(&mut self) -> Option<(usize, usize)> {
        let q = *self.b.get(self.i)?;
        if q != b'"' && q != b'\'' {
            return None;
        }
        let from = self.i + 1;
        // One pass: the first quote or forbidden byte ends the scan.
        let len = self.b[from..]
            .iter()
            .position(|&c| c == q || CLASS[c as usize] & NOT_IN_VALUE != 0)?;
        if self.b[from + len] != q {
            return None;
        }
        self.i = from + len + 1;
        Some((from, from + len))
    }

    /// `<?xml version="1.x" encoding="…" standalone="yes|no"?>`, the last two optional.
    fn declaration(&mut self) -> Option<()> {
        self.i = 5;
        let mut keys: &[&[u8]] = &[b"version", b"encoding", b"standalone"];
        let mut first = true;
        loop {
            let spaced = self.skip_space();
            if self.eat(b"?>").is_some() {
                return (!first).then_some(());
            }
            let k = keys.iter().position(|k| self.b[self.i..].starts_with(k))?;
            if !spaced || (first && k != 0) {
                return None;
            }
            self.i += keys[k].len();
            self.skip_space();
            self.eat(b"=")?;
            self.skip_space();
            let (a, e) = self.quoted()?;
            let v = &self.b[a..e];
            let ok = match keys[k] {
                b"version" => {
                    v.len() > 2 && v.starts_with(b"1.") && v[2..].iter().all(u8::is_ascii_digit)
                }
                b"encoding" => {
                    !v.is_empty()
                        && v.iter()
                            .all(|&c| c.is_ascii_alphanumeric() || matches!(c, b'.' | b'_' | b'-'))
                }
                _ => v == b"yes" || v == b"no",
            };
            if !ok {
                return None;
            }
            keys = &keys[k + 1..];
            first = false;
        }
    }

    /// Whitespace and comments (outside the root element).
    fn misc(&mut self) -> Option<()> {
        loop {
            self.skip_space();
            if self.b[self.i..].starts_with(b"<!--") {
                self.comment()?;
            } else {
                return Some(());
            }
        }
    }

    /// Appends a node under the open element, linked after its last child.
    fn push(&mut self, data: NodeData) -> u32 {
        let id = self.doc.nodes.len() as u32;
        let open = self.open.last_mut().expect("the document node is open");
        if open.last != 0 {
            self.doc.nodes[open.last as usize].next_sibling = id;
        }
        open.last = id;
        self.doc.nodes.push(NodeData {
            parent: open.id,
            end: id + 1,
            ..data
        });
        id
    }

    fn leaf(kind: Kind, range: (usize, usize), name: (usize, usize)) -> NodeData {
        NodeData {
            kind,
            parent: 0,
            next_sibling: 0,
            end: 0,
            range: (range.0 as u32, range.1 as u32),
            name: Str::of(name.0..name.1),
            ns: 0,
            attrs: (0, 0),
            scope: (0, 0),
        }
    }

    /// `<!--…-->` without `--` inside and not ending in `-`.
    fn comment(&mut self) -> Option<()> {
        let from = self.i;
        let t = from + 4;
        let len = self.b[t..].windows(3).position(|w| w == b"-->")?;
        let body = &self.b[t..t + len];
        if body.windows(2).any(|w| w == b"--") || body.ends_with(b"-") {
            return None;
        }
        self.i = t + len + 3;
        self.push(Self::leaf(Kind::Comment, (from, self.i), (t, t + len)));
        Some(())
    }

    /// The content of the open element up to and including its next child or its end tag.
    fn content(&mut self) -> Option<()> {
        let from = self.i;
        let len = self.b[from..].iter().position(|&c| c == b'<')?;
        if len > 0 {
            let t = &self.b[from..from + len];
            if t.windows(3).any(|w| w == b"]]>") {
                return None;
            }
            self.i += len;
            // Whitespace between tags is not kept (module `dom`: a document holds the texts
            // that say something).
            if !is_blank(t) {
                self.push(Self::leaf(Kind::Text, (from, self.i), (from, self.i)));
            }
        }
        let rest = &self.b[self.i..];
        if rest.starts_with(b"</") {
            self.end_tag()
        } else if rest.starts_with(b"<!--") {
            self.comment()
        } else if rest.len() > 1 && name_start(rest[1]) {
            self.start_tag()
        } else {
            None
        }
    }

    /// `</qname S?>` matching the open element.
    fn end_tag(&mut self) -> Option<()> {
        self.i += 2;
        let from = self.i;
        self.qname()?;
        let open = self.open.pop()?;
        if self.b[from..self.i] != self.b[open.qname.0..open.qname.1] || open.id == 0 {
            return None;
        }
        self.skip_space();
        self.eat(b">")?;
        let n = self.doc.nodes.len() as u32;
        let d = &mut self.doc.nodes[open.id as usize];
        d.end = n;
        d.range.1 = self.i as u32;
        Some(())
    }

    /// A start tag, with its attributes and namespace declarations; an element that is not
    /// empty stays open.
    fn start_tag(&mut self) -> Option<()> {
        let start = self.i;
        self.i += 1;
        let (prefix, local) = self.qname()?;
        let qname = (prefix.0, self.i);
        let written_prefix = &self.b[prefix.0..prefix.1];
        if written_prefix == b"xml" || written_prefix == b"xmlns" {
            return None;
        }
        let open = self.open.last()?;
        let (parent, parent_default) = (open.id as usize, open.default_ns);
        let parent_scope = match self.doc.nodes[parent].kind {
            Kind::Element => self.doc.nodes[parent].scope,
            _ => (0, 0),
        };
        let a0 = self.doc.attrs.len();
        let after_name = self.i;
        // Without declarations the element's scope is its parent's.
        let (empty, scope, default_ns) = match self.plain_attributes(a0)? {
            Some(empty) => (empty, parent_scope, parent_default),
            None => {
                self.doc.attrs.truncate(a0);
                self.i = after_name;
                let (empty, scope) = self.declared_attributes(a0, parent_scope)?;
                (empty, scope, self.namespace(scope, "")?)
            }
        };
        let ns = if prefix.0 == prefix.1 {
            default_ns
        } else {
            self.namespace(scope, &self.doc.text[prefix.0..prefix.1])?
        };
        let id = self.push(NodeData {
            kind: Kind::Element,
            parent: 0,
            next_sibling: 0,
            end: 0,
            range: (start as u32, self.i as u32),
            name: Str::of(local.0..local.1),
            ns,
            attrs: (a0 as u32, self.doc.attrs.len() as u32),
            scope,
        });
        if !empty {
            // Deeper than the importer reads: its depth check gives the error.
            if self.open.len() > super::text::MAX_DEPTH {
                return None;
            }
            self.open.push(Open {
                id,
                qname,
                last: 0,
                default_ns,
            });
        }
        Some(())
    }

    /// A start tag's attributes up to the tag's end, pushed straight into the document while
    /// none has a prefix or is named `xmlns` (no declaration: every attribute in no
    /// namespace, a duplicate a repeated name): whether the element is empty (`/>`), or
    /// `Some(None)` at the first attribute that has a prefix or is `xmlns` (the tag is then
    /// read again by [`Reader::declared_attributes`]).
    fn plain_attributes(&mut self, a0: usize) -> Option<Option<bool>> {
        loop {
            let spaced = self.skip_space();
            match *self.b.get(self.i)? {
                b'/' => {
                    self.eat(b"/>")?;
                    return Some(Some(true));
                }
                b'>' => {
                    self.i += 1;
                    return Some(Some(false));
                }
                _ if spaced => {
                    let (p, l) = self.qname()?;
                    let b = self.b;
                    let name = &b[l.0..l.1];
                    if p.0 != p.1 || (name.len() == 5 && name == b"xmlns") {
                        return Some(None);
                    }
                    self.skip_space();
                    self.eat(b"=")?;
                    self.skip_space();
                    let value = self.quoted()?;
                    let h = head(name);
                    let same = |x: &AttrData| {
                        x.head == h
                            && x.name.len as usize == name.len()
                            && (name.len() <= 4
                                || b[x.name.start as usize + 4..][..name.len() - 4] == name[4..])
                    };
                    if self.doc.attrs[a0..].iter().any(same) {
                        return None;
                    }
                    self.doc.attrs.push(AttrData {
                        ns: 0,
                        name: Str::of(l.0..l.1),
                        value: Str::of(value.0..value.1),
                        head: h,
                    });
                }
                _ => return None,
            }
        }
    }
}
