//! A URDF's relative file names made to resolve from another folder: `--write-urdf` writes
//! the input's text (with the rest pose, module `write_back`) to a file that may lie in
//! another folder than the input, and a `<mesh filename="meshes/foot.stl"/>` there would name
//! a file that is not there (re-analysing the written rest then fails with "mesh … was not
//! found").
//!
//! Each `filename` of a `<mesh>` or `<texture>` element that is a relative path (no URI scheme,
//! not absolute) is replaced by the path from the output's folder `O` to the file it named from
//! the input's folder `I`: `relative(I/f, O)`, both folders taken as absolute canonical paths,
//! and `I/f` itself (absolute) where they share no prefix (another drive). A `package://` or
//! `model://` name is kept where it resolves from `O` as well (the package directories given,
//! the environment's, or a package folder above `O`: module `geometry::package`), and replaced
//! the same way by the file it resolves to from `I` where only the walk up from `I` finds it
//! (example-robot-data's `talos_full_v2.urdf` names its meshes `package:///example-robot-data/…`,
//! an empty package name that only the folders above the file resolve). The text is edited in
//! place, as `write_back` edits it: only those attribute values change.

use std::path::{Component, Path, PathBuf};

/// `text` (parsed as the URDF file `file`) with the `filename`s of its `<mesh>` and `<texture>`
/// elements that resolved from the folder `from` only (module docs) rewritten to resolve from
/// the folder `to`; `packages` are the package directories given (`--package NAME=DIR`).
///
/// # Errors
/// [`crate::Error::Input`] if `text` is not well-formed XML.
pub fn relocated(
    text: &str,
    file: &str,
    from: &Path,
    to: &Path,
    packages: &[(String, PathBuf)],
) -> crate::Result<String> {
    let (Ok(from), Ok(to)) = (from.canonicalize(), to.canonicalize()) else {
        return Ok(text.to_string());
    };
    if from == to {
        return Ok(text.to_string());
    }
    let mut warnings = Vec::new();
    let mut repaired = None;
    let doc = super::text::parse(text, file, &mut warnings, &mut repaired)?;
    let text = doc.input_text();
    let mut edits: Vec<(std::ops::Range<usize>, String)> = Vec::new();
    for node in doc.descendants() {
        if !(node.is_element() && (node.is_named("mesh") || node.is_named("texture"))) {
            continue;
        }
        let Some(name) = node.attribute("filename") else {
            continue;
        };
        let target = if name.starts_with("package://") || name.starts_with("model://") {
            let paths = |dir: &Path| crate::geometry::PackagePaths {
                explicit: packages.to_vec(),
                urdf_dir: Some(dir.to_path_buf()),
            };
            if paths(&to).resolve(name).is_ok() {
                continue;
            }
            match paths(&from).resolve(name).map(|p| p.canonicalize()) {
                Ok(Ok(p)) => p,
                _ => continue,
            }
        } else if name.is_empty() || name.contains("://") || Path::new(name).is_absolute() {
            continue;
        } else {
            from.join(name)
        };
        let Some(range) = value_range(text, node.range(), name) else {
            continue;
        };
        let path = relative(&target, &to).unwrap_or(target);
        edits.push((range, super::write_back::escape(&path.to_string_lossy())));
    }
    let mut out = String::with_capacity(text.len() + 64 * edits.len());
    let mut pos = 0;
    for (range, value) in edits {
        out.push_str(&text[pos..range.start]);
        out.push_str(&value);
        pos = range.end;
    }
    out.push_str(&text[pos..]);
    Ok(out)
}

/// The byte range of the `filename` attribute's value in the start tag of the element at
/// `element`, if it is written as `value` (no character reference in it).
fn value_range(
    text: &str,
    element: std::ops::Range<usize>,
    value: &str,
) -> Option<std::ops::Range<usize>> {
    let tag = &text[element.clone()];
    let tag = &tag[..tag.find('>').unwrap_or(tag.len())];
    let mut from = 0;
    while let Some(at) = tag[from..].find("filename") {
        let start = from + at;
        from = start + "filename".len();
        let before = tag[..start].chars().next_back();
        if !before.is_some_and(char::is_whitespace) {
            continue;
        }
        let rest = tag[from..].trim_start();
        let Some(rest) = rest.strip_prefix('=') else {
            continue;
        };
        let rest = rest.trim_start();
        let quote = rest.chars().next()?;
        if quote != '"' && quote != '\'' {
            return None;
        }
        let open = element.start + tag.len() - rest.len() + 1;
        let close = text[open..].find(quote)? + open;
        return (&text[open..close] == value).then_some(open..close);
    }
    None
}

