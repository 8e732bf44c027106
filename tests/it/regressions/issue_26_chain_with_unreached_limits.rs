//! Regression (issue 26, "a chain with unreached limits"): the 1,000-link benchmark chain with
//! ±π limits that it never reaches. With the projected stop search the step was limited per
//! joint only, and the chain's joint rotations, small each, added up to steps its linear
//! model did not describe: `max_iterations` after 200 iterations (28938e5 with the cut: 7).
//! Limits that are never reached must change nothing: the same iterations and rest as the
//! chain without limits, under both stop searches.

use restpose::solver::StopSearch;
use restpose::{Options, Termination};

#[test]
fn unreached_limits_change_nothing_on_a_long_chain() {
    let free = restpose::generate::chain(1000, false);
    let limited = free
        .replace(r#"type="continuous""#, r#"type="revolute""#)
        .replace(
            "</joint>",
            r#"<limit lower="-3.14159" upper="3.14159" effort="1" velocity="1"/></joint>"#,
        );
    assert_eq!(limited.matches("<limit").count(), 1000);
    let solve = |text: &str, search| {
        let model = crate::common::model_from(text);
        let options = Options {
            load_steps: 1,
            stop_search: search,
            ..Default::default()
        };
        let (_, report) = restpose::solve(&model, &options).unwrap();
        assert_eq!(report.termination, Termination::Converged, "{search:?}");
        (report.iterations, report.energy.total)
    };
    let (n0, v0) = solve(&free, StopSearch::Projected);
    for search in [StopSearch::Projected, StopSearch::Cut] {
        let (n, v) = solve(&limited, search);
        assert_eq!(n, n0, "{search:?}: {n} iterations, without limits {n0}");
        assert!(
            (v - v0).abs() <= 1e-9 * v0.abs(),
            "{search:?}: V = {v}, without limits {v0}"
        );
    }
}
