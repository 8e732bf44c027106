//! Regression (issue 26, "rope 1,000 on the ground"): the 1,000-link rope's first active-set
//! round took 29 iterations and met no contact. Its Newton steps were accepted at 1/16 to 1/2 of
//! their length because the corrector failed at the longer trial points (18 failures in the
//! solve): the contact at the foot of the hanging part was pivoted on one 5 cm link, which
//! cannot lift the foot by what 333 links swinging along the step lower it. The second-order
//! correction of each trial point (module `step::second_order`) closes that row in all
//! coordinates first: 10 iterations in all (main 227a85a: 38), the first round in 3, one
//! failed correction, the same rest.

use crate::common::energies;
use restpose::Options;

#[test]
fn a_1000_link_rope_takes_its_newton_steps_at_full_length() {
    let n = 1000;
    let model = crate::common::model_from(&restpose::generate::rope(n));
    let (state, report) = restpose::solve(&model, &Options::default()).unwrap();
    assert!(report.converged(), "{:?}", report.termination);
    let first = report.history.iter().filter(|h| h.round == 1).count() - 1;
    assert!(
        report.iterations <= 12 && first <= 5,
        "{} iterations, {first} in the first round (227a85a: 38, 29)",
        report.iterations
    );
    assert!(
        report.diagnostics.corrector_failures <= 2,
        "{} failed corrections (227a85a: 18)",
        report.diagnostics.corrector_failures
    );
    // The same rest (independent check: the energy in joint coordinates; every contact
    // touching and pushing; 677 of them, as before).
    let th: Vec<f64> = (0..n)
        .map(|i| state.joint(&model, &format!("joint{i}")).unwrap()[0])
        .collect();
    assert!((report.energy.total - energies::rope(n, &th)).abs() < 1e-9);
    assert!((report.energy.total - 1255.708439029).abs() < 1e-9);
    assert_eq!(report.contacts.len(), 677);
    for c in &report.contacts {
        assert!(c.gap.abs() <= 1e-9 && c.normal_force >= 0.0, "{c:?}");
    }
}
