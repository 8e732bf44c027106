//! Golden outputs: the result JSON of `restpose analyze ROBOT --json -` for every robot in
//! `robots/`, compared with `tests/golden/ROBOT.json` field by field.
//!
//! Regenerate after an intended change with
//! `RESTPOSE_BLESS=1 cargo test --release --test it golden`, and review the diff.
//!
//! Compared: every key (none missing, none extra), strings and booleans exactly, integers
//! (iterations, counters, sizes) exactly, other numbers within `|a − b| ≤ 1e-9 + 1e-7 |b|`
//! (rounding-level changes pass; any change of the answer fails). Left out: volatile fields
//! (`diagnostics.timings`, wall times), and the mode shape of an eigenvalue closer than a
//! relative 1e-3 to another (its eigenvector is not unique); other mode shapes are compared
//! up to sign.
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;

const RTOL: f64 = 1e-7;
const ATOL: f64 = 1e-9;

fn robots() -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("robots");
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .filter_map(|e| Some(e.ok()?.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "urdf"))
        .collect();
    v.sort();
    v
}

fn golden_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/golden")
}

/// The result JSON without its volatile fields.
fn result(urdf: &Path) -> Value {
    let o = Command::new(env!("CARGO_BIN_EXE_restpose"))
        .arg("analyze")
        .arg(urdf)
        .args(["--json", "-"])
        .output()
        .unwrap();
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}: {}",
        urdf.display(),
        String::from_utf8_lossy(&o.stderr)
    );
    let mut v: Value = serde_json::from_slice(&o.stdout).unwrap();
    if let Some(d) = v.get_mut("diagnostics").and_then(Value::as_object_mut) {
        d.remove("timings");
    }
    v
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= ATOL + RTOL * b.abs()
}

/// Appends to `diffs` every difference between `got` and `want` below `path`.
fn compare(path: &str, got: &Value, want: &Value, diffs: &mut Vec<String>) {
    match (got, want) {
        (Value::Object(g), Value::Object(w)) => {
            for k in w.keys().filter(|k| !g.contains_key(*k)) {
                diffs.push(format!("{path}.{k}: missing"));
            }
            for k in g.keys().filter(|k| !w.contains_key(*k)) {
                diffs.push(format!("{path}.{k}: not in the golden file"));
            }
            for (k, gv) in g {
                if let Some(wv) = w.get(k) {
                    if path == ".stability" && k == "modes" {
                        compare_modes(got, want, diffs);
                    } else {
                        compare(&format!("{path}.{k}"), gv, wv, diffs);
                    }
                }
            }
        }
        (Value::Array(g), Value::Array(w)) => {
            if g.len() != w.len() {
                diffs.push(format!("{path}: {} entries, golden {}", g.len(), w.len()));
            } else {
                for (i, (gv, wv)) in g.iter().zip(w).enumerate() {
                    compare(&format!("{path}[{i}]"), gv, wv, diffs);
                }
            }
        }
        (Value::Number(g), Value::Number(w)) => {
            let exact = g.is_u64() && w.is_u64();
            let (a, b) = (g.as_f64().unwrap(), w.as_f64().unwrap());
            if (exact && g != w) || (!exact && !close(a, b)) {
                diffs.push(format!("{path}: {g}, golden {w}"));
            }
        }
        _ if got != want => diffs.push(format!("{path}: {got}, golden {want}")),
        _ => {}
    }
}

