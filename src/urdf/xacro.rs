//! xacro input: a `.xacro` file is expanded to URDF text in-process by the `xacro-rs` crate
//! (macros, properties, conditionals, `$(arg)`, `$(find)`, `load_yaml`), then imported like
//! any URDF.
//!
//! `$(find NAME)` resolves, in order, to the directory given as `packages` (`--package
//! NAME=DIR`), then the way ROS would (`RUST_XACRO_PACKAGE_MAP`, `ROS_PACKAGE_PATH`, a
//! `package.xml` named `NAME` above the file). The same directories resolve the expanded
//! URDF's `package://NAME/…` meshes.
//!
//! Errors of the expansion name the xacro file with `xacro-rs`'s message and macro stack, at
//! the line and column of the failing expression or argument where it is found in the
//! sources (`xacro-rs` gives no position); an error in the expanded URDF names the xacro file with the line and
//! column in the expanded text, and says so.

use crate::error::{Error, Result};
use std::path::{Path, PathBuf};
use xacro_rs::extensions::{ExtensionHandler, FindExtension, OptEnvExtension};
use xacro_rs::XacroProcessor;

/// Whether `path` names a xacro file (`*.xacro`), or `text` declares the xacro namespace and
/// uses it outside its comments (a `xacro:` element or attribute, `${…}` or `$(…)`). A URDF
/// that only declares it, as xacro's own output keeps it (pybullet_data's `diff_ring.urdf`),
/// or mentions xacro only in comments (the commented-out macro calls xacro leaves in its
/// output: Talos, PR2, TIAGo, Bolt, Solo of example-robot-data), is read as URDF, with the
/// URDF reader's leniency (a late XML declaration), its own line numbers in messages, and its
/// `refuse_xacro` check.
pub fn is_xacro(path: &Path, text: &str) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("xacro"))
        || (text.contains("xmlns:xacro=") && uses_xacro(text))
}

/// Whether `text` holds a xacro construct outside its comments (`<!-- … -->`; a CDATA
/// section is text, and `<!--` inside one starts no comment): one pass over the `<!`s.
fn uses_xacro(text: &str) -> bool {
    const MARKERS: [&str; 4] = ["<xacro:", " xacro:", "${", "$("];
    let holds = |s: &str| MARKERS.iter().any(|m| s.contains(m));
    // `segment`: where the text since the last comment starts; `from`: where to look on.
    let (mut segment, mut from) = (0, 0);
    while let Some(i) = text[from..].find("<!") {
        let at = from + i;
        let rest = &text[at..];
        if let Some(body) = rest.strip_prefix("<!--") {
            if holds(&text[segment..at]) {
                return true;
            }
            // An unclosed comment hides the rest (the URDF reader then reports it).
            let Some(end) = body.find("-->") else {
                return false;
            };
            from = at + 4 + end + 3;
            segment = from;
        } else if let Some(body) = rest.strip_prefix("<![CDATA[") {
            from = body.find("]]>").map_or(text.len(), |end| at + 9 + end + 3);
        } else {
            from = at + 2;
        }
    }
    holds(&text[segment..])
}

/// `$(find NAME)` through the user's `NAME=DIR` list; other names go to the next handler.
struct GivenPackages(Vec<(String, PathBuf)>);

impl ExtensionHandler for GivenPackages {
    fn resolve(
        &self,
        command: &str,
        args_raw: &str,
    ) -> std::result::Result<Option<String>, Box<dyn std::error::Error>> {
        if command != "find" {
            return Ok(None);
        }
        let name = args_raw.trim();
        Ok(self
            .0
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, d)| std::path::absolute(d).unwrap_or_else(|_| d.clone()))
            .map(|d| d.display().to_string()))
    }

    fn as_any(&self) -> &dyn std::any::Any {
        self
    }
}

