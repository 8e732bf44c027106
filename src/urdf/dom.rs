//! The importer's XML document: a compact tree of elements, text and comments in document
//! order, with the subset of `roxmltree`'s node interface the importer reads (names and their
//! namespaces, attributes, text, byte ranges, in-scope prefixes).
//!
//! A document comes from one of two readers with the same result:
//! [`super::lean::parse`], a reader of the plain XML that URDF files are written in (ASCII,
//! no entity references, no DTD), which declines anything else; or `roxmltree`, which reads
//! every XML document and reports every error, converted by [`Document::from_roxmltree`]
//! (module `dom_convert`).
//! Each node is 52 bytes with its strings borrowed from the text (`roxmltree` keeps 72 and a
//! table regrown by copies on files written one element per line). Text that is whitespace
//! only (the indentation between tags, about half of a URDF file's nodes) is not kept by
//! either reader: an element's [`Node::text`] is then `None`, which every reader of a text
//! takes as the empty one it trims to.

use std::ops::Range;

/// The namespace URI bound to the `xml` prefix.
const XML_URI: &str = "http://www.w3.org/XML/1998/namespace";

/// A string of the document: a byte range of the input text, or of the document's own
/// buffer (strings `roxmltree` expanded) when the length has its top bit set.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Str {
    pub(super) start: u32,
    pub(super) len: u32,
}

/// The top bit of [`Str::len`]: the string is in [`Document::owned`].
pub(super) const OWNED: u32 = 1 << 31;

impl Str {
    /// The byte range `r` of the input text.
    pub(super) fn of(r: Range<usize>) -> Str {
        Str {
            start: r.start as u32,
            len: (r.end - r.start) as u32,
        }
    }

    /// Its length in bytes.
    fn bytes(self) -> usize {
        (self.len & !OWNED) as usize
    }
}

/// What a node is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Kind {
    /// The document itself (node 0).
    Root,
    Element,
    Text,
    Comment,
    /// A processing instruction.
    Other,
}

/// One node; siblings and subtrees by index (node 0, the root, is nobody's sibling).
#[derive(Clone, Copy, Debug)]
pub(super) struct NodeData {
    pub(super) kind: Kind,
    pub(super) parent: u32,
    /// Next sibling, 0 if none.
    pub(super) next_sibling: u32,
    /// One past the node's last descendant.
    pub(super) end: u32,
    pub(super) range: (u32, u32),
    /// An element's local name; a text's or comment's content.
    pub(super) name: Str,
    /// An element's namespace URI: 1 + its index in [`Document::scope`], 0 for none.
    pub(super) ns: u32,
    /// An element's attributes: a range of [`Document::attrs`].
    pub(super) attrs: (u32, u32),
    /// An element's namespaces in scope: a range of [`Document::scope`].
    pub(super) scope: (u32, u32),
}

/// An attribute: namespace URI (as [`NodeData::ns`]), local name, value, and the name's
/// [`head`] (a lookup compares heads before bytes).
#[derive(Clone, Copy, Debug)]
pub(super) struct AttrData {
    pub(super) ns: u32,
    pub(super) name: Str,
    pub(super) value: Str,
    pub(super) head: u32,
}

/// Whether `text` is XML whitespace only (space, tab, carriage return, line feed): the text
/// between tags that a document does not keep.
pub(super) fn is_blank(text: &[u8]) -> bool {
    text.iter()
        .all(|c| matches!(c, b' ' | b'\t' | b'\r' | b'\n'))
}

/// The first four bytes of `name` as a little-endian number, zero past its end: names
/// (which hold no zero byte) of the same length and head are equal when at most four bytes
/// long; longer ones are compared byte by byte after the head.
#[inline(always)]
pub(super) fn head(name: &[u8]) -> u32 {
    let mut h = 0u32;
    for (k, &c) in name.iter().take(4).enumerate() {
        h |= u32::from(c) << (8 * k);
    }
    h
}

/// A parsed XML document.
pub(crate) struct Document<'i> {
    pub(super) text: &'i str,
    pub(super) owned: String,
    pub(super) nodes: Vec<NodeData>,
    pub(super) attrs: Vec<AttrData>,
    /// In-scope namespaces of elements: `(prefix, uri)`, an element's own declarations first;
    /// also the URIs that names refer to.
    pub(super) scope: Vec<(Option<Str>, Str)>,
}

impl<'i> Document<'i> {
    /// The text of `s`.
    #[inline(always)]
    pub(super) fn str(&self, s: Str) -> &str {
        let (a, b) = (s.start as usize, s.start as usize + s.bytes());
        if s.len & OWNED != 0 {
            &self.owned[a..b]
        } else {
            &self.text[a..b]
        }
    }