/// Mode shapes of well-separated eigenvalues, up to sign.
fn compare_modes(got: &Value, want: &Value, diffs: &mut Vec<String>) {
    let eig: Vec<f64> = want["eigenvalues"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    let (g, w) = (
        got["modes"].as_array().unwrap(),
        want["modes"].as_array().unwrap(),
    );
    if g.len() != w.len() {
        diffs.push(format!(
            "stability.modes: {} entries, golden {}",
            g.len(),
            w.len()
        ));
        return;
    }
    for (k, (gm, wm)) in g.iter().zip(w).enumerate() {
        let separated = eig.iter().enumerate().all(|(i, &l)| {
            i == k || (l - eig[k]).abs() > 1e-3 * l.abs().max(eig[k].abs()).max(1e-300)
        });
        if !separated {
            continue;
        }
        let mut plus = Vec::new();
        compare(&format!("stability.modes[{k}]"), gm, wm, &mut plus);
        if plus.is_empty() {
            continue;
        }
        let mut minus = Vec::new();
        compare(
            &format!("stability.modes[{k}] (sign flipped)"),
            &negate(gm),
            wm,
            &mut minus,
        );
        if !minus.is_empty() {
            diffs.extend(plus);
        }
    }
}

fn negate(v: &Value) -> Value {
    match v {
        Value::Number(n) => serde_json::json!(-n.as_f64().unwrap()),
        Value::Array(a) => Value::Array(a.iter().map(negate).collect()),
        Value::Object(o) => Value::Object(o.iter().map(|(k, x)| (k.clone(), negate(x))).collect()),
        other => other.clone(),
    }
}

#[test]
fn results_match_the_golden_files() {
    let bless = std::env::var_os("RESTPOSE_BLESS").is_some_and(|v| v == "1");
    let dir = golden_dir();
    let robots = robots();
    assert!(robots.len() >= 11, "{robots:?}");
    let mut failures = Vec::new();
    for urdf in &robots {
        let name = urdf.file_stem().unwrap().to_string_lossy().to_string();
        let file = dir.join(format!("{name}.json"));
        let got = result(urdf);
        if bless {
            std::fs::create_dir_all(&dir).unwrap();
            let text = serde_json::to_string_pretty(&got).unwrap() + "\n";
            std::fs::write(&file, text).unwrap();
            continue;
        }
        let Ok(text) = std::fs::read_to_string(&file) else {
            failures.push(format!("{name}: no golden file {}", file.display()));
            continue;
        };
        let want: Value = serde_json::from_str(&text).unwrap();
        let mut diffs = Vec::new();
        compare("", &got, &want, &mut diffs);
        if !diffs.is_empty() {
            let shown: Vec<&String> = diffs.iter().take(15).collect();
            failures.push(format!(
                "{name}: {} difference(s):\n    {}",
                diffs.len(),
                shown
                    .iter()
                    .map(|s| s.trim_start_matches('.'))
                    .collect::<Vec<_>>()
                    .join("\n    ")
            ));
        }
    }
    // Every golden file belongs to a robot.
    for e in std::fs::read_dir(&dir).into_iter().flatten().flatten() {
        let p = e.path();
        let stem = p.file_stem().unwrap().to_string_lossy().to_string();
        if !robots
            .iter()
            .any(|r| r.file_stem().unwrap().to_string_lossy() == stem)
        {
            failures.push(format!(
                "{}: golden file of no robot in robots/",
                p.display()
            ));
        }
    }
    assert!(
        failures.is_empty(),
        "{}\n(after an intended change: RESTPOSE_BLESS=1 cargo test --release --test it golden, then review the diff)",
        failures.join("\n")
    );
}

/// The comparison itself: it passes rounding-level changes and catches real ones.
#[test]
fn comparison_catches_changes() {
    let want = serde_json::json!({
        "iterations": 5, "potential_energy": -18.686957108738806,
        "joints": {"pivot": {"type": "continuous", "position": [-1.38157708], "units": ["rad"]}},
        "stability": {"eigenvalues": [1.0, 5.0, 5.000001], "modes": [
            {"pivot": [1.0, -0.5]}, {"pivot": [0.3]}, {"pivot": [0.7]}]}
    });
    let diffs = |got: &Value| {
        let mut d = Vec::new();
        compare("", got, &want, &mut d);
        d
    };
    assert!(diffs(&want).is_empty());
    let mut g = want.clone();
    g["potential_energy"] = serde_json::json!(-18.686957108738806 * (1.0 + 1e-12));
    g["stability"]["modes"][0] = serde_json::json!({"pivot": [-1.0, 0.5]});
    g["stability"]["modes"][1] = serde_json::json!({"pivot": [-0.9]});
    assert!(diffs(&g).is_empty(), "{:?}", diffs(&g));
    for (path, value) in [
        ("/potential_energy", serde_json::json!(-18.68697)),
        ("/iterations", serde_json::json!(6)),
        ("/joints/pivot/position/0", serde_json::json!(-1.3815775)),
        ("/joints/pivot/type", serde_json::json!("revolute")),
        ("/stability/modes/0/pivot/1", serde_json::json!(-0.6)),
    ] {
        let mut g = want.clone();
        *g.pointer_mut(path).unwrap() = value;
        assert_eq!(diffs(&g).len(), 1, "{path}: {:?}", diffs(&g));
    }
    let mut g = want.clone();
    g["joints"]["pivot"]["units"] = serde_json::json!(["rad", "m"]);
    g.as_object_mut().unwrap().remove("iterations");
    g["extra"] = serde_json::json!(1);
    assert_eq!(diffs(&g).len(), 3, "{:?}", diffs(&g));
}
