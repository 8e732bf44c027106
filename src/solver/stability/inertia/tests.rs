//! The inertia verdict against the dense eigendecomposition of the formed reduced Hessian
//! (small and mid-size models: stable, unstable, neutral) and against Lanczos (large chains).

use super::*;
use crate::constraints::Constraints;
use crate::solver::stability::eigen::symmetric_eigen;
use crate::solver::system::Backend;
use crate::urdf::{load_str, ImportOptions};

/// A generated chain of `n` links; `flip`: gravity up and weak springs (unstable where bent).
fn chain(n: usize, flip: bool) -> crate::model::Model {
    let text = crate::generate::chain(n, false);
    let text = if flip {
        let mut t = String::new();
        let mut rest = text.replace("0 0 -9.81", "0 0 9.81");
        while let Some(i) = rest.find("stiffness=\"") {
            t.push_str(&rest[..i]);
            t.push_str("stiffness=\"0.01");
            let tail = &rest[i + 11..];
            rest = tail[tail.find('"').unwrap()..].to_string();
        }
        t + &rest
    } else {
        text
    };
    load_str(&text, "c.urdf", &ImportOptions::default())
        .unwrap()
        .model
}

/// A bent configuration of the chain, away from any symmetry.
fn bent(model: &crate::model::Model, n: usize, amplitude: f64) -> DVector<f64> {
    let mut values = crate::state::JointValues::new();
    for i in 0..n {
        values.insert(
            format!("joint{i}"),
            vec![amplitude * ((i as f64) * 0.7).sin()],
        );
    }
    crate::state::State::from_joint_values(model, &values).q
}

/// The verdict the eigenvalue path gives for the ascending eigenvalues `vals` and tolerance.
fn by_eigenvalues(vals: &DVector<f64>, tol: f64) -> Verdict {
    if vals[0] < -tol {
        Verdict::Unstable
    } else if vals[0] <= tol {
        Verdict::Neutral
    } else {
        Verdict::Stable
    }
}

/// On chains small enough to form `Ĥ`, the count below `σ` equals the dense
/// eigendecomposition's at shifts between and around the eigenvalues, and the verdict equals
/// the eigenvalue path's: stable (hanging chain), unstable (held upside down).
#[test]
fn counts_and_verdicts_match_the_dense_eigendecomposition() {
    for (n, flip, amplitude) in [(30, false, 0.3), (30, true, 0.3), (60, true, 1.0)] {
        let model = chain(n, flip);
        let q = bent(&model, n, amplitude);
        let mut sys = System::new(&model, Constraints::new(&model, &[]), Backend::Sparse);
        let part = sys.partition(&q);
        let eval = sys.evaluate(&q, &part).unwrap();
        let (exact, _) = symmetric_eigen(&sys.reduced_hessian(&q, &part, &eval));
        assert_eq!(exact.len(), n);
        let ByInertia {
            verdict,
            tolerance: tol,
            ..
        } = inertia_verdict(&mut sys, &q, &part, &eval).unwrap();
        // The tolerance from the Lanczos estimate: never above the exact one (Ritz values lie
        // in the spectrum), and within a few per cent of it.
        let exact_tol = 1e-10 * exact.amax().max(1.0);
        assert!(tol <= exact_tol * (1.0 + 1e-12), "{tol} above {exact_tol}");
        assert!(
            (tol - exact_tol).abs() <= 0.05 * exact_tol,
            "{tol} vs {exact_tol}"
        );
        assert_eq!(verdict, by_eigenvalues(&exact, tol), "n {n} flip {flip}");
        assert_eq!(verdict == Verdict::Unstable, flip);
        // Shifts in the gaps of the spectrum (midpoints) and beyond both ends.
        let mut shifts = vec![exact[0] - 1.0, exact[n - 1] * 1.5 + 1.0];
        for i in 1..n {
            shifts.push(0.5 * (exact[i - 1] + exact[i]));
        }
        for sigma in shifts {
            let expected = exact.iter().filter(|&&e| e < sigma).count();
            // A shift closer to an eigenvalue than rounding resolves is not a fair test.
            let gap = exact
                .iter()
                .map(|e| (e - sigma).abs())
                .fold(f64::INFINITY, f64::min);
            if gap <= 1e-8 * exact.amax() {
                continue;
            }
            assert_eq!(
                eigenvalues_below(&mut sys, &part, sigma),
                Some(expected),
                "n {n} flip {flip} sigma {sigma}"
            );
        }
    }
}

