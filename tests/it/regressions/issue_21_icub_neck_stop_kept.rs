//! Regression (issue 21, icub-models 3.2.0's iCubGenova03 hanging, copied into
//! `robots/icub_genova03/`): the energy rose by 0.034 J between two active-set rounds
//! without an iteration. Its neck links are massless; in round 14 the line search's trial
//! point held the neck roll at its upper stop (the projected search), and the valley
//! correction (module `solver::valley`: stiff Newton steps back to a curved valley's floor)
//! then carried the neck roll 0.235 rad past that stop. The point was accepted with the stop
//! violated, round 15's first step met it at `α = 0`, and round 16 began by projecting the
//! pose back onto the stop, uphill, and took 4 iterations to come back down: 39 iterations in
//! 23 rounds. The correction's path is now bent at the stops as the line search's is; and rows
//! released before leave together at a stationary point where the step with all of them
//! released moves off every one (module `solver::inequality::release_trial`): 33 iterations,
//! 22 rounds, the same rest (Pinocchio agrees with it: `scripts/pinocchio_corpus.py`'s check).

use restpose::Termination;

fn icub() -> restpose::Model {
    crate::common::robot("icub_genova03/icub_genova03")
}

#[test]
fn the_energy_never_rises_between_rounds_and_the_neck_keeps_its_stop() {
    let model = icub();
    let (state, report) = crate::common::solve_direct(&model);
    assert_eq!(report.termination, Termination::Converged);
    // Each round starts where the last one ended, at no higher energy (was +0.034 J at the
    // start of round 16).
    for w in report.history.windows(2) {
        if w[1].round != w[0].round {
            let rise = w[1].potential_energy - w[0].potential_energy;
            assert!(
                rise <= 1e-9,
                "round {} starts {rise:e} J above where round {} ended",
                w[1].round,
                w[0].round
            );
        }
    }
    assert!(
        report.iterations <= 35,
        "{} iterations (was 39)",
        report.iterations
    );
    // The rest of main and of Pinocchio's check: the same energy, the neck roll within its
    // stops, every free joint balanced and each stop's effort the energy's slope.
    assert!(
        (report.energy.total - (-50.7187661372)).abs() < 1e-8,
        "V = {}",
        report.energy.total
    );
    let roll = state.joint(&model, "neck_roll").unwrap()[0];
    // Its upper stop is at 1.0472 rad (π/3 rounded up by 2·10⁻⁶).
    assert!(
        roll <= std::f64::consts::FRAC_PI_3 + 3e-6,
        "neck roll {roll} past its upper stop"
    );
    let h = 1e-4;
    for j in model
        .joints()
        .iter()
        .filter(|j| j.kind.name() == "revolute")
    {
        let name = j.name.as_str();
        let up = crate::common::energy_moved(&model, &state, name, h);
        let down = crate::common::energy_moved(&model, &state, name, -h);
        let slope = (up - down) / (2.0 * h);
        match report.active_limits.iter().find(|a| a.joint == name) {
            Some(stop) => assert!(
                (slope - stop.effort).abs() < 1e-5,
                "{name}: dV/dθ = {slope}, stop effort {}",
                stop.effort
            ),
            None => assert!(slope.abs() < 1e-5, "{name}: dV/dθ = {slope}"),
        }
    }
}