/// The URDF text that the xacro file at `path` expands to with the arguments `args`
/// (`NAME:=VALUE` pairs) and the package directories `packages`.
///
/// # Errors
/// [`Error::Io`] if the file cannot be read, [`Error::Input`] naming the file when the
/// expansion fails (unknown macro or property, a bad expression, an include or `$(find)` that
/// cannot be resolved), with `xacro-rs`'s message and its macro and include stack.
pub fn expand(
    path: &Path,
    args: &[(String, String)],
    packages: &[(String, PathBuf)],
) -> Result<String> {
    if let Err(cause) = std::fs::metadata(path) {
        return Err(Error::Io {
            path: path.display().to_string(),
            cause,
        });
    }
    // Literal defaults of the top file's `<xacro:arg>`s, for the arguments that the user
    // did not give: `xacro-rs` evaluates `<robot name="$(arg name)">` before it reads the
    // `<xacro:arg name="name" default="ur"/>` below it, which python xacro accepts.
    let text = std::fs::read_to_string(path).ok();
    let doc = text
        .as_deref()
        .and_then(|t| roxmltree::Document::parse(t).ok());
    let mut args = args.to_vec();
    for (name, default) in doc.as_ref().map(literal_arg_defaults).unwrap_or_default() {
        if !args.iter().any(|(n, _)| *n == name) {
            args.push((name, default));
        }
    }
    // As python xacro: tolerant of duplicate macro parameters and unusual namespace URIs,
    // ROS units (`!degrees`) in YAML.
    let processor = XacroProcessor::builder()
        .with_args(args.into_iter().collect())
        .with_extension(Box::new(GivenPackages(packages.to_vec())))
        .with_extension(Box::new(FindExtension::new()))
        .with_extension(Box::new(OptEnvExtension::new()))
        .with_compat_all()
        .with_ros_yaml_units()
        .build();
    // `xacro-rs` reads a top file through an unbuffered reader, one `read` system call per
    // byte (110,950 for Talos reduced's 111 kB: a third of its whole run). A file that
    // includes nothing and has no `$(…)` substitution or `load_yaml` (the only constructs
    // that read the file's folder or path) expands the same from its text, read at once.
    match (text.as_deref(), &doc) {
        (Some(t), Some(d)) if self_contained(d) => processor.run_from_string(t),
        _ => processor.run(path),
    }
    .map_err(|e| {
        let text = e.to_string();
        let mut message = String::from("xacro expansion failed: ");
        message.push_str(text.trim_end());
        if text.contains("find") || text.contains("package") {
            message.push_str(&format!(" ({})", crate::geometry::UNKNOWN_PACKAGE_HINT));
        }
        let (file, line, col) =
            source_position(&text, path, packages).unwrap_or_else(|| (path.to_path_buf(), 1, 1));
        Error::Input {
            file: file.display().to_string(),
            line,
            col,
            message,
            element: String::new(),
        }
    })
}

/// Where in the xacro sources an expansion error is: the first `${EXPRESSION` of an
/// "Evaluation error in 'EXPRESSION'", or `$(arg NAME)` of an "Undefined argument: 'NAME'",
/// in the top file, else in the `.xacro` files below its folder and the package folders
/// (`xacro-rs` names only the top file). `None` when the text is not found.
fn source_position(
    message: &str,
    path: &Path,
    packages: &[(String, PathBuf)],
) -> Option<(PathBuf, u32, u32)> {
    let needle = if let Some(rest) = message.split("Evaluation error in '").nth(1) {
        format!("${{{}", rest.split("': ").next()?)
    } else if let Some(rest) = message.split("Undefined argument: '").nth(1) {
        format!("$(arg {})", rest.split('\'').next()?)
    } else {
        return None;
    };
    let mut files = vec![path.to_path_buf()];
    let mut dirs: Vec<PathBuf> = path.parent().map(Path::to_path_buf).into_iter().collect();
    dirs.extend(packages.iter().map(|(_, d)| d.clone()));
    // A bounded walk: at most 2,000 entries.
    let mut seen = 0;
    while let Some(dir) = dirs.pop() {
        let Ok(entries) = std::fs::read_dir(&dir) else {
            continue;
        };
        for e in entries.flatten() {
            seen += 1;
            if seen > 2_000 {
                break;
            }
            let p = e.path();
            if p.is_dir() {
                dirs.push(p);
            } else if p.extension().is_some_and(|x| x == "xacro") && p != path {
                files.push(p);
            }
        }
    }
    files.into_iter().find_map(|f| {
        let text = std::fs::read_to_string(&f).ok()?;
        let at = text.find(&needle)?;
        let before = &text[..at];
        let line = before.matches('\n').count() + 1;
        let col = before[before.rfind('\n').map_or(0, |p| p + 1)..]
            .chars()
            .count()
            + 1;
        Some((f, line as u32, col as u32))
    })
}

/// Renames an importer error located in the expanded text of `path`: the position is in the
/// expansion, which the message says.
pub(crate) fn locate(e: Error, path: &Path) -> Error {
    match e {
        Error::Input {
            line,
            col,
            message,
            element,
            ..
        } => Error::Input {
            file: format!("{} (expanded)", path.display()),
            line,
            col,
            element,
            message: format!(
                "{message} (line and column of the URDF the xacro file expands to; see it with \
                 `xacro-rs {} > expanded.urdf`)",
                path.display()
            ),
        },
        e => e,
    }
}

/// Whether the xacro document `doc` expands without its path: no `include` element, and no
/// `$(…)` or `load_yaml` in an attribute or a text (comments aside).
fn self_contained(doc: &roxmltree::Document) -> bool {
    let path_bound = |v: &str| v.contains("$(") || v.contains("load_yaml");
    doc.descendants().all(|n| {
        if n.is_element() {
            n.tag_name().name() != "include" && !n.attributes().any(|a| path_bound(a.value()))
        } else {
            !n.is_text() || !n.text().is_some_and(path_bound)
        }
    })
}

