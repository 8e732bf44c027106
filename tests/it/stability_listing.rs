//! When the stability verdict lists its eigenvalues: always on the dense path and up to 64
//! degrees of freedom on the tree and sparse paths (where the Newton steps decompose the
//! reduced Hessian anyway); above, the verdict comes from the inertia of the shifted KKT matrix
//! unless eigenvalues are asked for, and asking changes nothing but the listing.

use crate::common::model_from;
use restpose::solver::Verdict;
use restpose::{LinearAlgebra, Options};

/// A 64-link chain on the tree path lists six exact eigenvalues (all above the tolerance);
/// a 100-link chain does not by default (`inertia`), and with `eigenvalues` asked for lists the
/// exact ones: same iterates, pose and verdict, and a tolerance from the power-iteration
/// estimate of the largest eigenvalue within a few per cent of the exact one.
#[test]
fn eigenvalues_listed_up_to_64_dof_and_on_request_above() {
    let m = model_from(&restpose::generate::chain(64, false));
    let (_, r) = restpose::solve(&m, &Options::default()).unwrap();
    assert_eq!(r.dof, 64);
    assert_eq!(r.diagnostics.linear_algebra, "tree");
    assert_eq!(r.diagnostics.eigenvalues_by, "exact");
    let st = r.stability.as_ref().unwrap();
    assert_eq!(st.verdict, Verdict::Stable);
    assert_eq!(st.eigenvalues.len(), 6);
    assert_eq!(st.modes.len(), 6);

    let n = 100;
    let m = model_from(&restpose::generate::chain(n, false));
    for algebra in [LinearAlgebra::Auto, LinearAlgebra::Sparse] {
        let plain = Options {
            linear_algebra: algebra,
            ..Default::default()
        };
        let (s, r) = restpose::solve(&m, &plain).unwrap();
        assert!(r.converged(), "{algebra:?}");
        assert_eq!(r.dof, n);
        assert_eq!(r.diagnostics.eigenvalues_by, "inertia", "{algebra:?}");
        let st = r.stability.as_ref().unwrap();
        assert!(st.eigenvalues.is_empty() && st.modes.is_empty());
        let asked = Options {
            eigenvalues: true,
            ..plain
        };
        let (se, re) = restpose::solve(&m, &asked).unwrap();
        assert_eq!(re.diagnostics.eigenvalues_by, "exact", "{algebra:?}");
        assert_eq!(se.q, s.q, "{algebra:?}");
        assert_eq!(re.history, r.history, "{algebra:?}");
        let ste = re.stability.as_ref().unwrap();
        assert_eq!(ste.eigenvalues.len(), 6);
        assert_eq!(ste.verdict, Verdict::Stable);
        assert_eq!(st.verdict, ste.verdict, "{algebra:?}");
        assert!(ste.eigenvalues[0] > ste.tolerance);
        // Both tolerances are 1e-10 max(λ_max, 1) of the scaled reduced Hessian: exact with
        // the spectrum, from 12 power iterations with the inertia.
        assert!(
            (st.tolerance - ste.tolerance).abs() <= 0.05 * ste.tolerance,
            "{algebra:?}: {} vs {}",
            st.tolerance,
            ste.tolerance
        );
    }
}

/// `verify` at the 100-link chain's rest follows the same rule: the inertia verdict by
/// default, without eigenvalues, and analyze's eigenvalues when asked for.
#[test]
fn verify_lists_eigenvalues_on_request_above_64_dof() {
    let m = model_from(&restpose::generate::chain(100, false));
    let (s, r) = restpose::solve(&m, &Options::default()).unwrap();
    let check = |eigenvalues| {
        restpose::verify::verify_reporting(
            &m,
            &s,
            &Default::default(),
            &Default::default(),
            LinearAlgebra::Auto,
            eigenvalues,
        )
        .unwrap()
        .stability
        .unwrap()
    };
    let plain = check(restpose::verify::Eigenvalues::WhenCheap);
    assert_eq!(plain.verdict, Verdict::Stable);
    assert!(plain.eigenvalues.is_empty() && plain.modes.is_empty());
    let tol = r.stability.as_ref().unwrap().tolerance;
    assert!(
        (plain.tolerance - tol).abs() <= 1e-9 * tol,
        "{} vs analyze's {tol}",
        plain.tolerance
    );
    let full = check(restpose::verify::Eigenvalues::Always);
    let (_, re) = restpose::solve(
        &m,
        &Options {
            eigenvalues: true,
            ..Default::default()
        },
    )
    .unwrap();
    let listed = &re.stability.as_ref().unwrap().eigenvalues;
    assert_eq!(full.eigenvalues.len(), listed.len());
    for (a, b) in full.eigenvalues.iter().zip(listed) {
        assert!((a - b).abs() <= 1e-8 * b.abs(), "{a} vs {b}");
    }
}
