//! Structure-aware fuzzing of restpose: a mutator of URDF text driven by the dictionary
//! `fuzz/urdf.dict` (the vocabulary of URDF, `mech:` and `drake:`), option choices as the
//! command line offers them, and the harness that takes a mutant where users take a file:
//! import, `check`, solve, `verify` on the solved pose and on the start, with obstacles,
//! contacts and stops as the options say.
//!
//! The same code runs in three places: the cargo-fuzz targets of `fuzz/fuzz_targets/`
//! (coverage-guided, nightly), the proptest smoke test of the default test suite
//! (`tests/it/regressions/issue_25_fuzz_smoke.rs`, stable, bounded), and, mirrored in
//! `fuzz/mutate.py`, the black-box campaign on the binary (`scripts/fuzz_campaign.py`).
//! See `docs/fuzzing.md`.
//!
//! The harness asserts what every input must give: no panic; an error or a result; every
//! number of a result and of a verification finite.

use restpose::model::Friction;
use restpose::urdf::{load_str, ImportOptions};
use restpose::verify::{Tolerances, Unilaterals};
use restpose::{Limits, LinearAlgebra, Method, Options, State};

/// The dictionary (`kind_name="value"` lines).
pub const DICTIONARY: &str = include_str!("../urdf.dict");

/// The dictionary's values by kind (`tag`, `attr`, `num`, `word`, `snippet`).
#[derive(Clone, Debug, Default)]
pub struct Dictionary {
    /// Element names.
    pub tags: Vec<String>,
    /// Attribute names.
    pub attributes: Vec<String>,
    /// Numbers (and a few non-numbers: `nan`, `1e999`, the empty string).
    pub numbers: Vec<String>,
    /// Attribute values: joint types, modes.
    pub words: Vec<String>,
    /// Whole elements; `LINK` and `JOINT` stand for names of the file.
    pub snippets: Vec<String>,
}

impl Dictionary {
    /// Parses [`DICTIONARY`].
    pub fn load() -> Dictionary {
        let mut d = Dictionary::default();
        for line in DICTIONARY.lines().map(str::trim) {
            if line.starts_with('#') {
                continue;
            }
            let Some((key, value)) = line.split_once('=') else {
                continue;
            };
            let value = value
                .strip_prefix('"')
                .and_then(|v| v.strip_suffix('"'))
                .unwrap_or(value)
                .replace("\\\"", "\"");
            let list = match key.split('_').next() {
                Some("tag") => &mut d.tags,
                Some("attr") => &mut d.attributes,
                Some("num") => &mut d.numbers,
                Some("word") => &mut d.words,
                Some("snippet") => &mut d.snippets,
                _ => continue,
            };
            list.push(value);
        }
        d
    }
}

/// One structure-aware edit; the `usize`s pick among the candidates found in the text
/// (modulo their number), so any value is valid.
#[derive(Clone, Debug)]
pub enum Mutation {
    /// Replace one number of an attribute value by a dictionary number.
    Number(usize, usize, usize),
    /// Replace a whole attribute value by a dictionary word, number or a name of the file.
    Value(usize, usize),
    /// Rename a `name`/`link`/`joint` reference to another name of the file, or a new one.
    Rename(usize, usize),
    /// Rename an element (and its closing tag).
    Tag(usize, usize),
    /// Rename an attribute.
    Attribute(usize, usize),
    /// Duplicate an element.
    Duplicate(usize),
    /// Delete an element.
    Delete(usize),
    /// Insert a dictionary snippet before `</robot>`, with names of the file.
    Snippet(usize, usize, usize),
}

/// Attribute spans `(name_start, name_end, value_start, value_end)` of `text`.
fn attributes(text: &str) -> Vec<(usize, usize, usize, usize)> {
    let b = text.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while let Some(k) = text[i..].find("=\"") {
        let eq = i + k;
        let mut s = eq;
        while s > 0 && (b[s - 1].is_ascii_alphanumeric() || b[s - 1] == b'_' || b[s - 1] == b':') {
            s -= 1;
        }
        let v0 = eq + 2;
        let Some(len) = text[v0..].find('"') else {
            break;
        };
        if s < eq {
            out.push((s, eq, v0, v0 + len));
        }
        i = v0 + len + 1;
    }
    out
}

/// Spans of the numbers inside `value`.
fn numbers(value: &str) -> Vec<(usize, usize)> {
    let b = value.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        if b[i].is_ascii_digit() || (b[i] == b'-' && b.get(i + 1).is_some_and(u8::is_ascii_digit)) {
            let s = i;
            i += 1;
            while i < b.len() && (b[i].is_ascii_digit() || b"+-.eE".contains(&b[i])) {
                i += 1;
            }
            out.push((s, i));
        } else {
            i += 1;
        }
    }
    out
}

