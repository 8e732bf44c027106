//! The command line: exit codes, the JSON contract, atomic output.
use std::process::Command;

fn restpose() -> Command {
    Command::new(env!("CARGO_BIN_EXE_restpose"))
}

fn robot(name: &str) -> String {
    format!("{}/robots/{name}.urdf", env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn analyze_writes_the_documented_json() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("r.json");
    let st = restpose()
        .args(["analyze", &robot("slider_crank"), "--quiet", "--json"])
        .arg(&out)
        .status()
        .unwrap();
    assert_eq!(st.code(), Some(0));
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    for key in [
        "robot",
        "converged",
        "termination",
        "iterations",
        "potential_energy",
        "dof",
        "history",
        "joints",
        "links",
        "stability",
        "reactions",
        "redundant_constraints",
        "independent_coordinates",
    ] {
        assert!(v.get(key).is_some(), "missing `{key}`");
    }
    assert_eq!(v["converged"], true);
    assert_eq!(v["termination"], "converged");
    assert_eq!(v["dof"], 1);
    assert_eq!(v["joints"]["slide"]["type"], "prismatic");
    assert_eq!(
        v["joints"]["wrist_pin"]["position"]
            .as_array()
            .unwrap()
            .len(),
        1
    );
    assert_eq!(
        v["links"]["rod"]["orientation_wxyz"]
            .as_array()
            .unwrap()
            .len(),
        4
    );
    let h = v["history"].as_array().unwrap();
    assert_eq!(h[0]["iteration"], 0);
    assert!(h[0]["gradient_norm"].as_f64().unwrap() > 0.0);
    assert_eq!(v["stability"]["verdict"], "stable");
    assert!(v["reactions"]["wrist_pin"]["force_world"].is_array());
}

#[test]
fn not_converged_exits_3_and_still_writes_json() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("r.json");
    let o = restpose()
        .args([
            "analyze",
            &robot("pendulum"),
            "--max-iterations",
            "1",
            "--json",
        ])
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(3));
    assert!(String::from_utf8_lossy(&o.stderr).contains("did not converge"));
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    assert_eq!(v["converged"], false);
    assert_eq!(v["termination"], "max_iterations");
}

#[test]
fn bad_input_exits_1_with_position_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.urdf");
    std::fs::write(
        &bad,
        "<robot name=\"r\">\n<link name=\"a\"/>\n<link name=\"a\"/>\n</robot>",
    )
    .unwrap();
    let out = dir.path().join("r.json");
    let o = restpose()
        .arg("analyze")
        .arg(&bad)
        .arg("--json")
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("bad.urdf:3:1: duplicate link name `a`"),
        "{err}"
    );
    assert!(!out.exists());
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        1,
        "no temporary files left"
    );
}

