//! `Release::needs_verdict`: a converged round whose every active row is a stop, more than
//! `MAX_WEAK` of them touching without a force, forms no verdict of its own, and the verdict
//! the active set reports there is the same with the round's verdict or without it.

use super::*;
use crate::solver::inequality::active_set::{activate, force_scale, inequalities, split};
use crate::solver::options::Options;
use crate::solver::system::Backend;
use crate::urdf::{load_str, ImportOptions};

/// A palm hanging from the world on a hinge, with `fingers` fingers hanging straight down
/// from it on hinges whose lower stop is their starting angle: at rest from the start, every
/// finger on its stop without a force.
fn hand(fingers: usize) -> crate::model::Model {
    let inertial = |z: f64| {
        format!(
            r#"<inertial><origin xyz="0 0 {z}"/><mass value="0.1"/><inertia ixx="1e-4" ixy="0" ixz="0" iyy="1e-4" iyz="0" izz="1e-5"/></inertial>"#
        )
    };
    let mut text = format!(
        r#"<robot name="hand"><link name="world"/><link name="palm">{}</link>
<joint name="wrist" type="revolute"><parent link="world"/><child link="palm"/><axis xyz="0 1 0"/><limit lower="-2" upper="2" effort="1" velocity="1"/></joint>"#,
        inertial(-0.1)
    );
    for k in 0..fingers {
        let x = 0.01 * (k as f64 - 0.5 * (fingers - 1) as f64);
        text += &format!(
            r#"<link name="f{k}">{}</link><joint name="j{k}" type="revolute"><parent link="palm"/><child link="f{k}"/><origin xyz="{x} 0 -0.2"/><axis xyz="1 0 0"/><limit lower="0" upper="1" effort="1" velocity="1"/></joint>"#,
            inertial(-0.05)
        );
    }
    text += "</robot>";
    load_str(&text, "hand.urdf", &ImportOptions::default())
        .unwrap()
        .model
}

/// The round from the start with the stops touching there active, with the release test
/// (`Some`) or without.
fn round(
    model: &crate::model::Model,
    options: &Options,
    with_release: bool,
) -> (crate::solver::Round, Vec<Active>) {
    let start = crate::solver::initial_state(model);
    let q = &start.q;
    let active: Vec<Active> = inequalities(model, options)
        .into_iter()
        .filter(|u| {
            crate::constraints::unilateral::gap(model, u, q, &start.branches)
                .is_some_and(|g| g.abs() <= options.gap_tolerance)
        })
        .map(|u| activate(model, options, u, q))
        .collect();
    let threshold = options.force_tolerance * force_scale(model);
    let release = Release::new(model, &active, &[], threshold).cycling(false);
    let round = crate::solver::solve_round(
        model,
        start,
        &[],
        &active,
        None,
        with_release.then_some(&release),
        options,
    )
    .unwrap();
    (round, active)
}

#[test]
fn a_round_on_many_weak_stops_forms_no_verdict_the_cone_would_not_use() {
    let options = Options::default();
    for fingers in [8, 12] {
        let model = hand(fingers);
        let (skipping, active) = round(&model, &options, true);
        let (judging, _) = round(&model, &options, false);
        assert_eq!(active.len(), fingers);
        assert!(skipping.report.converged() && judging.report.converged());
        // The same round otherwise: its rest, multipliers and spectrum's label.
        assert_eq!(skipping.state.q, judging.state.q);
        assert_eq!(skipping.multipliers, judging.multipliers);
        assert_eq!(
            skipping.report.diagnostics.eigenvalues_by,
            judging.report.diagnostics.eigenvalues_by
        );
        let (strong, weak) = split(
            &model,
            &skipping.multipliers,
            options.force_tolerance * force_scale(&model),
        );
        assert_eq!((strong.len(), weak.len()), (0, fingers));
        let all_held = judging.report.stability.clone();
        assert!(all_held.is_some());
        let many = fingers > crate::solver::stability::cone::MAX_WEAK;
        assert_eq!(skipping.report.stability.is_none(), many, "{fingers}");
        // What the active set reports at this rest, from the round's verdict (or none).
        let at_end = |held| {
            crate::solver::stability_verdict_after_round(
                &model,
                &skipping.state,
                (&strong, &weak),
                Backend::of(&model, &options),
                options.eigenvalues,
                held,
            )
        };
        let reported = at_end(skipping.report.stability.clone());
        assert_eq!(reported, at_end(all_held.clone()), "{fingers}");
        assert!(reported.is_some());
        if !many {
            // Few faces: the round's verdict is the one reported (its eigenvalues).
            assert_eq!(
                reported.map(|s| s.eigenvalues),
                all_held.map(|s| s.eigenvalues)
            );
        }
    }
}