/// Element start-tag name spans `(start, end)` of `text`.
fn tags(text: &str) -> Vec<(usize, usize)> {
    let b = text.as_bytes();
    let mut out = Vec::new();
    for (i, _) in text.match_indices('<') {
        let s = i + 1;
        if s < b.len() && (b[s].is_ascii_alphabetic() || b[s] == b'_') {
            let mut e = s;
            while e < b.len() && (b[e].is_ascii_alphanumeric() || b"_:-".contains(&b[e])) {
                e += 1;
            }
            out.push((s, e));
        }
    }
    out
}

/// Element spans: self-closing elements and whole elements `<t …>…</t>`.
fn elements(text: &str) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    for (s, e) in tags(text) {
        let name = &text[s..e];
        let Some(close) = text[e..].find('>') else {
            continue;
        };
        let end = e + close + 1;
        if text[..end].ends_with("/>") {
            out.push((s - 1, end));
        } else if let Some(k) = text[end..].find(&format!("</{name}>")) {
            out.push((s - 1, end + k + name.len() + 3));
        }
    }
    out
}

/// The values of the `name`/`link`/`joint` attributes of `text`.
fn names(text: &str) -> Vec<String> {
    attributes(text)
        .into_iter()
        .filter(|a| matches!(&text[a.0..a.1], "name" | "link" | "joint"))
        .map(|a| text[a.2..a.3].to_string())
        .collect()
}

fn pick<T: Clone>(v: &[T], k: usize) -> Option<T> {
    (!v.is_empty()).then(|| v[k % v.len()].clone())
}

fn splice(text: &str, (s, e): (usize, usize), with: &str) -> String {
    format!("{}{with}{}", &text[..s], &text[e..])
}

/// Applies `m` to `text` with the dictionary `d`.
pub fn apply(d: &Dictionary, text: &str, m: &Mutation) -> String {
    let attrs = attributes(text);
    match *m {
        Mutation::Number(a, n, v) => {
            let with_numbers: Vec<_> = attrs
                .iter()
                .filter(|x| !numbers(&text[x.2..x.3]).is_empty())
                .collect();
            let (Some(at), Some(num)) = (pick(&with_numbers, a), pick(&d.numbers, v)) else {
                return text.to_string();
            };
            let spans = numbers(&text[at.2..at.3]);
            let (s, e) = spans[n % spans.len()];
            splice(text, (at.2 + s, at.2 + e), &num)
        }
        Mutation::Value(a, v) => {
            let pool: Vec<String> = d
                .words
                .iter()
                .chain(&d.numbers)
                .cloned()
                .chain(names(text))
                .collect();
            match (pick(&attrs, a), pick(&pool, v)) {
                (Some(at), Some(value)) => splice(text, (at.2, at.3), &value),
                _ => text.to_string(),
            }
        }
        Mutation::Rename(a, v) => {
            let refs: Vec<_> = attrs
                .iter()
                .filter(|x| matches!(&text[x.0..x.1], "name" | "link" | "joint"))
                .copied()
                .collect();
            let Some(at) = pick(&refs, a) else {
                return text.to_string();
            };
            let new = match v % 2 {
                0 => format!("{}_fz", &text[at.2..at.3]),
                _ => pick(&names(text), v / 2).unwrap_or_default(),
            };
            splice(text, (at.2, at.3), &new)
        }
        Mutation::Tag(a, v) => {
            let (Some((s, e)), Some(new)) = (pick(&tags(text), a), pick(&d.tags, v)) else {
                return text.to_string();
            };
            let old = text[s..e].to_string();
            let out = splice(text, (s, e), &new);
            let closing = format!("</{old}>");
            match out[s..].find(&closing) {
                Some(k) => splice(&out, (s + k + 2, s + k + 2 + old.len()), &new),
                None => out,
            }
        }
        Mutation::Attribute(a, v) => match (pick(&attrs, a), pick(&d.attributes, v)) {
            (Some(at), Some(new)) => splice(text, (at.0, at.1), &new),
            _ => text.to_string(),
        },
        Mutation::Duplicate(a) => match pick(&elements(text), a) {
            Some((s, e)) => format!("{}{}{}", &text[..e], &text[s..e], &text[e..]),
            None => text.to_string(),
        },
        Mutation::Delete(a) => match pick(&elements(text), a) {
            Some(span) => splice(text, span, ""),
            None => text.to_string(),
        },
        Mutation::Snippet(k, l, j) => {
            let Some(snippet) = pick(&d.snippets, k) else {
                return text.to_string();
            };
            let element_names = |tag: &str| -> Vec<String> {
                let key = format!("<{tag} name=\"");
                text.match_indices(&key)
                    .filter_map(|(i, _)| {
                        let v = i + key.len();
                        text[v..].find('"').map(|n| text[v..v + n].to_string())
                    })
                    .collect()
            };
            let link = pick(&element_names("link"), l).unwrap_or_else(|| "world".into());
            let joint = pick(&element_names("joint"), j).unwrap_or_else(|| "j".into());
            let s = snippet.replace("LINK", &link).replace("JOINT", &joint);
            match text.rfind("</robot>") {
                Some(at) => format!("{}{s}\n{}", &text[..at], &text[at..]),
                None => format!("{text}{s}"),
            }
        }
    }
}

