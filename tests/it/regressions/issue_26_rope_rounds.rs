//! Regression (issues 21/26, the early release): a rope hanging from the world onto the ground
//! took many more active-set rounds with the early release of rows pulling hard
//! (`inequality::release`) than without it: its lift-off contacts pull for a few iterations
//! while the hanging part settles, by 30–300 times `‖∂V/∂v‖∞` when the force is scaled by the
//! characteristic length (`L` = 15 m at 300 links), so they were released one per round and came
//! back one per round (300 links: 22 iterations in 11 rounds; 1,000 links: 45 in 37, against 35
//! in 11 without the rule). For contacts on a chain held by the world the rate is now taken per
//! unit of the motion the relaxed row causes: 13 iterations in one round at 300 links.

use crate::common::energies;
use restpose::Options;

#[test]
fn a_300_link_rope_settles_without_releasing_its_lift_off_contacts_early() {
    let n = 300;
    let model = restpose::urdf::load_str(
        &restpose::generate::rope(n),
        "rope300.urdf",
        &Default::default(),
    )
    .unwrap()
    .model;
    let options = Options {
        load_steps: 1,
        ..Default::default()
    };
    let (state, report) = restpose::solve(&model, &options).unwrap();
    assert!(report.converged(), "{:?}", report.termination);
    let rounds = report.history.iter().map(|h| h.round).max().unwrap_or(1);
    assert!(
        rounds <= 3 && report.iterations <= 16,
        "{} iterations in {rounds} rounds",
        report.iterations
    );
    // The same rest as before (independent check: the energy in joint coordinates, every
    // contact touching and pushing).
    let th: Vec<f64> = (0..n)
        .map(|i| state.joint(&model, &format!("joint{i}")).unwrap()[0])
        .collect();
    assert!((report.energy.total - energies::rope(n, &th)).abs() < 1e-9);
    assert_eq!(report.contacts.len(), 201);
    for c in &report.contacts {
        assert!(c.gap.abs() <= 1e-9 && c.normal_force >= 0.0, "{c:?}");
    }
}
