//! The lean reader against `roxmltree`: whatever [`super::lean::parse`] accepts, `roxmltree`
//! accepts into the same document (every node's kind, links, range, name, namespace,
//! attributes and scope), on the repository's robots, on hand-written edge cases and on
//! mutations of a URDF byte by byte.

use super::dom::{Document, Node};

fn roxmltree(text: &str) -> Option<Document<'_>> {
    let opts = roxmltree::ParsingOptions {
        allow_dtd: true,
        ..Default::default()
    };
    roxmltree::Document::parse_with_options(text, opts)
        .ok()
        .map(|d| Document::from_roxmltree(&d))
}

/// Every observable of two documents, node by node.
fn assert_same(a: &Document, b: &Document, what: &str) {
    let (na, nb): (Vec<Node>, Vec<Node>) = (a.descendants().collect(), b.descendants().collect());
    assert_eq!(na.len(), nb.len(), "{what}: node count");
    for (x, y) in na.iter().zip(&nb) {
        let at = format!("{what}: node at {:?}", x.range());
        assert_eq!(x.range(), y.range(), "{at}");
        assert_eq!(x.is_element(), y.is_element(), "{at}");
        assert_eq!(x.is_text(), y.is_text(), "{at}");
        assert_eq!(x.tag_name(), y.tag_name(), "{at}");
        assert_eq!(x.text(), y.text(), "{at}");
        let pos = |n: Option<Node>| n.map(|n| n.range());
        assert_eq!(pos(x.parent()), pos(y.parent()), "{at}");
        assert_eq!(pos(x.parent_element()), pos(y.parent_element()), "{at}");
        let kids = |n: &Node| n.children().map(|c| c.range()).collect::<Vec<_>>();
        assert_eq!(kids(x), kids(y), "{at}");
        assert_eq!(x.descendants().count(), y.descendants().count(), "{at}");
        fn attrs<'a>(n: &Node<'a, '_>) -> Vec<(Option<&'a str>, &'a str, &'a str)> {
            n.attributes()
                .map(|a| (a.namespace(), a.name(), a.value()))
                .collect()
        }
        assert_eq!(attrs(x), attrs(y), "{at}");
        for (_, name, _) in attrs(x) {
            assert_eq!(x.attribute(name), y.attribute(name), "{at}");
        }
        for uri in ["urn:urdf-mech:1", "http://drake.mit.edu", "urn:a", "urn:b"] {
            assert_eq!(x.lookup_prefix(uri), y.lookup_prefix(uri), "{at} {uri}");
        }
    }
    assert_eq!(a.root_element().range(), b.root_element().range(), "{what}");
}

/// Accepted by the lean reader: the same document as roxmltree's.
fn check(text: &str, what: &str) -> bool {
    match super::lean::parse(text) {
        Some(lean) => {
            let full = roxmltree(text)
                .unwrap_or_else(|| panic!("{what}: lean accepted what roxmltree refuses"));
            assert_same(&lean, &full, what);
            true
        }
        None => false,
    }
}

fn urdf_files(dir: &std::path::Path, out: &mut Vec<std::path::PathBuf>) {
    for e in std::fs::read_dir(dir).into_iter().flatten().flatten() {
        let p = e.path();
        if p.is_dir() {
            urdf_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "urdf") {
            out.push(p);
        }
    }
}

#[test]
fn robots_read_the_same() {
    let mut files = Vec::new();
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    urdf_files(&root.join("robots"), &mut files);
    urdf_files(&root.join("tests"), &mut files);
    assert!(files.len() > 15, "{}", files.len());
    let mut accepted = 0;
    for f in &files {
        let text = std::fs::read_to_string(f).unwrap_or_default();
        accepted += usize::from(check(&text, &f.display().to_string()));
    }
    assert!(accepted > 10, "{accepted} of {}", files.len());
}

