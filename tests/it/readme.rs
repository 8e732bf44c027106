//! The README's worked examples are what the tool prints today.
//!
//! Every fenced block of `README.md` whose first line is `$ restpose …` is run (from the
//! repository root) and its output compared line by line with the rest of the block. A line
//! that is only `…` stands for any number of lines; a line ending in `…` matches any line that
//! starts with the text before it. `--pose result.json` names the result of
//! `restpose analyze` on the same file, written first. A block that no longer matches fails
//! with the tool's whole output, to paste into the README.
use std::path::Path;
use std::process::Command;

/// The `$ restpose` blocks: (line number of the command, arguments, expected output lines).
fn examples(readme: &str) -> Vec<(usize, Vec<String>, Vec<String>)> {
    let mut out = Vec::new();
    let lines: Vec<&str> = readme.lines().collect();
    let mut i = 0;
    while i < lines.len() {
        let fence = lines[i].trim_start().starts_with("```");
        let command = lines.get(i + 1).and_then(|l| l.strip_prefix("$ restpose "));
        if let (true, Some(command)) = (fence, command) {
            let args = command.split_whitespace().map(str::to_string).collect();
            let mut expected = Vec::new();
            let mut k = i + 2;
            while k < lines.len() && !lines[k].trim_start().starts_with("```") {
                expected.push(lines[k].trim_end().to_string());
                k += 1;
            }
            out.push((i + 2, args, expected));
            i = k + 1;
        } else {
            i += 1;
        }
    }
    out
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
    let readme = std::fs::read_to_string(root.join("README.md")).unwrap();
    let blocks = examples(&readme);
    assert!(blocks.len() >= 4, "found only {} examples", blocks.len());
    let dir = tempfile::tempdir().unwrap();
    let mut failures = Vec::new();
    for (line, mut args, expected) in blocks {
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
                "README.md:{line}: `restpose {}` printed:\n{stdout}",
                args.join(" ")
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
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
