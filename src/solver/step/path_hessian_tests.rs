//! The path curvature `C` (module `path_hessian`): against central differences of the energy
//! along the search path, against the direct sum over bodies and edges, and with the still
//! edges' twists skipped against all of them computed, bit for bit.
use super::*;
use crate::constraints::Constraints;
use crate::solver::system::Backend;
use crate::state::State;
use crate::urdf::{load_str, ImportOptions};

use crate::solver::step::retraction::tests::ARM;

/// `C` with the twists of unmoved edges left at zero equals `C` with every twist
/// computed, bit for bit, on a chain (the tree path: `Z`'s blocks above each joint zero)
/// and on the branched arm, fixed and floating.
#[test]
fn still_edges_skipped_change_no_bit() {
    let chain = crate::generate::chain(12, false);
    let cases = [
        (chain.as_str(), Backend::Tree, false),
        (ARM, Backend::Dense, false),
        (ARM, Backend::Tree, true),
    ];
    for (text, backend, floating) in cases {
        let options = ImportOptions {
            floating_base: floating,
            ..ImportOptions::default()
        };
        let model = load_str(text, "m.urdf", &options).unwrap().model;
        let values: crate::state::JointValues = if text == ARM {
            [("pan", 0.4), ("slide", 0.1), ("roll", -0.7), ("lift", 1.1)]
                .iter()
                .map(|(n, v)| (n.to_string(), vec![*v]))
                .collect()
        } else {
            (0..12)
                .map(|i| (format!("joint{i}"), vec![0.3 * (i as f64).sin()]))
                .collect()
        };
        let q = State::from_joint_values(&model, &values).q;
        let sys = &mut System::new(&model, Constraints::new(&model, &[]), backend);
        let part = sys.partition(&q);
        let eval = sys.evaluate(&q, &part).unwrap();
        let z = sys.null_basis(&part, &eval);
        let still = z
            .as_slice()
            .chunks_exact(7)
            .filter(|blk| blk.iter().all(|&v| v == 0.0))
            .count();
        if matches!(backend, Backend::Tree) && !floating {
            assert!(still > 0, "the chain's columns leave bodies still");
        }
        let fast = curvature_of(sys, &q, &part, &eval, Some(&z), true);
        let full = curvature_of(sys, &q, &part, &eval, Some(&z), false);
        assert!(fast.amax() > 0.0);
        for (x, y) in fast.iter().zip(full.iter()) {
            assert_eq!(x.to_bits(), y.to_bits(), "{backend:?}: {x:e} against {y:e}");
        }
    }
}

/// `C` equals the central second differences of `∇fᵀ v̂` along the search path, on a
/// fixed and a floating base, away from equilibrium.
#[test]
fn path_curvature_is_the_second_derivative_along_the_path() {
    for floating in [false, true] {
        let options = ImportOptions {
            floating_base: floating,
            ..ImportOptions::default()
        };
        let model = load_str(ARM, "arm.urdf", &options).unwrap().model;
        let values = [("pan", 0.4), ("slide", 0.1), ("roll", -0.7), ("lift", 1.1)]
            .iter()
            .map(|(n, v)| (n.to_string(), vec![*v]))
            .collect();
        let q = State::from_joint_values(&model, &values).q;
        let sys = &mut System::new(&model, Constraints::new(&model, &[]), Backend::Dense);
        let part = sys.partition(&q);
        let eval = sys.evaluate(&q, &part).unwrap();
        assert!(eval.grad_v.amax() > 0.1, "away from equilibrium");
        let c = path_curvature(sys, &q, &part, &eval, None);
        let dof = part.independent.len();
        let columns = &sys.problem.scaling.columns;
        let h = 1e-4;
        let second = |d: &DVector<f64>| -> f64 {
            let dq = sys.tangent_step(&part, &eval, d);
            let plus = sys.problem.retraction.point(&q, &dq, h);
            let minus = sys.problem.retraction.point(&q, &dq, -h);
            part.independent
                .iter()
                .enumerate()
                .map(|(k, &i)| eval.grad_v[k] * (plus[i] + minus[i] - 2.0 * q[i]) / columns[i])
                .sum::<f64>()
                / (h * h)
        };
        for trial in 0..4 {
            let d = DVector::from_fn(dof, |i, _| ((1 + i + 3 * trial) as f64).sin());
            let fd = second(&d);
            let exact = d.dot(&(&c * &d));
            assert!(
                (fd - exact).abs() < 1e-5 * (1.0 + exact.abs()),
                "floating {floating}, trial {trial}: {exact} against {fd}"
            );
        }
        assert!(c.amax() > 1e-3, "the path is curved in v̂");
    }
}

