//! The lean reader's start tags that declare namespaces or hold prefixed attributes (module
//! `lean`; in URDF files, `<robot>` with its `xmlns:…`): the declarations in the order
//! written, then the parent's in its order, those not declared again (`roxmltree`'s order of
//! the scope); an attribute's namespace by its prefix; a duplicate is the same local name and
//! namespace URI.

use super::Reader;
use crate::urdf::dom::{head, AttrData, Str};

/// The URI of the `xml` prefix and the reserved one of `xmlns`.
const XML_URI: &str = "http://www.w3.org/XML/1998/namespace";
const XMLNS_URI: &str = "http://www.w3.org/2000/xmlns/";

/// An attribute as written: prefix, local name, value (byte ranges).
pub(super) struct Raw {
    prefix: (usize, usize),
    local: (usize, usize),
    value: (usize, usize),
}

impl Reader<'_> {
    /// The namespace of prefix `p` (empty: none written) in `scope`: 1 + the index of its
    /// scope entry, 0 for none (no prefix and no default namespace); `None` for an undeclared
    /// prefix.
    pub(super) fn namespace(&self, scope: (u32, u32), p: &str) -> Option<u32> {
        let doc = &self.doc;
        let (a, b) = (scope.0 as usize, scope.1 as usize);
        // No prefix: the entry of the default namespace (none of the prefixed ones).
        let found = match p.is_empty() {
            true => doc.scope[a..b].iter().position(|x| x.0.is_none()),
            false => doc.scope[a..b]
                .iter()
                .position(|x| x.0.is_some_and(|q| doc.str(q) == p)),
        };
        match found {
            Some(k) => Some((a + k + 1) as u32),
            None if p.is_empty() => Some(0),
            None => None,
        }
    }

    /// A start tag's attributes where one has a prefix or is `xmlns`: the namespace
    /// declarations, in the order written, then the parent's in its order, those not declared
    /// again (`roxmltree`'s order of the scope); then the other attributes with their
    /// namespaces, a duplicate the same local name and namespace URI. Whether the element is
    /// empty (`/>`), and its scope.
    pub(super) fn declared_attributes(
        &mut self,
        a0: usize,
        parent_scope: (u32, u32),
    ) -> Option<(bool, (u32, u32))> {
        self.raw.clear();
        let empty = loop {
            let spaced = self.skip_space();
            match *self.b.get(self.i)? {
                b'/' => {
                    self.eat(b"/>")?;
                    break true;
                }
                b'>' => {
                    self.i += 1;
                    break false;
                }
                _ if spaced => {
                    let (p, l) = self.qname()?;
                    self.skip_space();
                    self.eat(b"=")?;
                    self.skip_space();
                    let value = self.quoted()?;
                    self.raw.push(Raw {
                        prefix: p,
                        local: l,
                        value,
                    });
                }
                _ => return None,
            }
        };
        let text = self.doc.text;
        let s = |r: (usize, usize)| &text[r.0..r.1];
        let s0 = self.doc.scope.len();
        for a in &self.raw {
            let (p, l, v) = (s(a.prefix), s(a.local), s(a.value));
            let declared = match (p, l) {
                ("xmlns", "xml" | "xmlns") => return None,
                ("xmlns", _) => Some(Some(a.local)),
                ("", "xmlns") => Some(None),
                ("xml", _) => return None,
                _ => None,
            };
            let Some(prefix) = declared else { continue };
            if v.is_empty() || v == XML_URI || v == XMLNS_URI {
                return None;
            }
            let same = |x: &(Option<Str>, Str)| match (x.0, prefix) {
                (None, None) => true,
                (Some(a), Some(b)) => self.doc.str(a) == s(b),
                _ => false,
            };
            if self.doc.scope[s0..].iter().any(same) {
                return None;
            }
            let entry = (
                prefix.map(|p| Str::of(p.0..p.1)),
                Str::of(a.value.0..a.value.1),
            );
            self.doc.scope.push(entry);
        }
        let scope = if self.doc.scope.len() == s0 {
            parent_scope
        } else {
            for k in parent_scope.0..parent_scope.1 {
                let inherited = self.doc.scope[k as usize];
                let p = inherited.0.map(|p| self.doc.str(p));
                let shadowed = self.doc.scope[s0..]
                    .iter()
                    .any(|x| x.0.map(|q| self.doc.str(q)) == p);
                if !shadowed {
                    self.doc.scope.push(inherited);
                }
            }
            (s0 as u32, self.doc.scope.len() as u32)
        };
        for k in 0..self.raw.len() {
            let a = &self.raw[k];
            let (p, l) = (s(a.prefix), s(a.local));
            if p == "xmlns" || (p.is_empty() && l == "xmlns") {
                continue;
            }
            let ans = if p.is_empty() {
                0
            } else {
                self.namespace(scope, p)?
            };
            let doc = &self.doc;
            let uri = |x: u32| (x != 0).then(|| doc.str(doc.scope[x as usize - 1].1));
            let duplicate = doc.attrs[a0..]
                .iter()
                .any(|x| doc.str(x.name) == l && uri(x.ns) == uri(ans));
            if duplicate {
                return None;
            }
            let (local, value) = (a.local, a.value);
            self.doc.attrs.push(AttrData {
                ns: ans,
                name: Str::of(local.0..local.1),
                value: Str::of(value.0..value.1),
                head: head(l.as_bytes()),
            });
        }
        Some((empty, scope))
    }
}