/// The path from the folder `base` to `target` (both absolute), with `..` where it climbs;
/// `None` if they share no root.
fn relative(target: &Path, base: &Path) -> Option<PathBuf> {
    let t: Vec<Component> = target.components().collect();
    let b: Vec<Component> = base.components().collect();
    if t.first() != b.first() {
        return None;
    }
    let common = t.iter().zip(&b).take_while(|(x, y)| x == y).count();
    let mut out = PathBuf::new();
    for _ in common..b.len() {
        out.push("..");
    }
    for c in &t[common..] {
        out.push(c.as_os_str());
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn relative_paths_climb_and_descend() {
        let p = |s: &str| PathBuf::from(s);
        assert_eq!(
            relative(&p("/a/b/meshes/f.stl"), &p("/a/c")),
            Some(p("../b/meshes/f.stl"))
        );
        assert_eq!(relative(&p("/a/b/f.stl"), &p("/a/b")), Some(p("f.stl")));
        assert_eq!(relative(&p("/f.stl"), &p("/x/y")), Some(p("../../f.stl")));
    }

    #[test]
    fn only_relative_mesh_and_texture_names_move() {
        let dir = std::env::temp_dir().join(format!("restpose-relocate-{}", std::process::id()));
        let (input, output) = (dir.join("robot"), dir.join("out"));
        std::fs::create_dir_all(&input).unwrap();
        std::fs::create_dir_all(&output).unwrap();
        let text = r#"<robot name="r"><link name="a"><visual><geometry>
  <mesh filename="meshes/a.stl" scale="1 1 1"/></geometry>
  <material name="m"><texture filename='t.png'/></material></visual>
  <collision><geometry><mesh  filename = "package://p/b.stl"/></geometry></collision>
  <collision><geometry><mesh filename="/abs/c.stl"/></geometry></collision></link>
  <!-- filename="meshes/a.stl" in a comment stays --></robot>"#;
        let out = relocated(text, "r.urdf", &input, &output, &[]).unwrap();
        assert!(
            out.contains(r#"<mesh filename="../robot/meshes/a.stl" scale="1 1 1"/>"#),
            "{out}"
        );
        assert!(
            out.contains("<texture filename='../robot/t.png'/>"),
            "{out}"
        );
        assert!(out.contains(r#"filename = "package://p/b.stl""#), "{out}");
        assert!(out.contains(r#"filename="/abs/c.stl""#), "{out}");
        assert!(out.contains(r#"<!-- filename="meshes/a.stl" in a comment stays -->"#));
        // The same folder: unchanged.
        assert_eq!(
            relocated(text, "r.urdf", &input, &input, &[]).unwrap(),
            text
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn package_names_found_only_above_the_input_move() {
        let dir =
            std::env::temp_dir().join(format!("restpose-relocate-pkg-{}", std::process::id()));
        // share/robots/r/r.urdf names `package:///robots/m/a.stl` (empty package name: the
        // folders above the file) and `package://m/b.stl` (package `m`, given explicitly).
        let (input, output, m) = (
            dir.join("share/robots/r"),
            dir.join("out"),
            dir.join("share/robots/m"),
        );
        for d in [&input, &output, &m] {
            std::fs::create_dir_all(d).unwrap();
        }
        for f in ["a.stl", "b.stl"] {
            std::fs::write(m.join(f), "solid x\nendsolid x\n").unwrap();
        }
        let text = r#"<robot name="r"><link name="a"><collision><geometry>
  <mesh filename="package:///robots/m/a.stl"/></geometry></collision><collision><geometry>
  <mesh filename="package://m/b.stl"/></geometry></collision></link></robot>"#;
        let given = [("m".to_string(), m.clone())];
        let out = relocated(text, "r.urdf", &input, &output, &given).unwrap();
        assert!(
            out.contains(r#"filename="../share/robots/m/a.stl""#),
            "{out}"
        );
        assert!(out.contains(r#"filename="package://m/b.stl""#), "{out}");
        // Without the package given, `m` is found only above the input too.
        let out = relocated(text, "r.urdf", &input, &output, &[]).unwrap();
        assert!(
            out.contains(r#"filename="../share/robots/m/b.stl""#),
            "{out}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
