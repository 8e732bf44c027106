//! The assembled global derivatives against central differences, on real robots at
//! random (non-assembled, non-unit) configurations.
use super::*;
use crate::constraints::Constraints;
use crate::forces::potential;
use crate::jet::HessianSink;
use crate::model::Model;
use crate::urdf::{load_str, ImportOptions};
use nalgebra::{DMatrix, DVector};

/// Analytic value against a central difference, relative to `1 + |value|`.
fn assert_fd(analytic: f64, fd: f64, tol: f64, what: impl Fn() -> String) {
    assert!(
        (fd - analytic).abs() < tol * (1.0 + analytic.abs().min(fd.abs())),
        "{}",
        what()
    );
}

fn models() -> Vec<Model> {
    [
        include_str!("../../../robots/pendulum.urdf"),
        include_str!("../../../robots/slider_crank.urdf"),
        include_str!("../../../robots/four_bar_spatial.urdf"),
    ]
    .iter()
    .map(|t| {
        load_str(t, "robot.urdf", &ImportOptions::default())
            .unwrap()
            .model
    })
    .collect()
}

fn random_q(n: usize, seed: u64) -> DVector<f64> {
    let mut lcg = crate::lcg::Lcg::new(seed);
    DVector::from_fn(n, |i, _| {
        let r = lcg.signed();
        if i % 7 == 3 {
            1.0 + 0.2 * r
        } else {
            0.3 * r
        }
    })
}

#[test]
fn potential_gradient_and_hessian_match_finite_differences() {
    for model in models() {
        let n = model.coordinate_count();
        let q = random_q(n, 7);
        let mut g = DVector::zeros(n);
        let mut h = DMatrix::zeros(n, n);
        potential(
            &model,
            &Default::default(),
            &q,
            &mut g,
            Some(&mut h as &mut dyn HessianSink),
        )
        .unwrap();
        let step = 1e-6;
        for i in 0..n {
            let mut qp = q.clone();
            let mut qm = q.clone();
            qp[i] += step;
            qm[i] -= step;
            let (mut gp, mut gm) = (DVector::zeros(n), DVector::zeros(n));
            let vp = potential(&model, &Default::default(), &qp, &mut gp, None)
                .unwrap()
                .total;
            let vm = potential(&model, &Default::default(), &qm, &mut gm, None)
                .unwrap()
                .total;
            let fd = (vp - vm) / (2.0 * step);
            assert_fd(g[i], fd, 1e-6, || {
                format!("{}: V_q[{i}] {} vs {fd}", model.name, g[i])
            });
            for j in 0..n {
                let fdh = (gp[j] - gm[j]) / (2.0 * step);
                assert_fd(h[(j, i)], fdh, 1e-5, || {
                    format!("{}: V_qq[{j},{i}] {} vs {fdh}", model.name, h[(j, i)])
                });
            }
        }
    }
}

#[test]
fn constraint_jacobian_and_weighted_hessian_match_finite_differences() {
    for model in models() {
        let n = model.coordinate_count();
        let sys_cons = Constraints::new(&model, &[(crate::model::JointId(0), 0, 0.3)]);
        let mut sys = System::new(
            &model,
            sys_cons,
            Backend::choose(&model, crate::solver::LinearAlgebra::Auto),
        );
        let m = sys.problem.cons.len();
        let q = random_q(n, 11);
        let j = sys.jacobian(&q);
        let w = DVector::from_fn(m, |i, _| ((i * 37 % 11) as f64 - 5.0) * 0.1);
        let mut h = DMatrix::zeros(n, n);
        sys.problem.cons.add_hessian(&model, &q, &w, &mut h);
        let step = 1e-6;
        for i in 0..n {
            let mut qp = q.clone();
            let mut qm = q.clone();
            qp[i] += step;
            qm[i] -= step;
            let jp = sys.jacobian(&qp);
            let php = sys.work.phi.clone();
            let jm = sys.jacobian(&qm);
            let phm = sys.work.phi.clone();
            for r in 0..m {
                let fd = (php[r] - phm[r]) / (2.0 * step);
                assert_fd(j[(r, i)], fd, 1e-6, || {
                    format!(
                        "{}: Φ_q[{},{i}] ({}) {} vs {fd}",
                        model.name,
                        r,
                        sys.problem.cons.row_name(&model, r),
                        j[(r, i)]
                    )
                });
            }
            let gp = jp.transpose() * &w;
            let gm = jm.transpose() * &w;
            for k in 0..n {
                let fd = (gp[k] - gm[k]) / (2.0 * step);
                assert_fd(h[(k, i)], fd, 1e-5, || {
                    format!("{}: (wᵀΦ)_qq[{k},{i}] {} vs {fd}", model.name, h[(k, i)])
                });
            }
        }
    }
}