#[test]
fn options_lock_initial_gravity() {
    let o = restpose()
        .args([
            "analyze",
            &robot("pendulum"),
            "--lock",
            "pivot=-0.5",
            "--gravity",
            "0",
            "0",
            "-9.81",
        ])
        .output()
        .unwrap();
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("[-0.500000000]"), "{text}");
    let o = restpose()
        .args(["analyze", &robot("pendulum"), "--initial", "pivot=oops"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    let o = restpose()
        .args(["analyze", &robot("pendulum"), "--method", "simplex"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
}

/// Byte-identical apart from the wall times in `diagnostics.timings` (cut out here).
#[test]
fn same_input_same_json_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let run = |name: &str| {
        let out = dir.path().join(name);
        let st = restpose()
            .args(["analyze", &robot("four_bar_spatial"), "--quiet", "--json"])
            .arg(&out)
            .status()
            .unwrap();
        assert!(st.success());
        let text = std::fs::read_to_string(out).unwrap();
        let v: serde_json::Value = serde_json::from_str(&text).unwrap();
        // The numbers are cut out of the text as written (serde_json's default parser does
        // not round-trip every float, so the text is not rebuilt from the parsed value).
        let timings = text
            .find("\"timings\"")
            .expect("diagnostics.timings is written");
        let (head, tail) = text.split_at(timings);
        let mut zeroed = tail.to_string();
        for phase in v["diagnostics"]["timings"].as_object().unwrap().keys() {
            let key = format!("\"{phase}\": ");
            let at = zeroed.find(&key).expect("each phase is written") + key.len();
            let end = at + zeroed[at..].find([',', '\n', '}']).unwrap();
            zeroed.replace_range(at..end, "0");
        }
        format!("{head}{zeroed}").into_bytes()
    };
    assert_eq!(run("a.json"), run("b.json"));
}

/// `restpose analyze … | head -1`: a reader that closes the pipe early is not a crash.
#[test]
fn closed_stdout_is_not_a_panic() {
    use std::io::{BufRead, BufReader};
    use std::process::Stdio;
    let mut child = restpose()
        .args(["analyze", &robot("chain20")])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut first = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut first)
        .unwrap();
    assert!(first.starts_with("robot"));
    let out = child.wait_with_output().unwrap();
    assert!(!String::from_utf8_lossy(&out.stderr).contains("panicked"));
    assert_eq!(out.status.code(), Some(0));
}

/// `--linear-algebra`: the generated 60-body chain (auto: sparse) and the same chain forced
/// onto the dense path give the same energy; the JSON says which path ran; a bad value is a
/// usage error (exit 2).
#[test]
fn linear_algebra_flag_selects_the_path() {
    let dir = tempfile::tempdir().unwrap();
    let urdf = dir.path().join("chain.urdf");
    let gen = restpose()
        .args(["generate", "chain", "--size", "60"])
        .output()
        .unwrap();
    assert_eq!(gen.status.code(), Some(0));
    std::fs::write(&urdf, &gen.stdout).unwrap();
    let mut energies = Vec::new();
    for (flag, expected) in [
        ("auto", "tree"),
        ("dense", "dense"),
        ("sparse", "sparse"),
        ("tree", "tree"),
    ] {
        let out = dir.path().join(format!("{flag}.json"));
        let st = restpose()
            .arg("analyze")
            .arg(&urdf)
            .args(["--quiet", "--linear-algebra", flag, "--json"])
            .arg(&out)
            .status()
            .unwrap();
        assert_eq!(st.code(), Some(0), "{flag}");
        let v: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
        assert_eq!(v["diagnostics"]["linear_algebra"], expected, "{flag}");
        assert_eq!(v["stability"]["verdict"], "stable", "{flag}");
        energies.push(v["potential_energy"].as_f64().unwrap());
    }
    for e in &energies[1..] {
        assert!(
            (e - energies[0]).abs() < 1e-9 * energies[0].abs(),
            "{energies:?}"
        );
    }
    let st = restpose()
        .arg("analyze")
        .arg(&urdf)
        .args(["--quiet", "--linear-algebra", "magic"])
        .status()
        .unwrap();
    assert_eq!(st.code(), Some(2));
}

/// The rest pose of the pendulum from `analyze --json -`.
fn pendulum_rest_angle() -> f64 {
    let o = restpose()
        .args(["analyze", &robot("pendulum"), "--json", "-"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    v["joints"]["pivot"]["position"][0].as_f64().unwrap()
}

/// `rostopic echo /joint_states` output (header, velocity and effort lists, every message
/// ended by `---`) is a pose for `verify`; with several messages, the last one counts.
#[test]
fn verify_reads_rostopic_echo_output() {
    let rest = pendulum_rest_angle();
    let message = |angle: f64, seq: usize| {
        format!(
            "header: \n  seq: {seq}\n  stamp: \n    secs: 1700000000\n    nsecs: 5000\n  frame_id: ''\nname: [pivot]\nposition: [{angle}]\nvelocity: [0.0]\neffort: []\n---\n"
        )
    };
    let dir = tempfile::tempdir().unwrap();
    let run = |text: String| {
        let path = dir.path().join("echo.yaml");
        std::fs::write(&path, text).unwrap();
        restpose()
            .args(["verify", &robot("pendulum"), "-q", "--pose"])
            .arg(&path)
            .status()
            .unwrap()
            .code()
    };
    assert_eq!(run(message(rest, 1)), Some(0));
    assert_eq!(run(message(rest + 0.2, 1) + &message(rest, 2)), Some(0));
    assert_eq!(run(message(rest, 1) + &message(rest + 0.2, 2)), Some(4));
    // ROS 2 (`ros2 topic echo`): block lists, `sec`/`nanosec`.
    let ros2 = format!(
        "header:\n  stamp:\n    sec: 0\n    nanosec: 0\n  frame_id: ''\nname:\n- pivot\nposition:\n- {rest}\nvelocity: []\neffort: []\n---\n"
    );
    assert_eq!(run(ros2), Some(0));
}

/// `--json -` writes the JSON, and only the JSON, to standard output for `analyze`, `check`
/// and `verify`; no file named `-` appears.
#[test]
fn json_dash_means_standard_output() {
    let dir = tempfile::tempdir().unwrap();
    let rest = pendulum_rest_angle();
    for args in [
        vec!["analyze".to_string(), robot("slider_crank")],
        vec!["check".to_string(), robot("slider_crank")],
        vec![
            "check".to_string(),
            robot("slider_crank"),
            "--format".into(),
            "json".into(),
        ],
        vec![
            "verify".to_string(),
            robot("pendulum"),
            "--joint".into(),
            format!("pivot={rest}"),
        ],
    ] {
        let o = restpose()
            .current_dir(dir.path())
            .args(&args)
            .args(["--json", "-"])
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(0), "{args:?}");
        let v: serde_json::Value = serde_json::from_slice(&o.stdout)
            .unwrap_or_else(|e| panic!("{args:?}: stdout is not one JSON document: {e}"));
        assert!(v.is_object(), "{args:?}");
        match args[0].as_str() {
            "analyze" => assert_eq!(v["converged"], true),
            "check" => assert_eq!(v["dof"], 1),
            _ => assert_eq!(v["passed"], true),
        }
        assert!(!dir.path().join("-").exists(), "{args:?}");
    }
}

/// The keys of a JSON object in the order they were written.
struct Keys(Vec<String>);

impl<'de> serde::Deserialize<'de> for Keys {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Visit;
        impl<'de> serde::de::Visitor<'de> for Visit {
            type Value = Keys;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("an object")
            }
            fn visit_map<A: serde::de::MapAccess<'de>>(self, mut m: A) -> Result<Keys, A::Error> {
                let mut k = Vec::new();
                while let Some((key, _)) = m.next_entry::<String, serde::de::IgnoredAny>()? {
                    k.push(key);
                }
                Ok(Keys(k))
            }
        }
        d.deserialize_map(Visit)
    }
}