/// The options of one run, as the command line offers them.
#[derive(Clone, Debug, Default)]
pub struct Choices {
    /// `--floating-base`.
    pub floating_base: bool,
    /// `--ground`.
    pub ground: bool,
    /// `--method`: 0 newton, 1 bfgs, 2 dfp.
    pub method: u8,
    /// `--linear-algebra`: 0 auto, 1 dense, 2 sparse.
    pub linear_algebra: u8,
    /// `--limits ignore`.
    pub ignore_limits: bool,
    /// `--friction stick`.
    pub stick: bool,
    /// `--mu`.
    pub mu: Option<f64>,
    /// `--load-steps`.
    pub load_steps: usize,
}

impl Choices {
    /// Choices from a byte (each bit or pair of bits an option).
    pub fn from_byte(b: u8, extra: u8) -> Choices {
        Choices {
            floating_base: b & 1 != 0,
            ground: b & 2 != 0,
            method: (b >> 2) % 3,
            linear_algebra: (b >> 4) % 3,
            ignore_limits: b & 64 != 0,
            stick: b & 128 != 0,
            mu: (extra & 1 != 0).then_some([0.0, 0.5, 1e9][(extra as usize >> 1) % 3]),
            load_steps: (extra as usize >> 3) % 3,
        }
    }

    fn linear_algebra(&self) -> LinearAlgebra {
        [
            LinearAlgebra::Auto,
            LinearAlgebra::Dense,
            LinearAlgebra::Sparse,
        ][self.linear_algebra as usize % 3]
    }
}

/// What one run reached (for the smoke test's counts).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Reached {
    /// The importer refused the text.
    Refused,
    /// Loaded; too large for a bounded run.
    Large,
    /// Loaded; the solve returned an error.
    SolveError,
    /// Solved; `verify` ran on the solved pose.
    Verified,
}

/// Largest model (bodies) the harness solves: runs stay within milliseconds.
pub const MAX_BODIES: usize = 40;

/// Takes `text` where a user takes a file, with `choices`; panics (the fuzz finding) if
/// anything panics or a reported number is not finite.
pub fn exercise(text: &str, choices: &Choices) -> Reached {
    let import = ImportOptions {
        floating_base: choices.floating_base,
        ground: choices.ground,
        ..Default::default()
    };
    let loaded = match load_str(text, "fuzz.urdf", &import) {
        Ok(l) => l,
        Err(e) => {
            let message = e.to_string();
            assert!(!message.is_empty());
            return Reached::Refused;
        }
    };
    let model = &loaded.model;
    if model.bodies().len() > MAX_BODIES {
        return Reached::Large;
    }
    let _ = restpose::verify::check(model);
    let options = Options {
        method: [Method::Newton, Method::Bfgs, Method::Dfp][choices.method as usize % 3],
        linear_algebra: choices.linear_algebra(),
        max_iterations: 20,
        load_steps: choices.load_steps.max(1),
        limits: if choices.ignore_limits {
            Limits::Ignore
        } else {
            Limits::Enforce
        },
        friction: if choices.stick {
            Friction::Stick
        } else {
            Friction::None
        },
        mu: choices.mu,
        ..Default::default()
    };
    let uni = Unilaterals {
        limits: options.limits,
        friction: options.friction,
        mu: options.mu,
    };
    let verify = |state: &State| {
        if let Ok(v) = restpose::verify::verify_using(
            model,
            state,
            &Tolerances::default(),
            &uni,
            options.linear_algebra,
        ) {
            let numbers = [
                v.constraint_residual,
                v.projected_gradient,
                v.potential_energy,
                v.unassigned,
                v.force_scale,
                v.effort_tolerance,
            ];
            assert!(numbers.iter().all(|x| x.is_finite()), "{v:?}");
            assert!(v.imbalance.iter().all(|i| i.effort.is_finite()), "{v:?}");
        }
    };
    verify(&State::initial(model));
    match restpose::solve(model, &options) {
        Ok((state, report)) => {
            assert!(report.energy.total.is_finite(), "{report:?}");
            assert!(state.q.iter().all(|x| x.is_finite()));
            verify(&state);
            Reached::Verified
        }
        Err(e) => {
            assert!(!e.to_string().contains("NaN"), "{e}");
            Reached::SolveError
        }
    }
}

/// The seed corpus committed in `fuzz/seeds` (robots and the tests' fixtures).
pub fn seeds(corpus: &std::path::Path) -> Vec<(String, String)> {
    let mut out: Vec<(String, String)> = std::fs::read_dir(corpus)
        .map(|d| {
            d.filter_map(Result::ok)
                .map(|e| e.path())
                .filter(|p| p.extension().is_some_and(|e| e == "urdf"))
                .filter_map(|p| {
                    let text = std::fs::read_to_string(&p).ok()?;
                    Some((p.file_name()?.to_string_lossy().into_owned(), text))
                })
                .collect()
        })
        .unwrap_or_default();
    out.sort();
    out
}