/// The Newton step from the sparse KKT system equals `−Ĥ⁻¹ ∇f` with the reduced Hessian
/// formed explicitly (dense path), and the sparse path's reduced gradient and reduced
/// Hessian equal the dense path's under the same partition.
#[test]
fn kkt_step_is_the_reduced_newton_step() {
    let mut all = models();
    all.push(
        load_str(
            &crate::generate::ladder(3),
            "l.urdf",
            &ImportOptions::default(),
        )
        .unwrap()
        .model,
    );
    for model in all {
        let q0 = crate::solver::initial_state(&model).q;
        let q = crate::solver::assemble_only(&model, q0, &mut Default::default(), &[]).unwrap();
        let mut dense = System::new(&model, Constraints::new(&model, &[]), Backend::Dense);
        let part = dense.partition(&q);
        let ed = dense.evaluate(&q, &part).unwrap();
        let hd = dense.reduced_hessian(&q, &part, &ed);
        let mut sparse = System::new(&model, Constraints::new(&model, &[]), Backend::Sparse);
        let es = sparse.evaluate(&q, &part).unwrap();
        let hs = sparse.reduced_hessian(&q, &part, &es);
        let scale = hd.amax().max(1.0);
        assert!((&hd - &hs).amax() < 1e-9 * scale, "{}", model.name);
        assert!((&ed.grad_v - &es.grad_v).amax() < 1e-9 * (1.0 + ed.grad_v.amax()));
        let g = &es.grad_v;
        if g.amax() < 1e-12 {
            continue;
        }
        assert!(
            sparse.factor_kkt(&q, &part, &es, true, 0.0)
                != crate::solver::sparse::kkt::Factored::None,
            "{}",
            model.name
        );
        let mut b = DVector::zeros(q.len());
        for (k, &c) in part.independent.iter().enumerate() {
            b[c] = -g[k];
        }
        let dq = sparse.kkt_solve(&b).unwrap();
        let d = DVector::from_iterator(g.len(), part.independent.iter().map(|&c| dq[c]));
        let expected = hd.clone().lu().solve(&(-g)).unwrap();
        assert!(
            (&d - &expected).amax() < 1e-8 * expected.amax(),
            "{}: KKT step {d} vs reduced Newton step {expected}",
            model.name
        );
        // The LU fallback (the full matrix rebuilt from the stored upper triangle) gives the
        // same step.
        assert_eq!(
            sparse.kkt_fall_back_to_lu(),
            crate::solver::sparse::kkt::Factored::Lu,
            "{}",
            model.name
        );
        let dq_lu = sparse.kkt_solve(&b).unwrap();
        assert!(
            (&dq_lu - &dq).amax() < 1e-8 * (1.0 + dq.amax()),
            "{}: LU step differs from the LDLT step",
            model.name
        );
        // δq is the tangent step of δv: Φ_q δq = 0 on the independent rows.
        let full = sparse.tangent_step(&part, &es, &d);
        let dq_unscaled = DVector::from_iterator(
            q.len(),
            (0..q.len()).map(|i| dq[i] * sparse.problem.scaling.columns[i]),
        );
        assert!(
            (&full - &dq_unscaled).amax() < 1e-8 * (1.0 + full.amax()),
            "{}",
            model.name
        );
    }
}

/// The reduced gradient equals the derivative of f(v) = V(u(v), v) along each independent
/// coordinate (finite differences through the corrector), and the reduced Hessian the
/// derivative of the reduced gradient.
#[test]
fn reduced_gradient_and_hessian_match_differences_through_the_corrector() {
    for model in models() {
        let q0 = crate::solver::initial_state(&model).q;
        let q = crate::solver::assemble_only(&model, q0, &mut Default::default(), &[]).unwrap();
        let mut sys = System::new(
            &model,
            Constraints::new(&model, &[]),
            Backend::choose(&model, crate::solver::LinearAlgebra::Auto),
        );
        let part = sys.partition(&q);
        let e = sys.evaluate(&q, &part).unwrap();
        let hr = sys.reduced_hessian(&q, &part, &e);
        let step = 1e-5;
        for (b, &c) in part.independent.iter().enumerate() {
            let at = |sign: f64, sys: &mut System| {
                let mut qq = q.clone();
                qq[c] += sign * step * sys.problem.scaling.columns[c];
                sys.correct(&mut qq, &part, 1e-13, 50).unwrap();
                sys.evaluate(&qq, &part).unwrap()
            };
            let ep = at(1.0, &mut sys);
            let em = at(-1.0, &mut sys);
            let fd = (ep.energy.total - em.energy.total) / (2.0 * step);
            assert_fd(e.grad_v[b], fd, 1e-6, || {
                format!("{}: ∂f/∂v[{b}] {} vs {fd}", model.name, e.grad_v[b])
            });
            for a in 0..part.independent.len() {
                let fdh = (ep.grad_v[a] - em.grad_v[a]) / (2.0 * step);
                assert_fd(hr[(a, b)], fdh, 1e-5, || {
                    format!(
                        "{}: reduced Hessian [{a},{b}] {} vs {fdh}",
                        model.name,
                        hr[(a, b)]
                    )
                });
            }
        }
    }
}

