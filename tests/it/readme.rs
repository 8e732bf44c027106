//! The README and the guide in `docs/` show what the tool prints today, code that compiles, and
//! links that lead somewhere.
//!
//! Every fenced block of `README.md` and `docs/*.md` whose first line is `$ restpose …` is run
//! (from the repository root) and its output compared line by line with the rest of the block.
//! A line that is only `…` stands for any number of lines; a line ending in `…` matches any
//! line that starts with the text before it. `--pose result.json` names the result of
//! `restpose analyze` on the same file, written first. A block may be indented (inside a list
//! item): the fence's indentation is taken off its lines. A block that no longer matches fails
//! with the tool's whole output, to paste into the document.
//!
//! Every ` ```rust ` block must be found in one file of `examples/` (which `cargo test`
//! compiles): its non-empty lines, leading spaces ignored, in order. Every relative link must
//! name an existing file, and its `#anchor` a heading of that file (GitHub's anchors).
use std::path::{Path, PathBuf};
use std::process::Command;

/// A fenced code block: (line number of its first line, info string, lines without the
/// fence's indentation).
struct Block {
    line: usize,
    info: String,
    lines: Vec<String>,
}

/// `README.md` and every `docs/*.md`, with their text.
fn documents() -> Vec<(PathBuf, String)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = vec![root.join("README.md")];
    let mut docs: Vec<PathBuf> = std::fs::read_dir(root.join("docs"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .collect();
    docs.sort();
    files.extend(docs);
    files
        .into_iter()
        .map(|p| {
            let text = std::fs::read_to_string(&p).unwrap();
            (p, text)
        })
        .collect()
}

/// The path of `p` relative to the repository root, for messages.
fn shown(p: &Path) -> String {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    p.strip_prefix(root).unwrap_or(p).display().to_string()
}

/// The fenced code blocks of a markdown text.
fn blocks(text: &str) -> Vec<Block> {
    let lines: Vec<&str> = text.lines().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < lines.len() {
        let trimmed = lines[i].trim_start();
        if let Some(info) = trimmed.strip_prefix("```") {
            let indent = lines[i].len() - trimmed.len();
            let mut body = Vec::new();
            let mut k = i + 1;
            while k < lines.len() && !lines[k].trim_start().starts_with("```") {
                let l = lines[k];
                let strip = l.len() - l.trim_start_matches(' ').len();
                body.push(l[strip.min(indent)..].trim_end().to_string());
                k += 1;
            }
            out.push(Block {
                line: i + 2,
                info: info.trim().to_string(),
                lines: body,
            });
            i = k + 1;
        } else {
            i += 1;
        }
    }
    out
}

/// The `$ restpose` blocks: (line number of the command, arguments, expected output lines).
/// The `$ restpose …` blocks that are run: a fence whose first line is one `restpose`
/// command on the repository's files, followed by its output. A ```` ```console ```` block is a
/// transcript (several commands, pipes, or files outside the repository, such as
/// example-robot-data's) and is shown, not run; so is a block with a second `$ ` line.
fn examples(text: &str) -> Vec<(usize, Vec<String>, Vec<String>)> {
    blocks(text)
        .into_iter()
        .filter(|b| b.info != "console" && b.lines.iter().skip(1).all(|l| !l.starts_with("$ ")))
        .filter_map(|b| {
            let (first, rest) = b.lines.split_first()?;
            let command = first.strip_prefix("$ restpose ")?;
            let args = command.split_whitespace().map(str::to_string).collect();
            Some((b.line, args, rest.to_vec()))
        })
        .collect()
}

/// Whether `actual` matches `expected` with its `…` elisions.
fn matches(expected: &[String], actual: &[&str]) -> bool {
    let Some((first, rest)) = expected.split_first() else {
        return actual.is_empty();
    };
    if first.trim() == "…" {
        return (0..=actual.len()).any(|skip| matches(rest, &actual[skip..]));
    }
    let Some((line, tail)) = actual.split_first() else {
        return false;
    };
    let line = line.trim_end();
    let head = match first.strip_suffix('…') {
        Some(prefix) => line.starts_with(prefix),
        None => line == first,
    };
    head && matches(rest, tail)
}

#[test]
fn readme_examples_print_what_the_readme_shows() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let dir = tempfile::tempdir().unwrap();
    let mut failures = Vec::new();
    let mut count = 0;
    for (path, text) in documents() {
        let blocks = examples(&text);
        if path.ends_with("README.md") && path.parent() == Some(root) {
            assert!(blocks.len() >= 2, "README.md has {} examples", blocks.len());
        }
        for (line, mut args, expected) in blocks {
            count += 1;
            if let Some(k) = args.iter().position(|a| a == "result.json") {
                let file = args.iter().find(|a| a.ends_with(".urdf")).unwrap().clone();
                let result = dir.path().join("result.json");
                let o = Command::new(env!("CARGO_BIN_EXE_restpose"))
                    .current_dir(root)
                    .args(["analyze", &file, "-q", "--json"])
                    .arg(&result)
                    .output()
                    .unwrap();
                assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
                args[k] = result.display().to_string();
            }
            let o = Command::new(env!("CARGO_BIN_EXE_restpose"))
                .current_dir(root)
                .args(&args)
                .output()
                .unwrap();
            let stdout = String::from_utf8_lossy(&o.stdout);
            let actual: Vec<&str> = stdout.lines().collect();
            if !matches(&expected, &actual) {
                failures.push(format!(
                    "{}:{line}: `restpose {}` printed:\n{stdout}",
                    shown(&path),
                    args.join(" ")
                ));
            }
        }
    }
    assert!(count >= 6, "found only {count} examples");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn rust_blocks_are_code_that_an_example_compiles() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let trimmed = |lines: &[String]| -> Vec<String> {
        lines
            .iter()
            .map(|l| l.trim().to_string())
            .filter(|l| !l.is_empty())
            .collect()
    };
    let sources: Vec<(PathBuf, Vec<String>)> = std::fs::read_dir(root.join("examples"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "rs"))
        .map(|p| {
            let lines: Vec<String> = std::fs::read_to_string(&p)
                .unwrap()
                .lines()
                .map(str::to_string)
                .collect();
            (p, trimmed(&lines))
        })
        .collect();
    let in_order = |needle: &[String], hay: &[String]| {
        let mut rest = hay.iter();
        needle.iter().all(|n| rest.any(|h| h == n))
    };
    let mut count = 0;
    let mut failures = Vec::new();
    for (path, text) in documents() {
        for b in blocks(&text).into_iter().filter(|b| b.info == "rust") {
            count += 1;
            let needle = trimmed(&b.lines);
            if !sources.iter().any(|(_, hay)| in_order(&needle, hay)) {
                failures.push(format!(
                    "{}:{}: this rust block is in no file of examples/, so nothing compiles it",
                    shown(&path),
                    b.line
                ));
            }
        }
    }
    assert!(count >= 2, "found only {count} rust blocks");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// GitHub's anchor of a heading: lower case, spaces to `-`, only letters, digits, `-`, `_`.
fn anchor(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter_map(|c| match c {
            ' ' => Some('-'),
            c if c.is_alphanumeric() || c == '-' || c == '_' => Some(c),
            _ => None,
        })
        .collect()
}

/// The anchors of a markdown text's headings (outside code blocks), with GitHub's `-1`, `-2`
/// suffixes for repeated headings.
fn anchors(text: &str) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    let mut fenced = false;
    for line in text.lines() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
        } else if !fenced && line.starts_with('#') {
            let base = anchor(line.trim_start_matches('#'));
            let n = out
                .iter()
                .filter(|a| **a == base || a.starts_with(&format!("{base}-")))
                .count();
            out.push(if n == 0 { base } else { format!("{base}-{n}") });
        }
    }
    out
}