/// A neutral pose: a chain without gravity or springs has a zero reduced Hessian; the
/// verdict is neutral (no eigenvalue below `−t`, all below `t`).
#[test]
fn neutral_without_gravity_or_springs() {
    let n = 30;
    let text = crate::generate::chain(n, false).replace("0 0 -9.81", "0 0 0");
    let mut t = String::new();
    let mut rest = text;
    while let Some(i) = rest.find("stiffness=\"") {
        t.push_str(&rest[..i]);
        t.push_str("stiffness=\"0");
        let tail = &rest[i + 11..];
        rest = tail[tail.find('"').unwrap()..].to_string();
    }
    let model = load_str(&(t + &rest), "c.urdf", &ImportOptions::default())
        .unwrap()
        .model;
    let q = bent(&model, n, 0.3);
    let mut sys = System::new(&model, Constraints::new(&model, &[]), Backend::Sparse);
    let part = sys.partition(&q);
    let eval = sys.evaluate(&q, &part).unwrap();
    let (exact, _) = symmetric_eigen(&sys.reduced_hessian(&q, &part, &eval));
    let ByInertia {
        verdict,
        tolerance: tol,
        ..
    } = inertia_verdict(&mut sys, &q, &part, &eval).unwrap();
    assert!(exact.amax() <= tol, "{exact}");
    assert_eq!(verdict, Verdict::Neutral);
    assert_eq!(by_eigenvalues(&exact, tol), Verdict::Neutral);
}

/// Above `EXACT_UP_TO`, the verdict equals the Lanczos path's, and on the unstable chain the
/// count of negative eigenvalues equals the Lanczos path's inertia count at zero shift.
#[test]
fn verdicts_match_lanczos_on_large_chains() {
    let n = crate::solver::spectrum::EXACT_UP_TO + 100;
    for flip in [false, true] {
        let model = chain(n, flip);
        let q = bent(&model, n, 0.3);
        let mut sys = System::new(&model, Constraints::new(&model, &[]), Backend::Sparse);
        let part = sys.partition(&q);
        let eval = sys.evaluate(&q, &part).unwrap();
        let ByInertia {
            verdict,
            tolerance: tol,
            largest,
        } = inertia_verdict(&mut sys, &q, &part, &eval).unwrap();
        let negative = eigenvalues_below(&mut sys, &part, 0.0);
        let spectrum = crate::solver::spectrum::spectrum(&mut sys, &q, &part, &eval);
        assert!(!spectrum.exact);
        assert_eq!(
            verdict,
            by_eigenvalues(&spectrum.values, spectrum.tolerance())
        );
        assert_eq!(tol, spectrum.tolerance(), "the same estimate of λ_max");
        // The spectrum given the verdict's `λ_max` (not iterated again) is the same, bit for
        // bit: what the minimizer and `--eigenvalues` take after an inertia verdict.
        let knowing =
            crate::solver::spectrum::spectrum_knowing(&mut sys, &q, &part, &eval, Some(largest));
        assert_eq!(knowing.largest, spectrum.largest);
        assert_eq!(knowing.values, spectrum.values);
        assert_eq!(knowing.vectors, spectrum.vectors);
        assert_eq!(knowing.negative_by_inertia, spectrum.negative_by_inertia);
        assert_eq!(verdict == Verdict::Unstable, flip);
        assert_eq!(negative, spectrum.negative_by_inertia);
        assert_eq!(negative.unwrap() > 0, flip);
        if !flip {
            // The hanging chain: Lanczos's six smallest eigenvalues are the six smallest, so
            // the count between the k-th and (k+1)-th is k.
            let v = &spectrum.values;
            assert_eq!(v.len(), 6);
            for k in 1..v.len() {
                let sigma = 0.5 * (v[k - 1] + v[k]);
                assert_eq!(eigenvalues_below(&mut sys, &part, sigma), Some(k), "{v}");
            }
            assert_eq!(eigenvalues_below(&mut sys, &part, 0.5 * v[0]), Some(0));
        }
    }
}

/// `stability_of` takes the evaluation and frees its factors once `λ_max` is known
/// ([`largest_at`], then [`inertia_verdict_knowing`]): the verdict and tolerance are those of
/// [`inertia_verdict`] with the evaluation kept, bit for bit (both backends, stable and
/// unstable chains), and an evaluation made again after that release (the spectrum after an
/// untrusted inertia) equals the first.
#[test]
fn verdict_that_frees_the_factors_is_the_same() {
    let n = crate::solver::spectrum::EXACT_UP_TO + 100;
    for flip in [false, true] {
        let model = chain(n, flip);
        let q = bent(&model, n, 0.3);
        for backend in [Backend::Sparse, Backend::Tree] {
            let cons = || Constraints::new(&model, &[]);
            let mut kept = System::new(&model, cons(), backend);
            let part = kept.partition(&q);
            let eval = kept.evaluate(&q, &part).unwrap();
            let whole = inertia_verdict(&mut kept, &q, &part, &eval).unwrap();
            let mut sys = System::new(&model, cons(), backend);
            let part = sys.partition(&q);
            let first = sys.evaluate(&q, &part).unwrap();
            let judged = crate::solver::stability_of(&mut sys, &q, &part, first, false).unwrap();
            assert_eq!(judged.verdict, whole.verdict);
            assert_eq!(judged.tolerance, whole.tolerance);
            assert_eq!(judged.verdict == Verdict::Unstable, flip);
            let again = sys.evaluate(&q, &part).unwrap();
            assert_eq!(again.mu, eval.mu);
            assert_eq!(again.grad_v, eval.grad_v);
            assert_eq!(again.energy.total, eval.energy.total);
            let x = DVector::from_fn(part.independent.len(), |i, _| (i as f64 * 0.37).sin());
            assert_eq!(
                sys.tangent_step(&part, &again, &x),
                kept.tangent_step(&part, &eval, &x)
            );
        }
    }
}