#[derive(serde::Deserialize)]
struct Ordered {
    joints: Keys,
    reactions: Keys,
}

/// Joints are listed in URDF file order (not alphabetically) in the JSON and the summary, and
/// every coordinate has its unit.
#[test]
fn joints_in_file_order_with_units() {
    for name in ["chain20", "four_bar_spatial", "slider_crank"] {
        let text = std::fs::read_to_string(robot(name)).unwrap();
        // `<joint name="…"` in file order, then the extension's loop joint.
        let mut file_order: Vec<String> = text
            .split("<joint name=\"")
            .skip(1)
            .map(|s| s[..s.find('"').unwrap()].to_string())
            .collect();
        file_order.extend(
            text.split("loop_joint name=\"")
                .skip(1)
                .map(|s| s[..s.find('"').unwrap()].to_string()),
        );
        let o = restpose()
            .args(["analyze", &robot(name), "--json", "-"])
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(0));
        let ordered: Ordered = serde_json::from_slice(&o.stdout).unwrap();
        assert_eq!(ordered.joints.0, file_order, "{name}");
        let in_order: Vec<&String> = file_order
            .iter()
            .filter(|j| ordered.reactions.0.contains(j))
            .collect();
        assert_eq!(
            ordered.reactions.0.iter().collect::<Vec<_>>(),
            in_order,
            "{name}"
        );
        let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        for (j, r) in v["joints"].as_object().unwrap() {
            let units: Vec<&str> = r["units"]
                .as_array()
                .unwrap()
                .iter()
                .map(|u| u.as_str().unwrap())
                .collect();
            assert_eq!(units.len(), r["position"].as_array().unwrap().len(), "{j}");
            let expected: &[&str] = match r["type"].as_str().unwrap() {
                "revolute" | "continuous" => &["rad"],
                "prismatic" => &["m"],
                "universal" => &["rad", "rad"],
                "spherical" => &["1", "1", "1", "1"],
                other => panic!("{name}: joint type {other} not expected here"),
            };
            assert_eq!(units, expected, "{name}: {j}");
        }
        // The summary lists the joints in the same order, each with its unit.
        let o = restpose().args(["analyze", &robot(name)]).output().unwrap();
        let summary = String::from_utf8_lossy(&o.stdout);
        let lines: Vec<&str> = summary
            .lines()
            .skip_while(|l| !l.contains("joint                          type"))
            .skip(1)
            .take(file_order.len())
            .collect();
        for (line, j) in lines.iter().zip(&file_order) {
            assert_eq!(line.split_whitespace().next(), Some(j.as_str()), "{name}");
            assert!(
                line.ends_with(" rad") || line.ends_with(" m") || line.ends_with(" 1"),
                "{name}: {line}"
            );
        }
    }
}