/// The link targets `](target)` of a markdown text, outside code blocks and code spans, with
/// their line numbers.
fn links(text: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    let mut fenced = false;
    for (i, line) in text.lines().enumerate() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
            continue;
        }
        if fenced {
            continue;
        }
        let prose: String = line.split('`').step_by(2).collect::<Vec<_>>().join(" ");
        let mut rest = prose.as_str();
        while let Some(k) = rest.find("](") {
            rest = &rest[k + 2..];
            let end = rest.find(')').unwrap_or(rest.len());
            out.push((i + 1, rest[..end].to_string()));
            rest = &rest[end..];
        }
    }
    out
}

#[test]
fn relative_links_of_the_docs_lead_to_files_and_headings() {
    let mut failures = Vec::new();
    let mut count = 0;
    for (path, text) in documents() {
        let dir = path.parent().unwrap();
        for (line, target) in links(&text) {
            if target.contains("://") || target.starts_with("mailto:") {
                continue;
            }
            count += 1;
            let (file, fragment) = match target.split_once('#') {
                Some((f, a)) => (f, Some(a)),
                None => (target.as_str(), None),
            };
            let linked = if file.is_empty() {
                path.clone()
            } else {
                dir.join(file)
            };
            let at = format!("{}:{line}: link `{target}`", shown(&path));
            if !linked.exists() {
                failures.push(format!("{at}: no file {}", shown(&linked)));
                continue;
            }
            if let Some(fragment) = fragment {
                let text = std::fs::read_to_string(&linked).unwrap_or_default();
                if !anchors(&text).iter().any(|a| a == fragment) {
                    failures.push(format!(
                        "{at}: {} has no heading `#{fragment}`",
                        shown(&linked)
                    ));
                }
            }
        }
    }
    assert!(count >= 20, "found only {count} relative links");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn anchors_are_githubs() {
    assert_eq!(
        anchor(" Large models: the sparse path"),
        "large-models-the-sparse-path"
    );
    assert_eq!(
        anchor(" Is this pose a rest pose? `restpose verify`"),
        "is-this-pose-a-rest-pose-restpose-verify"
    );
    assert_eq!(anchor(" a — b, 1,000"), "a--b-1000");
    assert_eq!(anchors("# A\n```\n# B\n```\n## A\n"), ["a", "a-1"]);
    assert_eq!(
        links("see [a](x.md#y) and `[b](z.md)` ![c](d.png)\n```\n[e](f)\n```\n"),
        [(1, "x.md#y".to_string()), (1, "d.png".to_string())]
    );
}

#[test]
fn elisions_match_what_they_stand_for_and_nothing_else() {
    let e = |v: &[&str]| v.iter().map(|s| s.to_string()).collect::<Vec<_>>();
    assert!(matches(&e(&["a", "…", "d"]), &["a", "b", "c", "d"]));
    assert!(matches(&e(&["a", "…", "d"]), &["a", "d"]));
    assert!(!matches(&e(&["a", "…", "d"]), &["a", "b", "c"]));
    assert!(matches(&e(&["mode: x, …"]), &["mode: x, y, z"]));
    assert!(!matches(&e(&["mode: x, …"]), &["mode: y"]));
    assert!(!matches(&e(&["a", "b"]), &["a", "b", "c"]));
}

#[test]
fn indented_blocks_lose_their_fence_indentation() {
    let b = blocks("1. x\n\n   ```\n   $ restpose check a.urdf\n     two\n   ```\n");
    assert_eq!(b.len(), 1);
    assert_eq!(b[0].lines, ["$ restpose check a.urdf", "  two"]);
    assert_eq!(b[0].line, 4);
}
