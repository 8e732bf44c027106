//! The layers of the library, held by a test: each top-level module of `src/` may use only
//! the modules of lower layers (and, within its own layer, only itself), so the module graph
//! has no cycle and no upward import. The table is the architecture of `docs/development.md`:
//!
//! ```text
//! (lcg, tests only)  →  error, math, names, cpu  →  geometry | joint  →  model  →  jet  →  kinematics  →  constraints | forces
//!   →  state  →  urdf | generate  →  solver  →  verify  →  export | view  →  (cli)
//! ```
//!
//! A reference is any `crate::module` path in code (comments and doc links are skipped). A
//! second test holds every file of `src/` to at most 500 lines.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Layer of each top-level module; a module may use modules of strictly lower layers.
const LAYERS: &[(&str, u32)] = &[
    // Test-only: the unit tests' pseudo-random sequence (`#[cfg(test)]`).
    ("lcg", 0),
    ("error", 1),
    ("math", 1),
    ("names", 1),
    // The CPU extensions of the build against the machine's (uses nothing of the crate).
    ("cpu", 1),
    ("geometry", 2),
    ("joint", 2),
    ("model", 3),
    ("jet", 4),
    ("kinematics", 5),
    ("constraints", 6),
    ("forces", 6),
    ("state", 7),
    ("urdf", 8),
    ("generate", 8),
    ("solver", 9),
    ("verify", 10),
    ("export", 11),
    ("view", 11),
    ("cli", 12),
];

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).expect("src/ is readable") {
        let path = entry.expect("directory entry").path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The top-level module a file of `src/` belongs to (`None` for lib.rs and main.rs).
fn module_of(src: &Path, file: &Path) -> Option<String> {
    let rel = file.strip_prefix(src).ok()?;
    let first = rel.components().next()?.as_os_str().to_str()?.to_owned();
    let name = first.trim_end_matches(".rs").to_owned();
    (name != "lib" && name != "main").then_some(name)
}

/// Modules named by `crate::NAME` in the code of `text`, with the line of each use.
fn references(text: &str) -> Vec<(String, usize)> {
    let mut found = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let code = line.trim_start();
        if code.starts_with("//") {
            continue;
        }
        let code = code.split("//").next().unwrap_or("");
        // `use crate::{a, b::c}` groups.
        if let Some(rest) = code.split("crate::{").nth(1) {
            let group = rest.split('}').next().unwrap_or("");
            for item in group.split(',') {
                let head = item.trim().split("::").next().unwrap_or("").trim();
                if !head.is_empty() {
                    found.push((head.to_owned(), n + 1));
                }
            }
        }
        for part in code.split("crate::").skip(1) {
            let head: String = part
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                .collect();
            if !head.is_empty() {
                found.push((head, n + 1));
            }
        }
    }
    found
}

#[test]
fn modules_use_only_lower_layers() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let layer: BTreeMap<&str, u32> = LAYERS.iter().copied().collect();
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    files.sort();
    let mut violations = Vec::new();
    for file in &files {
        let Some(module) = module_of(&src, file) else {
            continue;
        };
        let Some(&own) = layer.get(module.as_str()) else {
            violations.push(format!(
                "{}: module `{module}` has no layer",
                file.display()
            ));
            continue;
        };
        let text = std::fs::read_to_string(file).expect("source is readable");
        for (used, line) in references(&text) {
            if used == module {
                continue;
            }
            match layer.get(used.as_str()) {
                Some(&l) if l < own => {}
                Some(&l) => violations.push(format!(
                    "{}:{line}: `{module}` (layer {own}) uses `{used}` (layer {l})",
                    file.display()
                )),
                // Re-exports at the crate root (`crate::Error`, `crate::Model`) and macros.
                None => {}
            }
        }
    }
    assert!(
        violations.is_empty(),
        "upward or sideways imports:\n{}",
        violations.join("\n")
    );
}

/// Longest file allowed under `src/` [lines]: one concept per file (`docs/architecture.md`).
const MAX_FILE_LINES: usize = 500;

#[test]
fn no_source_file_is_longer_than_the_limit() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    files.sort();
    assert!(
        files.len() > 10,
        "found only {} files under src/",
        files.len()
    );
    let long: Vec<String> = files
        .iter()
        .filter_map(|file| {
            let text = std::fs::read_to_string(file).expect("source is readable");
            let lines = text.lines().count();
            (lines > MAX_FILE_LINES).then(|| format!("{}: {lines} lines", file.display()))
        })
        .collect();
    assert!(
        long.is_empty(),
        "files over {MAX_FILE_LINES} lines (split them by concept):\n{}",
        long.join("\n")
    );
}

/// Library messages speak in library terms: no string literal outside `src/cli/` (and
/// `main.rs`) names a command-line option (`--name`); the CLI adds such hints itself.
#[test]
fn library_strings_name_no_command_line_option() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    files.sort();
    let mut found = Vec::new();
    for file in &files {
        let rel = file.strip_prefix(&src).expect("under src/");
        if rel.starts_with("cli") || rel == Path::new("main.rs") {
            continue;
        }
        let text = std::fs::read_to_string(file).expect("source is readable");
        for (n, line) in text.lines().enumerate() {
            let code = line.trim_start();
            if code.starts_with("//") {
                continue;
            }
            // Text inside string literals: every other piece between quotes.
            let strings = code.split('"').skip(1).step_by(2);
            let flag = strings.into_iter().any(|s| {
                s.match_indices("--")
                    .any(|(i, _)| s[i + 2..].starts_with(|c: char| c.is_ascii_lowercase()))
            });
            if flag {
                found.push(format!("{}:{}: {}", file.display(), n + 1, code));
            }
        }
    }
    assert!(
        found.is_empty(),
        "library strings that name a CLI option:\n{}",
        found.join("\n")
    );
}