/// `(name, default)` of each `<xacro:arg>` child of the root of the xacro document `doc`
/// whose default is literal (no `$(…)` or `${…}`).
fn literal_arg_defaults(doc: &roxmltree::Document) -> Vec<(String, String)> {
    doc.root_element()
        .children()
        .filter(|n| {
            n.tag_name().name() == "arg"
                && n.tag_name()
                    .namespace()
                    .is_some_and(|u| u.contains("xacro"))
        })
        .filter_map(|n| Some((n.attribute("name")?, n.attribute("default")?)))
        .filter(|(_, d)| !d.contains("$(") && !d.contains("${"))
        .map(|(n, d)| (n.to_string(), d.to_string()))
        .collect()
}

#[cfg(test)]
mod tests {
    /// [`super::self_contained`] of `text`; `false` if it does not parse (as `expand` then
    /// expands from the path).
    fn self_contained(text: &str) -> bool {
        roxmltree::Document::parse(text).is_ok_and(|d| super::self_contained(&d))
    }

    const NS: &str = r#"xmlns:xacro="http://www.ros.org/wiki/xacro""#;

    /// xacro constructs count outside comments only; a CDATA section is text (its `<!--`
    /// opens no comment, its constructs count).
    #[test]
    fn xacro_constructs_count_outside_comments() {
        let uses = super::uses_xacro;
        // Talos's leftover: commented-out macro calls with `${…}`.
        let commented = r#"<robot><!-- <xacro:gripper name="${name}_x"/> --><link name="l"/><!-- $(find p) --></robot>"#;
        assert!(!uses(commented));
        for text in [
            r#"<robot><xacro:property name="a" value="1"/></robot>"#,
            r#"<robot><!-- note --><link name="${a}"/></robot>"#,
            r#"<robot><link name="l" xacro:if="1"/><!-- x --></robot>"#,
            r#"<robot><![CDATA[ <!-- ]]><xacro:property name="a" value="1"/> --></robot>"#,
            r#"<robot><![CDATA[ $(find p) ]]></robot>"#,
        ] {
            assert!(uses(text), "{text}");
        }
        // An unclosed comment hides the rest (the URDF reader then reports it).
        assert!(!uses(
            r#"<robot><!-- <xacro:property name="a" value="1"/></robot>"#
        ));
        assert!(!uses(""));
    }

    #[test]
    fn only_files_without_path_bound_constructs_expand_from_their_text() {
        let plain = format!(
            r#"<robot name="r" {NS}><!-- File includes: $(find x) --><xacro:property name="a" value="1"/><link name="l"/></robot>"#
        );
        assert!(self_contained(&plain));
        for body in [
            r#"<xacro:include filename="other.xacro"/>"#,
            r#"<xacro:property name="p" value="$(find pkg)/x"/>"#,
            r#"<xacro:property name="y" value="${xacro.load_yaml('a.yaml')}"/>"#,
            r#"<link name="l"><visual>$(cwd)</visual></link>"#,
        ] {
            let text = format!(r#"<robot name="r" {NS}>{body}</robot>"#);
            assert!(!self_contained(&text), "{body}");
        }
        assert!(!self_contained("<robot"));
    }

    #[test]
    fn a_self_contained_file_expands_as_from_its_path() {
        let dir = std::env::temp_dir().join(format!("restpose-xacro-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("r.urdf.xacro");
        let text = format!(
            r#"<robot name="r" {NS}><xacro:property name="l" value="0.5"/><xacro:macro name="m" params="n"><link name="${{n}}"><inertial><mass value="${{2*l}}"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link></xacro:macro><xacro:m n="a"/><xacro:m n="b"/></robot>"#
        );
        std::fs::write(&path, &text).unwrap();
        assert!(self_contained(&text));
        let from_path = xacro_rs::XacroProcessor::builder()
            .with_compat_all()
            .build()
            .run(&path)
            .unwrap();
        let expanded = super::expand(&path, &[], &[]).unwrap();
        std::fs::remove_dir_all(&dir).ok();
        // The same elements and attributes (`xacro-rs` writes attributes in hash order).
        assert_eq!(canonical(&expanded), canonical(&from_path));
        assert!(canonical(&expanded).contains("link[name=b]"));
    }

    fn canonical(xml: &str) -> String {
        let doc = roxmltree::Document::parse(xml).unwrap();
        let mut out = String::new();
        for n in doc.descendants().filter(|n| n.is_element()) {
            let mut attributes: Vec<String> = n
                .attributes()
                .map(|a| format!("{}={}", a.name(), a.value()))
                .collect();
            attributes.sort();
            out.push_str(&format!(
                "{}[{}] ",
                n.tag_name().name(),
                attributes.join(",")
            ));
        }
        out
    }
}