    /// Whether `s` is `name`, lengths first, then byte by byte (names are a few bytes: no
    /// call to `memcmp`).
    #[inline(always)]
    fn is(&self, s: Str, name: &str) -> bool {
        s.bytes() == name.len() && self.bytes(s).iter().zip(name.bytes()).all(|(&a, b)| a == b)
    }

    /// The bytes of `s` (no character-boundary test, unlike [`Document::str`]).
    #[inline(always)]
    fn bytes(&self, s: Str) -> &[u8] {
        let all = if s.len & OWNED != 0 {
            &self.owned
        } else {
            self.text
        };
        &all.as_bytes()[s.start as usize..s.start as usize + s.bytes()]
    }

    /// The namespace URI of a name's `ns` ([`NodeData::ns`]).
    #[inline]
    fn uri(&self, ns: u32) -> Option<&str> {
        (ns != 0).then(|| self.str(self.scope[ns as usize - 1].1))
    }

    /// Whether a namespace URI of the document contains `part`.
    pub(crate) fn mentions_uri(&self, part: &str) -> bool {
        self.scope
            .iter()
            .any(|&(_, uri)| self.str(uri).contains(part))
    }

    /// The text the document was read from.
    pub(crate) fn input_text(&self) -> &'i str {
        self.text
    }

    /// The document node.
    pub(crate) fn root(&self) -> Node<'_, 'i> {
        Node { doc: self, id: 0 }
    }

    /// The root element.
    pub(crate) fn root_element(&self) -> Node<'_, 'i> {
        self.root()
            .children()
            .find(|n| n.is_element())
            .unwrap_or(self.root())
    }

    /// Every node in document order, the document node first.
    pub(crate) fn descendants(&self) -> Descendants<'_, 'i> {
        self.root().descendants()
    }
}

/// A node of a [`Document`] (copyable, compared by identity).
#[derive(Clone, Copy)]
pub(crate) struct Node<'a, 'i> {
    doc: &'a Document<'i>,
    id: u32,
}

impl PartialEq for Node<'_, '_> {
    fn eq(&self, other: &Self) -> bool {
        std::ptr::eq(self.doc, other.doc) && self.id == other.id
    }
}

impl std::fmt::Debug for Node<'_, '_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Node({}, {:?})", self.id, self.d().kind)
    }
}

/// An element's name with its namespace URI.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct ExpandedName<'a> {
    ns: Option<&'a str>,
    name: &'a str,
}

impl<'a> ExpandedName<'a> {
    /// The local name.
    pub(crate) fn name(&self) -> &'a str {
        self.name
    }

    /// The namespace URI.
    pub(crate) fn namespace(&self) -> Option<&'a str> {
        self.ns
    }
}

/// An attribute of an element.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Attribute<'a> {
    ns: Option<&'a str>,
    name: &'a str,
    value: &'a str,
}

impl<'a> Attribute<'a> {
    /// The local name.
    pub(crate) fn name(&self) -> &'a str {
        self.name
    }

    /// The namespace URI (none for an unprefixed attribute).
    pub(crate) fn namespace(&self) -> Option<&'a str> {
        self.ns
    }

    /// The value.
    pub(crate) fn value(&self) -> &'a str {
        self.value
    }
}