/// The folders of the solver wing (issue 20): each is a signpost, its `mod.rs` a `//!` module
/// doc naming what is inside, then only `mod` lines and re-exports (`use`), the code in the
/// files it lists.
const SOLVER_FOLDERS: &[&str] = &[
    "friction",
    "inequality",
    "sparse",
    "stability",
    "step",
    "system",
    "tree",
];

/// The lines of `text` that are neither module docs, attributes, `mod` declarations nor `use`
/// re-exports (a grouped `use` spanning lines counted as one).
fn code_lines(text: &str) -> Vec<(usize, String)> {
    let mut found = Vec::new();
    let mut in_use = false;
    for (n, line) in text.lines().enumerate() {
        let code = line.trim();
        let item = code
            .trim_start_matches("pub(crate) ")
            .trim_start_matches("pub(super) ")
            .trim_start_matches("pub ");
        if in_use {
            in_use = !code.ends_with(';');
            continue;
        }
        if code.is_empty() || code.starts_with("//") || code.starts_with("#[") {
            continue;
        }
        if item.starts_with("mod ") && item.ends_with(';') {
            continue;
        }
        if item.starts_with("use ") {
            in_use = !code.ends_with(';');
            continue;
        }
        found.push((n + 1, code.to_owned()));
    }
    found
}

#[test]
fn solver_folders_are_signposts() {
    let solver = Path::new(env!("CARGO_MANIFEST_DIR")).join("src/solver");
    let mut problems = Vec::new();
    for folder in SOLVER_FOLDERS {
        let file = solver.join(folder).join("mod.rs");
        let Ok(text) = std::fs::read_to_string(&file) else {
            problems.push(format!("{}: missing", file.display()));
            continue;
        };
        if !text.starts_with("//!") {
            problems.push(format!(
                "{}: does not start with a `//!` doc",
                file.display()
            ));
        }
        let mods = text
            .lines()
            .filter(|l| {
                l.trim_start_matches("pub(crate) ")
                    .trim_start_matches("pub(super) ")
                    .starts_with("mod ")
            })
            .count();
        if mods == 0 {
            problems.push(format!("{}: declares no module", file.display()));
        }
        for (line, code) in code_lines(&text) {
            problems.push(format!(
                "{}:{line}: code in a signpost: {code}",
                file.display()
            ));
        }
    }
    // The geometry folder is a signpost too.
    let geometry = Path::new(env!("CARGO_MANIFEST_DIR")).join("src/geometry/mod.rs");
    match std::fs::read_to_string(&geometry) {
        Ok(text) => {
            for (line, code) in code_lines(&text) {
                problems.push(format!(
                    "{}:{line}: code in a signpost: {code}",
                    geometry.display()
                ));
            }
        }
        Err(_) => problems.push(format!("{}: missing", geometry.display())),
    }
    // No other folder hides in the solver without being listed here.
    for entry in std::fs::read_dir(&solver).expect("src/solver is readable") {
        let path = entry.expect("directory entry").path();
        let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
        if path.is_dir() && !SOLVER_FOLDERS.contains(&name) {
            problems.push(format!("{}: folder not in SOLVER_FOLDERS", path.display()));
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

#[test]
fn signpost_check_finds_code() {
    let text = "//! doc\nmod a;\npub(crate) use a::{\n    B,\n};\nfn f() {}\n";
    assert_eq!(code_lines(text), vec![(6, "fn f() {}".to_owned())]);
}

/// One place for joint type names (issue 20): no file of `src/` outside `joint/` (one file per
/// kind) matches a joint type name as a string (`"revolute" =>`, `"ball" |`); the importer
/// and the exports look names up with `joint_type` or call `JointKind::name`.
#[test]
fn joint_type_names_are_matched_in_one_table() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    let table = src.join("joint");
    let names: Vec<&str> = restpose::model::joint_types().map(|t| t.name).collect();
    assert!(names.contains(&"revolute") && names.contains(&"ball"));
    let mut problems = Vec::new();
    for file in files.iter().filter(|f| !f.starts_with(&table)) {
        let text = std::fs::read_to_string(file).expect("source is readable");
        for (n, line) in text.lines().enumerate() {
            let code = line.trim_start();
            if code.starts_with("//") {
                continue;
            }
            for name in &names {
                let quoted = format!("\"{name}\"");
                let arm = [" =>", " |"]
                    .iter()
                    .any(|tail| code.contains(&format!("{quoted}{tail}")));
                if arm {
                    problems.push(format!("{}:{}: {}", file.display(), n + 1, code));
                }
            }
        }
    }
    assert!(
        problems.is_empty(),
        "joint type names matched outside joint/:\n{}",
        problems.join("\n")
    );
}
