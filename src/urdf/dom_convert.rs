//! `roxmltree`'s document as the importer's [`Document`]: every node in document order, its
//! strings copied into the document's own buffer (`roxmltree` expands references, so they are
//! not byte ranges of the text), subtree ends and sibling links by index.

use super::dom::{head, is_blank, AttrData, Document, Kind, NodeData, Str, OWNED};

impl<'i> Document<'i> {
    /// `roxmltree`'s document, converted.
    pub(crate) fn from_roxmltree(doc: &roxmltree::Document<'i>) -> Document<'i> {
        let mut out = Document {
            text: doc.input_text(),
            owned: String::new(),
            nodes: Vec::new(),
            attrs: Vec::new(),
            scope: Vec::new(),
        };
        let own = |owned: &mut String, s: &str| {
            let start = owned.len() as u32;
            owned.push_str(s);
            Str {
                start,
                len: s.len() as u32 | OWNED,
            }
        };
        // Depth-first with an explicit stack of (roxmltree node, parent index); siblings are
        // linked when the next one is placed.
        let mut last_child: Vec<u32> = Vec::new();
        let mut stack = vec![(doc.root(), 0u32, 0usize)];
        while let Some((n, parent, depth)) = stack.pop() {
            let id = out.nodes.len() as u32;
            let kind = match n.node_type() {
                roxmltree::NodeType::Root => Kind::Root,
                roxmltree::NodeType::Element => Kind::Element,
                roxmltree::NodeType::Text => Kind::Text,
                roxmltree::NodeType::Comment => Kind::Comment,
                roxmltree::NodeType::PI => Kind::Other,
            };
            let mut data = NodeData {
                kind,
                parent,
                next_sibling: 0,
                end: id + 1,
                range: (n.range().start as u32, n.range().end as u32),
                name: Str::default(),
                ns: 0,
                attrs: (0, 0),
                scope: (0, 0),
            };
            match kind {
                Kind::Element => {
                    data.name = own(&mut out.owned, n.tag_name().name());
                    // A name's URI: an entry of the scope table outside every element's range.
                    let uri = |owned: &mut String, scope: &mut Vec<_>, u: Option<&str>| {
                        u.map_or(0, |u| {
                            scope.push((None, own(owned, u)));
                            scope.len() as u32
                        })
                    };
                    data.ns = uri(&mut out.owned, &mut out.scope, n.tag_name().namespace());
                    let a0 = out.attrs.len() as u32;
                    for a in n.attributes() {
                        let ns = uri(&mut out.owned, &mut out.scope, a.namespace());
                        let name = own(&mut out.owned, a.name());
                        let value = own(&mut out.owned, a.value());
                        out.attrs.push(AttrData {
                            ns,
                            name,
                            value,
                            head: head(a.name().as_bytes()),
                        });
                    }
                    data.attrs = (a0, out.attrs.len() as u32);
                    let s0 = out.scope.len() as u32;
                    for s in n.namespaces() {
                        let p = s.name().map(|p| own(&mut out.owned, p));
                        let u = own(&mut out.owned, s.uri());
                        out.scope.push((p, u));
                    }
                    data.scope = (s0, out.scope.len() as u32);
                }
                Kind::Text | Kind::Comment => {
                    data.name = own(&mut out.owned, n.text().unwrap_or(""));
                }
                _ => {}
            }
            // The previous node at this depth under the same parent (`u32::MAX`: none yet).
            last_child.truncate(depth + 1);
            match last_child.get_mut(depth) {
                Some(prev) => {
                    if *prev != u32::MAX {
                        out.nodes[*prev as usize].next_sibling = id;
                    }
                    *prev = id;
                }
                None => last_child.push(id),
            }
            last_child.push(u32::MAX);
            out.nodes.push(data);
            let children: Vec<_> = n
                .children()
                .filter(|c| !(c.is_text() && c.text().is_some_and(|t| is_blank(t.as_bytes()))))
                .collect();
            for c in children.into_iter().rev() {
                stack.push((c, id, depth + 1));
            }
        }
        // Subtree ends, from the last node back: a node ends where its last descendant does.
        for i in (1..out.nodes.len()).rev() {
            let (p, e) = (out.nodes[i].parent as usize, out.nodes[i].end);
            if out.nodes[p].end < e {
                out.nodes[p].end = e;
            }
        }
        out
    }
}