/// The per-edge sums give the direct sum over bodies and edges of the module docs
/// (`C_ij = Σ_b Σ_l wy_b·(a_i × ξ_j(y_b)) + ¼ (a_i ⊗ ω_j)·ρ_b`, written out here) to
/// rounding, on a branched tree on the dense and the tree path.
#[test]
fn per_edge_sums_equal_the_direct_sum() {
    let model = load_str(ARM, "arm.urdf", &ImportOptions::default())
        .unwrap()
        .model;
    let values = [("pan", 0.4), ("slide", 0.1), ("roll", -0.7), ("lift", 1.1)]
        .iter()
        .map(|(n, v)| (n.to_string(), vec![*v]))
        .collect();
    let q = State::from_joint_values(&model, &values).q;
    for backend in [Backend::Dense, Backend::Tree] {
        let sys = &mut System::new(&model, Constraints::new(&model, &[]), backend);
        let part = sys.partition(&q);
        let eval = sys.evaluate(&q, &part).unwrap();
        let c = path_curvature(sys, &q, &part, &eval, None);
        let dof = part.independent.len();
        let columns = &sys.problem.scaling.columns;
        let parents = sys.problem.retraction.parents();
        let twists: Vec<Vec<(Vector3<f64>, Vector3<f64>)>> = (0..dof)
            .map(|i| {
                let mut e = DVector::zeros(dof);
                e[i] = 1.0;
                let dq = sys.tangent_step(&part, &eval, &e);
                (0..parents.len())
                    .map(|b| relative_twist(&q, &dq, b, parents[b]))
                    .collect()
            })
            .collect();
        let mut direct = DMatrix::<f64>::zeros(dof, dof);
        for (k, &col) in part.independent.iter().enumerate() {
            let b = col / 7;
            let mut w = [0.0; 7];
            w[col % 7] = eval.grad_v[k] / columns[col];
            let y = position(&q, b);
            let p = Vector4::new(q[7 * b + 3], q[7 * b + 4], q[7 * b + 5], q[7 * b + 6]);
            let wy = Vector3::new(w[0], w[1], w[2]);
            let wp = Vector4::new(w[3], w[4], w[5], w[6]);
            let mut chain = vec![b];
            while let Some(a) = parents[*chain.last().unwrap_or(&b)] {
                chain.push(a);
            }
            let mut before = vec![Vector3::<f64>::zeros(); dof];
            for &l in chain.iter().rev() {
                let xl = position(&q, l);
                for i in 0..dof {
                    let a = twists[i][l].0 + 2.0 * before[i];
                    for j in 0..dof {
                        let (omega, vl) = twists[j][l];
                        let xi = omega.cross(&(y - xl)) + vl;
                        let ao = a.cross(&omega);
                        let pq = Vector4::new(-a.dot(&omega), ao.x, ao.y, ao.z);
                        // wᵀ ¼ (pq ⊗ p), the second derivative of p written out.
                        direct[(i, j)] += wy.dot(&a.cross(&xi)) + 0.25 * wp.dot(&compose(&pq, &p));
                    }
                }
                for (i, bi) in before.iter_mut().enumerate() {
                    *bi += twists[i][l].0;
                }
            }
        }
        let direct = (&direct + direct.transpose()) * 0.5;
        let scale = direct.amax();
        assert!(scale > 1e-3);
        assert!(
            (&c - &direct).amax() <= 1e-12 * scale,
            "{backend:?}: {c} against {direct}"
        );
    }
}