impl<'a, 'i> Node<'a, 'i> {
    #[inline]
    fn d(&self) -> &'a NodeData {
        &self.doc.nodes[self.id as usize]
    }

    #[inline]
    fn at(&self, id: u32) -> Node<'a, 'i> {
        Node { doc: self.doc, id }
    }

    /// Whether the node is an element.
    #[inline]
    pub(crate) fn is_element(&self) -> bool {
        self.d().kind == Kind::Element
    }

    /// Whether the node is text.
    #[cfg(test)]
    pub(crate) fn is_text(&self) -> bool {
        self.d().kind == Kind::Text
    }

    /// An element's name (empty for other nodes).
    #[inline(always)]
    pub(crate) fn tag_name(&self) -> ExpandedName<'a> {
        let d = self.d();
        if d.kind != Kind::Element {
            return ExpandedName { ns: None, name: "" };
        }
        ExpandedName {
            ns: self.doc.uri(d.ns),
            name: self.doc.str(d.name),
        }
    }

    /// Whether the node is an element of local name `name` (any namespace).
    #[inline]
    pub(crate) fn is_named(&self, name: &str) -> bool {
        let d = self.d();
        d.kind == Kind::Element && self.doc.is(d.name, name)
    }

    /// The attributes of an element.
    pub(crate) fn attributes(&self) -> impl Iterator<Item = Attribute<'a>> + 'a {
        let doc = self.doc;
        let (a, b) = self.d().attrs;
        doc.attrs[a as usize..b as usize]
            .iter()
            .map(move |x| Attribute {
                ns: doc.uri(x.ns),
                name: doc.str(x.name),
                value: doc.str(x.value),
            })
    }

    /// Whether the node is an element in no namespace with every attribute in none.
    #[inline]
    pub(crate) fn is_plain_element(&self) -> bool {
        let d = self.d();
        let (a, b) = d.attrs;
        d.kind == Kind::Element
            && d.ns == 0
            && self.doc.attrs[a as usize..b as usize]
                .iter()
                .all(|x| x.ns == 0)
    }

    /// The attributes of an element that are in a namespace.
    pub(crate) fn namespaced_attributes(&self) -> impl Iterator<Item = Attribute<'a>> + 'a {
        let doc = self.doc;
        let (a, b) = self.d().attrs;
        doc.attrs[a as usize..b as usize]
            .iter()
            .filter(|x| x.ns != 0)
            .map(move |x| Attribute {
                ns: doc.uri(x.ns),
                name: doc.str(x.name),
                value: doc.str(x.value),
            })
    }

    /// The value of the unprefixed attribute `name`.
    #[inline]
    pub(crate) fn attribute(&self, name: &str) -> Option<&'a str> {
        let doc = self.doc;
        let (a, b) = self.d().attrs;
        let (h, n) = (head(name.as_bytes()), name.len());
        doc.attrs[a as usize..b as usize]
            .iter()
            .find(|x| {
                x.head == h
                    && x.ns == 0
                    && x.name.bytes() == n
                    && (n <= 4 || doc.bytes(x.name)[4..] == name.as_bytes()[4..])
            })
            .map(|x| doc.str(x.value))
    }

    /// Whether the element has the unprefixed attribute `name`.
    pub(crate) fn has_attribute(&self, name: &str) -> bool {
        self.attribute(name).is_some()
    }

    /// An element's first child if it is text; a text's or comment's content.
    pub(crate) fn text(&self) -> Option<&'a str> {
        let d = self.d();
        match d.kind {
            Kind::Element => {
                let c = self.id + 1;
                (c < d.end && self.doc.nodes[c as usize].kind == Kind::Text)
                    .then(|| self.doc.str(self.doc.nodes[c as usize].name))
            }
            Kind::Text | Kind::Comment => Some(self.doc.str(d.name)),
            _ => None,
        }
    }

    /// Byte range of the node in the text.
    pub(crate) fn range(&self) -> Range<usize> {
        let (a, b) = self.d().range;
        a as usize..b as usize
    }

    /// The parent node.
    pub(crate) fn parent(&self) -> Option<Node<'a, 'i>> {
        (self.id != 0).then(|| self.at(self.d().parent))
    }

    /// The parent if it is an element.
    pub(crate) fn parent_element(&self) -> Option<Node<'a, 'i>> {
        self.ancestors().skip(1).find(|n| n.is_element())
    }

    /// The node and its ancestors up to the document node.
    pub(crate) fn ancestors(&self) -> impl Iterator<Item = Node<'a, 'i>> {
        std::iter::successors(Some(*self), |n| n.parent())
    }

    /// The children, in document order.
    pub(crate) fn children(&self) -> Children<'a, 'i> {
        let d = self.d();
        Children {
            node: (self.id + 1 < d.end).then(|| self.at(self.id + 1)),
        }
    }

    /// The node and every node under it, in document order.
    pub(crate) fn descendants(&self) -> Descendants<'a, 'i> {
        Descendants {
            doc: self.doc,
            next: self.id,
            end: self.d().end,
        }
    }

    /// The prefix bound to `uri` in the element's scope (`None` for the default namespace).
    pub(crate) fn lookup_prefix(&self, uri: &str) -> Option<&'a str> {
        if uri == XML_URI {
            return Some("xml");
        }
        let doc = self.doc;
        let d = self.d();
        if d.kind != Kind::Element {
            return None;
        }
        doc.scope[d.scope.0 as usize..d.scope.1 as usize]
            .iter()
            .find(|(_, u)| doc.str(*u) == uri)
            .and_then(|(p, _)| p.map(|p| doc.str(p)))
    }
}

/// Iterator over a node's children.
pub(crate) struct Children<'a, 'i> {
    node: Option<Node<'a, 'i>>,
}

impl<'a, 'i> Iterator for Children<'a, 'i> {
    type Item = Node<'a, 'i>;
    #[inline]
    fn next(&mut self) -> Option<Self::Item> {
        let n = self.node?;
        let s = n.d().next_sibling;
        self.node = (s != 0).then(|| n.at(s));
        Some(n)
    }
}

/// Iterator over a subtree in document order.
pub(crate) struct Descendants<'a, 'i> {
    doc: &'a Document<'i>,
    next: u32,
    end: u32,
}

impl<'a, 'i> Iterator for Descendants<'a, 'i> {
    type Item = Node<'a, 'i>;
    fn next(&mut self) -> Option<Self::Item> {
        (self.next < self.end).then(|| {
            self.next += 1;
            Node {
                doc: self.doc,
                id: self.next - 1,
            }
        })
    }
}
