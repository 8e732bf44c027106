//! Issue 25: the fuzz target reached only `load_str` and `solve`, so a campaign on the binary
//! found what it could not (a panic in an obstacle, a panic and a hang in `verify`'s SVD). The
//! structure-aware mutator and the harness of `fuzz/src/lib.rs` (the cargo-fuzz targets'
//! code) take mutants of the committed corpus where users take files: import with the
//! command line's options, `check`, solve, `verify` on the start and on the solved pose, with
//! obstacles, contacts, stops, `mech:` and drake elements. This smoke run (stable toolchain,
//! default test suite, a few seconds; `PROPTEST_CASES` raises it) holds that no mutant panics
//! or reports a non-finite number. The long campaigns: `docs/fuzzing.md`.

#[expect(
    unreachable_pub,
    reason = "the fuzz crate's library, included as a module: its items are public there"
)]
#[path = "../../../fuzz/src/lib.rs"]
mod fuzz_lib;

use fuzz_lib::{apply, exercise, seeds, Choices, Dictionary, Mutation, Reached};
use proptest::prelude::*;

fn corpus() -> Vec<(String, String)> {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/seeds");
    seeds(&dir)
}

fn mutation() -> impl Strategy<Value = Mutation> {
    let u = any::<usize>;
    prop_oneof![
        3 => (u(), u(), u()).prop_map(|(a, b, c)| Mutation::Number(a, b, c)),
        1 => (u(), u()).prop_map(|(a, b)| Mutation::Value(a, b)),
        1 => (u(), u()).prop_map(|(a, b)| Mutation::Rename(a, b)),
        1 => (u(), u()).prop_map(|(a, b)| Mutation::Tag(a, b)),
        1 => (u(), u()).prop_map(|(a, b)| Mutation::Attribute(a, b)),
        1 => u().prop_map(Mutation::Duplicate),
        1 => u().prop_map(Mutation::Delete),
        2 => (u(), u(), u()).prop_map(|(a, b, c)| Mutation::Snippet(a, b, c)),
    ]
}

#[test]
fn the_corpus_is_seeded_and_the_dictionary_read() {
    let c = corpus();
    assert!(c.len() >= 20, "{} seeds", c.len());
    assert!(c.iter().any(|(n, _)| n == "tractor_trailer.urdf"));
    let d = Dictionary::load();
    assert!(d.tags.iter().any(|t| t == "mech:spring"));
    assert!(d.numbers.iter().any(|n| n == "1e308"));
    assert!(d
        .snippets
        .iter()
        .all(|s| s.starts_with('<') && s.ends_with('>')));
    // Every seed goes through the harness unmutated, and most reach verify.
    let verified = c
        .iter()
        .filter(|(_, t)| exercise(t, &Choices::default()) == Reached::Verified)
        .count();
    assert!(
        verified * 2 >= c.len(),
        "{verified} of {} seeds verified",
        c.len()
    );
}

/// The issue's own mutants, through the harness.
#[test]
fn the_issue_mutants_pass_the_harness() {
    let d = Dictionary::load();
    let c = corpus();
    let text = |name: &str| c.iter().find(|(n, _)| n == name).unwrap().1.clone();
    let cases = [
        text("four_bar_spatial.urdf").replace(
            r#"<end link="coupler" xyz="0.21 0 0"/>"#,
            r#"<end link="coupler" xyz="1e308 0 0"/>"#,
        ),
        text("slider_crank.urdf").replace(
            r#"<end link="slider" xyz="0 0 0"/>"#,
            r#"<end link="slider" xyz="-1e308 0 0"/>"#,
        ),
    ];
    for t in &cases {
        assert_eq!(exercise(t, &Choices::default()), Reached::Refused);
    }
    // Every snippet of the dictionary inserted into the pendulum.
    for k in 0..d.snippets.len() {
        let t = apply(&d, &text("pendulum.urdf"), &Mutation::Snippet(k, 1, 0));
        for b in [0u8, 3, 0x42, 0x91] {
            exercise(&t, &Choices::from_byte(b, 7));
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig {
        // 256 cases (a few seconds); `PROPTEST_CASES` sets another number.
        cases: std::env::var("PROPTEST_CASES")
            .ok()
            .and_then(|v| v.parse().ok())
            .unwrap_or(256),
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    /// Mutants of the corpus with random options: no panic, nothing non-finite.
    #[test]
    fn structure_aware_mutants_never_panic(
        seed in any::<usize>(),
        mutations in prop::collection::vec(mutation(), 1..4),
        options in any::<u8>(),
        extra in any::<u8>(),
    ) {
        let d = Dictionary::load();
        let c = corpus();
        let mut text = c[seed % c.len()].1.clone();
        for m in &mutations {
            text = apply(&d, &text, m);
        }
        exercise(&text, &Choices::from_byte(options, extra));
    }
}
