//! Regression (issue 21, the standing corpus): the A1 of example-robot-data 6.0.0 (copied into
//! `robots/a1/`) on the floor from its SRDF `standing` state, sticking feet, no servos: nothing
//! holds its joints and it collapses. Its fall reached a degenerate vertex of the active set: a
//! thigh contact pulling −224 N at a stationary point left the set, alone (it had left once
//! before), and the next round's first step turned it back into the floor after 10⁻⁸ J, round
//! after round, until the cycling guard: `active_set_cycling` after 103 iterations, 202 rounds
//! (main at 8a8013e). A row that comes straight back three times without progress then ended
//! the search there (module `inequality::release`), with the same message, in 9 iterations
//! (main at 09cc023). Now such a sticking contact slides (rejoins frictionless) instead, and no
//! sphere is re-anchored after a slide: the fall rests in 27 iterations, accepted by `verify`
//! (the slide without that stop ended 1.3·10⁻⁴ m through the floor, `rejected_by_verify`).
//! Frictionless, the same fall has a rest (16 iterations, unchanged).

fn analyze(friction: &str) -> (Option<i32>, String, serde_json::Value) {
    let args = "a1.urdf --load-steps 1 --floating-base --ground --srdf a1.srdf --srdf-state standing --friction";
    let mut args: Vec<String> = args.split(' ').map(String::from).collect();
    args.push(friction.into());
    crate::common::analyze_in("a1", &args)
}

#[test]
fn a_sticking_fall_without_servos_slides_its_returning_thighs_to_a_verified_rest() {
    let (code, err, v) = analyze("stick");
    // Exit 0: converged, and `analyze`'s own `verify` check accepted the pose.
    assert_eq!(code, Some(0), "{err}");
    assert_eq!(v["termination"], "converged", "{err}");
    let iterations = v["iterations"].as_u64().unwrap();
    assert!(
        iterations <= 30,
        "{iterations} iterations (9 to the cycle on main)"
    );
    assert_eq!(v["stability"]["verdict"], "stable", "{err}");
    let contacts = v["contacts"].as_array().unwrap();
    for c in contacts {
        assert!(c["gap"].as_f64().unwrap() >= -1e-9, "{c}");
        assert!(c["normal_force"].as_f64().unwrap() >= -1e-6, "{c}");
    }
    // Some thigh that came back three times rests frictionless (no tangential force).
    assert!(
        contacts
            .iter()
            .any(|c| c["link"].as_str().unwrap().ends_with("_thigh") && c["state"] == "touching"),
        "{contacts:?}"
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