/// `|D_i Φ_i| / (ε m^{k_i})` over the rows `rows`, with the extent `m` computed here from the
/// body origins: how many units in the last place of its scale each row is off.
fn worst_ulps(sys: &System, q: &DVector<f64>, rows: &[usize]) -> f64 {
    let l = sys.problem.model.length_scale();
    let m = (0..q.len())
        .filter(|i| i % 7 < 3)
        .fold(1.0f64, |m, i| m.max(q[i].abs() / l));
    let phi = sys.phi().clone();
    rows.iter()
        .map(|&i| {
            let k = sys.problem.cons.length_power(i);
            (phi[i] * l.powi(-k)).abs() / (f64::EPSILON * m.powi(k))
        })
        .fold(0.0, f64::max)
}

/// The corrector takes a point whose rows are all within their rounding floor (8 ulps of the
/// extent in `L^k`) as it is, although its residual is above the chord steps' target
/// (`10⁻³` of the tolerance), and corrects a point above the floor (but within the
/// tolerance) to the target or the floor.
#[test]
fn the_corrector_stops_at_the_rounding_floor_and_not_above_it() {
    let model = load_str(
        &crate::generate::chain(300, false),
        "chain.urdf",
        &ImportOptions::default(),
    )
    .unwrap()
    .model;
    let q0 = crate::solver::initial_state(&model).q;
    let q = crate::solver::assemble_only(&model, q0, &mut Default::default(), &[]).unwrap();
    let mut sys = System::new(
        &model,
        Constraints::new(&model, &[]),
        Backend::choose(&model, crate::solver::LinearAlgebra::Auto),
    );
    let part = sys.partition(&q);
    let e = sys.evaluate(&q, &part).unwrap();
    let tol = 1e-10;
    // A position coordinate of the last body, a dependent one.
    let last = model.bodies.len() - 1;
    let c = *part
        .dependent
        .iter()
        .find(|&&c| c / 7 == last && c % 7 < 3)
        .expect("a dependent position of the last body");
    let l = model.length_scale();
    let scaled = |sys: &mut System, q: &DVector<f64>| {
        sys.residual(q);
        sys.problem.scaling.residual_over(sys.phi(), &part.rows)
    };
    // 1.5 · 10⁻¹³ L off (about 5 ulps of the 60 m chain): above the target, within the floor.
    let mut at_floor = q.clone();
    at_floor[c] += 1.5e-13 * l;
    let res = scaled(&mut sys, &at_floor);
    let ulps = worst_ulps(&sys, &at_floor, &part.rows);
    assert!(res > 1e-3 * tol && ulps <= 8.0, "res {res:e}, {ulps} ulps");
    let before = at_floor.clone();
    let its = sys
        .correct_from(&mut at_floor, &part, tol, 25, Some(&e.factors))
        .unwrap();
    assert_eq!(its, 0);
    assert_eq!(at_floor, before, "a point at the floor is not moved");
    // 10⁻¹¹ L off: within the tolerance but far above the floor; corrected.
    let mut above = q.clone();
    above[c] += 1e-11 * l;
    let res = scaled(&mut sys, &above);
    assert!(res > 1e-12 && res <= tol, "res {res:e}");
    let its = sys
        .correct_from(&mut above, &part, tol, 25, Some(&e.factors))
        .unwrap();
    assert!(its >= 1);
    let res = scaled(&mut sys, &above);
    let ulps = worst_ulps(&sys, &above, &part.rows);
    assert!(res <= 1e-3 * tol || ulps <= 8.0, "res {res:e}, {ulps} ulps");
    assert!((above[c] - q[c]).abs() < 1e-12 * l, "corrected back");
}