/// Issue 12 §3: numeric options are checked when parsed; the message names the option and
/// the run stops with a usage error (exit 2) before reading the file.
#[test]
fn numeric_options_are_validated() {
    let pendulum = robot("pendulum");
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec!["analyze", &pendulum, "--tolerance", "0"],
            "--tolerance",
        ),
        (
            vec!["analyze", &pendulum, "--tolerance=-1e-8"],
            "--tolerance",
        ),
        (
            vec!["analyze", &pendulum, "--tolerance", "nan"],
            "--tolerance",
        ),
        (
            vec!["analyze", &pendulum, "--constraint-tolerance", "inf"],
            "--constraint-tolerance",
        ),
        (
            vec!["analyze", &pendulum, "--constraint-tolerance", "0"],
            "--constraint-tolerance",
        ),
        (
            vec!["analyze", &pendulum, "--gravity", "0", "nan", "-9.81"],
            "--gravity",
        ),
        (
            vec!["analyze", &pendulum, "--gravity", "0", "0", "-inf"],
            "--gravity",
        ),
        (
            vec!["analyze", &pendulum, "--load-steps", "1001"],
            "--load-steps",
        ),
        (
            vec!["analyze", &pendulum, "--inertia-from-geometry=-5"],
            "--inertia-from-geometry",
        ),
        (
            vec!["analyze", &pendulum, "--inertia-from-geometry", "0"],
            "--inertia-from-geometry",
        ),
        (
            vec![
                "verify",
                &pendulum,
                "--joint",
                "pivot=0",
                "--force-tolerance=-1",
            ],
            "--force-tolerance",
        ),
        (
            vec![
                "verify",
                &pendulum,
                "--joint",
                "pivot=0",
                "--constraint-tolerance",
                "nan",
            ],
            "--constraint-tolerance",
        ),
        (
            vec!["check", &pendulum, "--gravity", "inf", "0", "0"],
            "--gravity",
        ),
        (vec!["generate", "chain", "--size", "0"], "--size"),
    ];
    for (args, option) in cases {
        let o = restpose().args(&args).output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(option), "{args:?}: {err}");
        assert!(o.stdout.is_empty(), "{args:?}");
    }
    // The bound of --load-steps is in the message; values inside the ranges run.
    let o = restpose()
        .args(["analyze", &pendulum, "--load-steps", "5000"])
        .output()
        .unwrap();
    assert!(String::from_utf8_lossy(&o.stderr).contains("1000"));
    let o = restpose()
        .args([
            "analyze",
            &pendulum,
            "-q",
            "--load-steps",
            "1000",
            // `--max-iterations` bounds all 1000 load steps together.
            "--max-iterations",
            "100000",
            "--tolerance",
            "1e-9",
        ])
        .args([
            "--constraint-tolerance",
            "1e-11",
            "--gravity",
            "0",
            "0",
            "-9.81",
        ])
        .output()
        .unwrap();
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
}

