//! Regression (issue 21, the standing corpus): the A1 of example-robot-data 6.0.0 (copied into
//! `robots/a1/`) on the floor from its SRDF `standing` state, sticking feet, no servos: nothing
//! holds its joints and it collapses. Its fall reached a degenerate vertex of the active set: a
//! thigh contact pulling −224 N at a stationary point left the set, alone (it had left once
//! before), and the next round's first step turned it back into the floor after 10⁻⁸ J, round
//! after round, until the cycling guard: `active_set_cycling` after 103 iterations, 202 rounds
//! (main at 8a8013e). A row that comes straight back three times without progress now ends the
//! search there (module `inequality::release`), with the same message, in 9 iterations.
//! Frictionless, the same fall has a rest (16 iterations, unchanged).

fn analyze(friction: &str) -> (Option<i32>, String, serde_json::Value) {
    let args = "a1.urdf --load-steps 1 --floating-base --ground --srdf a1.srdf --srdf-state standing --friction";
    let mut args: Vec<String> = args.split(' ').map(String::from).collect();
    args.push(friction.into());
    crate::common::analyze_in("a1", &args)
}

#[test]
fn a_sticking_fall_without_servos_ends_at_its_cycle_at_once_with_the_remedy() {
    let (code, err, v) = analyze("stick");
    assert_eq!(code, Some(3), "{err}");
    assert_eq!(v["termination"], "active_set_cycling", "{err}");
    let iterations = v["iterations"].as_u64().unwrap();
    assert!(iterations <= 15, "{iterations} iterations (103 on main)");
    assert!(
        err.contains("12 joints are held by no servo, spring or lock")
            && err.contains("--servo all=K"),
        "{err}"
    );
}

#[test]
fn the_frictionless_fall_still_finds_its_rest() {
    let (code, err, v) = analyze("none");
    assert_eq!(code, Some(0), "{err}");
    assert_eq!(v["termination"], "converged");
    let iterations = v["iterations"].as_u64().unwrap();
    assert!(iterations <= 20, "{iterations} iterations");
    // It lies on its trunk: the base carries part of the weight, and the normal forces hold
    // the whole weight (no servos, no other support).
    let contacts = v["contacts"].as_array().unwrap();
    let total: f64 = contacts
        .iter()
        .map(|c| c["normal_force"].as_f64().unwrap())
        .sum();
    // The weight from the file's masses (13.741 kg) and the default gravity.
    let text =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/robots/a1/a1.urdf")).unwrap();
    let mass: f64 = text
        .split("<mass value=\"")
        .skip(1)
        .map(|t| t.split('"').next().unwrap().parse::<f64>().unwrap())
        .sum();
    let weight = mass * 9.81;
    assert!(
        contacts.iter().any(|c| c["link"] == "trunk"),
        "{contacts:?}"
    );
    assert!(
        (total - weight).abs() <= 1e-6 * weight,
        "{total} N for {weight} N"
    );
}