#[test]
fn edge_cases_read_the_same_or_decline() {
    let accepted = [
        "<r/>",
        "<?xml version=\"1.0\"?>\n<r a='1' b = \"x>y\"/>",
        "<?xml version='1.0' encoding='UTF-8' standalone='yes' ?><r/>",
        "<!-- c --><r>t<!-- d -->u<e/> <f></f ></r><!-- e -->\n",
        "<r xmlns:m='urn:a'><m:x m:a='1' a='2'/><y xmlns='urn:b'><z/></y></r>",
        "<r xmlns:m='urn:a'><x xmlns:m='urn:b' xmlns:n='urn:a'><m:y/></x></r>",
        "<r xmlns='urn:a' xmlns:m='urn:a'><x/></r>",
        "<robot name=\"a\"><link name=\"l\"><inertial><mass value=\"1\"/></inertial></link></robot>",
    ];
    for t in accepted {
        assert!(check(t, t), "declined: {t}");
    }
    // Well-formed or not, these go to roxmltree.
    let declined = [
        "<r>&amp;</r>",
        "<r a='&#36;'/>",
        "<r>\r\n</r>",
        "<r a='x\ny'/>",
        "<r>\u{e9}</r>",
        "<!DOCTYPE r><r/>",
        "<r><![CDATA[x]]></r>",
        "<r><?pi x?></r>",
        "<r></s>",
        "<r>",
        "<r/><r/>",
        "<r/>t",
        "<r a='1' a='2'/>",
        "<r a='1'b='2'/>",
        "<m:r/>",
        "<r xmlns:m='urn:a' xmlns:m='urn:b'/>",
        "<r xmlns:m=''/>",
        "<r xml:lang='en'/>",
        "<r><!-- a -- b --></r>",
        "<r><!-- a ---></r>",
        "<r>]]></r>",
        "<r a='<'/>",
        "<?xml version=\"2.0\"?><r/>",
        "<?xml encoding='UTF-8'?><r/>",
        "<?xml version='1.0'encoding='UTF-8'?><r/>",
        "<r xmlns:a='urn:a' xmlns:b='urn:a' a:x='1' b:x='2'/>",
        " <?xml version='1.0'?><r/>",
        "",
        "<1r/>",
    ];
    for t in declined {
        assert!(super::lean::parse(t).is_none(), "accepted: {t}");
    }
}

/// Single-byte mutations of a URDF: never accepted where roxmltree refuses, and read the
/// same where both accept.
#[test]
fn mutations_read_the_same_or_decline() {
    let base = "<?xml version=\"1.0\"?>\n<robot name=\"r\" xmlns:mech=\"urn:urdf-mech:1\">\n  <!-- arm -->\n  <link name=\"a\"><inertial><origin xyz=\"0 0 0\"/><mass value=\"1\"/></inertial></link>\n  <joint name=\"j\" type=\"revolute\"><parent link=\"a\"/><child link=\"b\"/></joint>\n  <mech:spring name=\"s\" a='x'>t</mech:spring>\n</robot>\n";
    let alphabet = b"<>/=\"' \n:!-?abmx";
    let mut seed = 0x2545_f491_4f6c_dd1du64;
    let mut next = || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        seed
    };
    let (mut accepted, mut declined) = (0, 0);
    for _ in 0..20_000 {
        let mut b = base.as_bytes().to_vec();
        for _ in 0..1 + next() % 2 {
            let at = (next() % b.len() as u64) as usize;
            let c = alphabet[(next() % alphabet.len() as u64) as usize];
            match next() % 3 {
                0 => b[at] = c,
                1 => b.insert(at, c),
                _ => {
                    b.remove(at);
                }
            }
        }
        let t = String::from_utf8(b).expect("ASCII");
        if check(&t, &t) {
            accepted += 1;
        } else {
            declined += 1;
        }
    }
    assert!(
        accepted > 1000 && declined > 1000,
        "{accepted} / {declined}"
    );
}

/// The lean reader declines where the importer's depth check refuses, and reads what it
/// accepts.
#[test]
fn nesting_beyond_the_limit_is_declined() {
    let deep = |n: usize| format!("{}{}", "<a>".repeat(n), "</a>".repeat(n));
    let limit = super::text::MAX_DEPTH;
    assert!(check(&deep(limit), "at the limit"));
    assert!(super::lean::parse(&deep(limit + 1)).is_none());
    let Err(e) = super::text::parse(&deep(limit + 1), "f", &mut Vec::new(), &mut None) else {
        panic!("read beyond the nesting limit");
    };
    assert!(e.to_string().contains("nested more than"), "{e}");
}

#[test]
fn whitespace_between_tags_is_not_kept_by_either_reader() {
    // Indentation (spaces, tabs, line feeds; carriage returns in roxmltree's reading) makes
    // no node; a text with anything else is kept whole, its whitespace included.
    let text =
        "<robot name=\"r\">\n\t<link name=\"a\">  </link>\n  <x> v 1 </x><y>\n</y>\n</robot>\n";
    let crlf = text.replace('\n', "\r\n");
    let docs = [
        super::lean::parse(text).expect("plain XML"),
        roxmltree(text).expect("well-formed"),
        roxmltree(&crlf).expect("well-formed"),
    ];
    for doc in &docs {
        let texts: Vec<&str> = doc
            .descendants()
            .filter(|n| n.is_text())
            .filter_map(|n| n.text())
            .collect();
        assert_eq!(texts, [" v 1 "]);
        let robot = doc.root_element();
        let kids: Vec<&str> = robot.children().map(|c| c.tag_name().name()).collect();
        assert_eq!(kids, ["link", "x", "y"]);
        let link = robot.children().next().expect("a child");
        assert_eq!((link.text(), link.children().count()), (None, 0));
    }
    assert_same(&docs[0], &docs[1], "indented");
}