/// Issue 12 §4: a joint name on the command line that the model does not have is an input
/// error (exit 1) naming the option and suggesting the closest joint name.
#[test]
fn unknown_joint_names_get_a_suggestion() {
    let arm = robot("ur5_class");
    for (args, hint) in [
        (
            vec!["analyze", &arm, "--lock", "elbow_jiont=0.3"],
            Some("elbow_joint"),
        ),
        (
            vec!["analyze", &arm, "--initial", "wrist_2=0.3"],
            Some("wrist_2_joint"),
        ),
        (
            vec!["analyze", &arm, "--lock", "Shoulder_Lift_Joint=0.1"],
            Some("shoulder_lift_joint"),
        ),
        (vec!["analyze", &arm, "--lock", "gripper=0"], None),
        (
            vec!["verify", &arm, "--joint", "wrist_3_jont=0.1"],
            Some("wrist_3_joint"),
        ),
    ] {
        let o = restpose().args(&args).output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
        let option = args[2];
        assert!(
            err.contains(&format!("{option} {}", args[3])),
            "{args:?}: {err}"
        );
        assert!(err.contains("the model has no joint"), "{args:?}: {err}");
        match hint {
            Some(h) => assert!(
                err.contains(&format!("did you mean `{h}`?")),
                "{args:?}: {err}"
            ),
            None => assert!(!err.contains("did you mean"), "{args:?}: {err}"),
        }
    }
}

/// Issue 14: the result JSON reports the wall time of each phase; each is a finite,
/// non-negative number of seconds and together they fit in the process's own wall time.
#[test]
fn analyze_reports_timings_of_each_phase() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("t.json");
    let started = std::time::Instant::now();
    let st = restpose()
        .args(["analyze", &robot("four_bar_spatial"), "--quiet", "--json"])
        .arg(&out)
        .status()
        .unwrap();
    let wall = started.elapsed().as_secs_f64();
    assert_eq!(st.code(), Some(0));
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    let t = &v["diagnostics"]["timings"];
    let mut sum = 0.0;
    for phase in [
        "import",
        "assembly",
        "iterations",
        "stability",
        "export",
        "self_check",
    ] {
        let s = t[phase].as_f64().unwrap_or(-1.0);
        assert!(s.is_finite() && s >= 0.0, "{phase}: {t}");
        sum += s;
    }
    assert!(t["iterations"].as_f64().unwrap() > 0.0, "{t}");
    // Issue 26: the self-check of a converged pose is timed too (it ran: the pose converged).
    assert!(t["self_check"].as_f64().unwrap() > 0.0, "{t}");
    assert!(
        sum > 0.0 && sum <= wall,
        "phases {sum} s, process {wall} s: {t}"
    );
    // Issue 26: the iterations proper and the first of them, parts of `iterations`.
    let (steps, first) = (
        t["steps"].as_f64().unwrap(),
        t["first_step"].as_f64().unwrap(),
    );
    assert!(v["iterations"].as_u64().unwrap() >= 2, "{v}");
    assert!(
        0.0 < first && first < steps && steps <= t["iterations"].as_f64().unwrap(),
        "{t}"
    );
}
