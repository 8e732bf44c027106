//! Regression (issue 21, item 3: neutral directions must not stall the solve): a leg hanging
//! from a hip yaw tilted 10⁻⁷ rad from vertical (the random-leg fuzz, seed 1, case 223), whose
//! yaw curvature is 2·10⁻¹³ N m/rad. The gradient fell to 6·10⁻⁹ (below the tolerance) with
//! the reduced Hessian's smallest eigenvalue at −1.2·10⁻⁸, within the Hessian's error at that
//! gradient (`Spectrum::unresolved`): the Newton step asked for first moved 0.05 along the
//! yaw (its magnitude step, noise over noise), which brought the gradient back to 6·10⁻⁹, and
//! then no step could lower the energy beyond rounding: `max_iterations` after 200
//! iterations on main b359fe8 (case 226 of the same fuzz with `--stop-search cut` likewise).
//! The step asked for is now the settling step (module `step::newton`): Newton along the
//! resolved curvatures only, after which the gradient is 2.6·10⁻¹³ and the yaw neutral.

use super::issue_21_yaw_near_vertical::{leg, pitch_and_ankle_balanced};
use restpose::solver::Verdict;
use restpose::{Options, StopSearch, Termination};

/// The yaw's curvature in closed form, to order `τ²`: with the knee on its stop and pitch
/// and ankle balanced, `V(ψ) = V₀ + τ² (P (1 − cos ψ) + K sin²ψ / 2)`: `P (1 − cos ψ)` the
/// pitch pivot (0.1 m below the yaw, 3.5 kg below it) and the hip's centre of mass rising
/// around the tilted axis, `K = g (|S| + m_foot ℓ_foot)` the depth of the hanging chain under
/// its pivot times its weight, which the out-of-plane part `τ sin ψ` of gravity reduces by
/// `K τ² sin²ψ / 2`. So `d²V/dψ² = τ² (P cos ψ + K cos 2ψ)`.
fn yaw_curvature(tilt: f64, off: f64, knee: f64, yaw: f64) -> f64 {
    let g = 9.81;
    let (c, s) = (knee.cos(), knee.sin());
    // Rotation about y of a point (x, z) of the shank's frame into the thigh's.
    let turn = |x: f64, z: f64| (x * c + z * s, -x * s + z * c);
    let (shank, ankle) = (turn(0.0, -0.2), turn(0.0, -0.4));
    // First moment about the pitch axis of thigh, shank and the foot's mass at the ankle.
    let moment = (
        2.0 * off + shank.0 + 0.5 * ankle.0,
        2.0 * -0.2 + (-0.4 + shank.1) + 0.5 * (-0.4 + ankle.1),
    );
    let k = g * (moment.0.hypot(moment.1) + 0.5 * 0.08f64.hypot(0.03));
    let p = g * (0.5 * 0.05 + 3.5 * 0.1);
    tilt * tilt * (p * yaw.cos() + k * (2.0 * yaw).cos())
}

#[test]
fn a_yaw_curvature_below_the_hessian_error_does_not_stall_the_solve() {
    let cases = [
        (
            1.3170845250290088e-7,
            -0.6828003147983326,
            0.46882641596895036,
            0.049217331560912486,
            [
                ("hip_yaw", -0.1929042667210752),
                ("hip_pitch", 0.6920577176750244),
                ("ankle", -0.39924246762064897),
                ("knee", 1.259409480492278),
            ],
            StopSearch::Projected,
        ),
        (
            9.47167895774543e-8,
            -0.8443250312063411,
            1.1882946559189616,
            0.012046102168627823,
            [
                ("hip_yaw", 0.4192611439563194),
                ("hip_pitch", -0.28552044898528095),
                ("ankle", -0.20244848968973472),
                ("knee", 2.0567704581128097),
            ],
            StopSearch::Cut,
        ),
    ];
    for (tilt, lower, knee, off, start, stop_search) in cases {
        let model = leg(tilt, lower, knee, off, start);
        let options = Options {
            load_steps: 1,
            stop_search,
            ..Default::default()
        };
        let (state, report) = restpose::solve(&model, &options).unwrap();
        assert_eq!(report.termination, Termination::Converged, "tilt {tilt}");
        assert!(
            report.iterations <= 30,
            "tilt {tilt}: {} iterations (main: 200)",
            report.iterations
        );
        let d = &report.diagnostics;
        assert!(d.gradient_norm <= d.gradient_tolerance && d.constraint_residual < 1e-10);

        // The knee on its lower stop, pitch and ankle balanced and at a minimum.
        let values: restpose::state::JointValues = state.joint_values(&model).into_iter().collect();
        let energy =
            |joint: &str, delta: f64| crate::common::energy_moved(&model, &state, joint, delta);
        let v0 = energy("hip_yaw", 0.0);
        assert!((report.energy.total - v0).abs() < 1e-12);
        assert!((values["knee"][0] - knee).abs() < 1e-9, "tilt {tilt}");
        assert!(energy("knee", 1e-4) > v0 + 1e-6, "tilt {tilt}");
        pitch_and_ankle_balanced(&energy, v0, tilt);

        // The yaw: neutral (its curvature, 10⁻¹³ N m/rad, is far below the verdict's
        // tolerance), its mode the yaw alone, its eigenvalue the closed form's to rounding
        // (`ε λ_max` ≈ 3·10⁻¹⁵ N m/rad); nothing to gain along it beyond rounding.
        let stability = report.stability.as_ref().expect("a stability verdict");
        assert_eq!(stability.verdict, Verdict::Neutral, "tilt {tilt}");
        let yaw = values["hip_yaw"][0];
        let expected = yaw_curvature(tilt, off, knee, yaw);
        let lowest = stability.eigenvalues[0];
        assert!(
            (lowest - expected).abs() < 0.25 * expected,
            "tilt {tilt}: yaw curvature {lowest:e}, closed form {expected:e}"
        );
        let mode = stability.modes[0].iter().find(|(j, _)| *j == "hip_yaw");
        assert!(mode.is_some_and(|(_, v)| v[0].abs() > 0.99), "tilt {tilt}");
        for delta in [-0.3, 0.3] {
            assert!(
                energy("hip_yaw", delta) > v0 - 1e-12,
                "tilt {tilt}, yaw {delta:+}"
            );
        }
    }
}
