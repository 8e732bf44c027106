//! Evaluation of the partitioned problem at a configuration: the corrector, the reduced
//! gradient and the reduced Hessian.
//!
//! With `q = [u; v]`, `Φ_q = [Φ_u Φ_v]` (independent rows only) and `H = −Φ_u⁻¹ Φ_v`:
//! - corrector: Newton on `Φ(u; v) = 0` for fixed `v`: `Φ_u δu = −Φ`;
//! - multipliers: `Φ_uᵀ μ = V_uᵀ`, so that `V_qᵀ = Φ_qᵀ μ` at equilibrium;
//! - reduced gradient (eq. 37): `∂V/∂v = V_v + V_u H = V_v − Φ_vᵀ μ`;
//! - reduced Hessian: `Zᵀ (V_qq − Σ_k μ_k Φ_k,qq) Z`, `Z = [H; I]`, exact at feasible points.
//!
//! Independent coordinates are scaled, `v = S v̂` (positions by the characteristic length), and
//! gradients and Hessians are reported in the scaled coordinates `v̂`.

use super::partition::{partition, Partition};
use crate::constraints::{Constraints, Triplets};
use crate::forces::{potential, Energy};
use crate::model::Model;
use nalgebra::{DMatrix, DVector, LU};

/// The model, its constraint rows and scratch space.
pub(crate) struct System<'a> {
    pub(crate) model: &'a Model,
    pub(crate) cons: Constraints,
    /// Column scale per coordinate (`L` for positions, 1 for Euler parameters).
    pub(crate) scale: Vec<f64>,
    /// Row scale per constraint row (`L^−k` for a row in m^k).
    pub(crate) row_scale: Vec<f64>,
    phi: DVector<f64>,
    jac: Triplets,
}

/// Quantities at a feasible configuration under a partition.
pub(crate) struct Eval {
    pub(crate) energy: Energy,
    /// `V − μᵀ Φ` over the independent rows: the energy corrected to first order for the
    /// corrector's residual [J].
    pub(crate) merit: f64,
    /// Multipliers of the independent rows (in `Partition::rows` order).
    pub(crate) mu: DVector<f64>,
    /// Reduced gradient in scaled coordinates.
    pub(crate) grad_v: DVector<f64>,
    pub(crate) lu: LU<f64, nalgebra::Dyn, nalgebra::Dyn>,
    pub(crate) phi_v: DMatrix<f64>,
}

/// Column scale per coordinate: the characteristic length for positions, 1 for Euler
/// parameters.
pub(crate) fn coordinate_scale(model: &Model) -> Vec<f64> {
    let l = model.length_scale;
    (0..model.coordinate_count())
        .map(|i| if i % 7 < 3 { l } else { 1.0 })
        .collect()
}

/// Solves `Aᵀ x = b` with the factors `P A = L U` of `A`: `Uᵀ y = b`, `Lᵀ z = y`, `x = Pᵀ z`.
fn solve_transpose(
    lu: &LU<f64, nalgebra::Dyn, nalgebra::Dyn>,
    b: DVector<f64>,
) -> Option<DVector<f64>> {
    let y = lu.u().tr_solve_upper_triangular(&b)?;
    let mut z = lu.l().tr_solve_lower_triangular(&y)?;
    lu.p().inv_permute_rows(&mut z);
    Some(z)
}

/// Why the corrector gave up.
#[derive(Debug)]
pub(crate) struct CorrectorFailure;

impl<'a> System<'a> {
    pub(crate) fn new(model: &'a Model, cons: Constraints) -> Self {
        let scale = coordinate_scale(model);
        let l = model.length_scale;
        let row_scale = (0..cons.len())
            .map(|i| l.powi(-cons.length_power(i)))
            .collect();
        System {
            row_scale,
            model,
            phi: DVector::zeros(cons.len()),
            jac: Triplets::default(),
            cons,
            scale,
        }
    }

    /// `Φ(q)`.
    pub(crate) fn residual(&mut self, q: &DVector<f64>) -> &DVector<f64> {
        self.cons.evaluate(self.model, q, &mut self.phi, None);
        &self.phi
    }

    /// `‖D Φ‖∞` at the point of the last evaluation: the residual with each row in m^k divided
    /// by `L^k`, so that one tolerance means the same in any length unit.
    pub(crate) fn dimensionless_residual(&self) -> f64 {
        self.phi
            .iter()
            .zip(&self.row_scale)
            .map(|(p, s)| (p * s).abs())
            .fold(0.0, f64::max)
    }

    /// `Φ` at the point of the last [`System::jacobian`] or [`System::residual`] call.
    pub(crate) fn phi(&self) -> &DVector<f64> {
        &self.phi
    }

    /// Dense `Φ_q(q)` (and `Φ(q)` into the scratch).
    pub(crate) fn jacobian(&mut self, q: &DVector<f64>) -> DMatrix<f64> {
        self.cons
            .evaluate(self.model, q, &mut self.phi, Some(&mut self.jac));
        self.jac.to_dense()
    }

    /// Partition at `q`.
    pub(crate) fn partition(&mut self, q: &DVector<f64>) -> Partition {
        let j = self.jacobian(q);
        partition(&j, &self.row_scale, &self.scale)
    }

    /// Newton corrector: solves the independent rows for `u` with `v` fixed; returns the number
    /// of iterations. Also fails if the redundant rows are not satisfied at the end.
    pub(crate) fn correct(
        &mut self,
        q: &mut DVector<f64>,
        part: &Partition,
        tol: f64,
        max_iterations: usize,
    ) -> Result<usize, CorrectorFailure> {
        let r = part.rows.len();
        let mut first = f64::INFINITY;
        for it in 0..=max_iterations {
            let j = self.jacobian(q);
            let res = part
                .rows
                .iter()
                .map(|&i| self.phi[i].abs() * self.row_scale[i])
                .fold(0.0, f64::max);
            if !res.is_finite() {
                return Err(CorrectorFailure);
            }
            if res <= tol {
                let all = self.dimensionless_residual();
                return if all <= tol.max(1e-8) {
                    Ok(it)
                } else {
                    Err(CorrectorFailure)
                };
            }
            if it == 0 {
                first = res;
            } else if res > 1e3 * first.max(tol) {
                return Err(CorrectorFailure);
            }
            if it == max_iterations {
                break;
            }
            let phi_u = DMatrix::from_fn(r, r, |a, b| j[(part.rows[a], part.dependent[b])]);
            let rhs = DVector::from_fn(r, |a, _| -self.phi[part.rows[a]]);
            let Some(du) = phi_u.lu().solve(&rhs) else {
                return Err(CorrectorFailure);
            };
            for (k, &c) in part.dependent.iter().enumerate() {
                q[c] += du[k];
            }
        }
        Err(CorrectorFailure)
    }

    /// Energy, multipliers and reduced gradient at a feasible `q`; `None` where the energy is
    /// undefined or `Φ_u` is singular.
    pub(crate) fn evaluate(&mut self, q: &DVector<f64>, part: &Partition) -> Option<Eval> {
        let j = self.jacobian(q);
        let mut grad_q = DVector::zeros(q.len());
        let energy = potential(self.model, q, &mut grad_q, None)?;
        let r = part.rows.len();
        let dof = part.independent.len();
        let phi_u = DMatrix::from_fn(r, r, |a, b| j[(part.rows[a], part.dependent[b])]);
        let phi_v = DMatrix::from_fn(r, dof, |a, b| j[(part.rows[a], part.independent[b])]);
        let v_u = DVector::from_fn(r, |a, _| grad_q[part.dependent[a]]);
        let lu = phi_u.lu();
        let mu = if r > 0 {
            solve_transpose(&lu, v_u)?
        } else {
            DVector::zeros(0)
        };
        let mut grad_v =
            DVector::from_fn(dof, |b, _| grad_q[part.independent[b]]) - phi_v.transpose() * &mu;
        for (b, &c) in part.independent.iter().enumerate() {
            grad_v[b] *= self.scale[c];
        }
        let merit = energy.total
            - part
                .rows
                .iter()
                .zip(mu.iter())
                .map(|(&row, m)| m * self.phi[row])
                .sum::<f64>();
        Some(Eval {
            energy,
            merit,
            mu,
            grad_v,
            lu,
            phi_v,
        })
    }

    /// `Z δv̂` for a step `δv̂` in scaled independent coordinates: the first-order change of all
    /// coordinates.
    pub(crate) fn tangent_step(
        &self,
        part: &Partition,
        eval: &Eval,
        dv: &DVector<f64>,
    ) -> DVector<f64> {
        let n = self.model.coordinate_count();
        let mut dq = DVector::zeros(n);
        let mut dvu = dv.clone();
        for (b, &c) in part.independent.iter().enumerate() {
            dvu[b] *= self.scale[c];
            dq[c] = dvu[b];
        }
        if !part.rows.is_empty() {
            let rhs = -(&eval.phi_v * dvu);
            if let Some(du) = eval.lu.solve(&rhs) {
                for (k, &c) in part.dependent.iter().enumerate() {
                    dq[c] = du[k];
                }
            }
        }
        dq
    }

    /// The null-space basis `Z = [H; I] S` (n × dof) at `eval`.
    pub(crate) fn null_basis(&self, part: &Partition, eval: &Eval) -> DMatrix<f64> {
        let n = self.model.coordinate_count();
        let dof = part.independent.len();
        let mut z = DMatrix::zeros(n, dof);
        let h = if part.rows.is_empty() {
            DMatrix::zeros(0, dof)
        } else {
            eval.lu
                .solve(&(-&eval.phi_v))
                .unwrap_or_else(|| DMatrix::zeros(part.rows.len(), dof))
        };
        for b in 0..dof {
            let s = self.scale[part.independent[b]];
            z[(part.independent[b], b)] = s;
            for (k, &c) in part.dependent.iter().enumerate() {
                z[(c, b)] = h[(k, b)] * s;
            }
        }
        z
    }

    /// The Hessian of the Lagrangian `W = V_qq − Σ μ_k Φ_k,qq` at `q`.
    pub(crate) fn lagrangian_hessian(
        &self,
        q: &DVector<f64>,
        part: &Partition,
        eval: &Eval,
    ) -> DMatrix<f64> {
        let n = q.len();
        let mut w = DMatrix::zeros(n, n);
        let mut g = DVector::zeros(n);
        let _ = potential(self.model, q, &mut g, Some(&mut w));
        let mut weights = DVector::zeros(self.cons.len());
        for (k, &row) in part.rows.iter().enumerate() {
            weights[row] = -eval.mu[k];
        }
        self.cons.add_hessian(self.model, q, &weights, &mut w);
        w
    }

    /// The reduced Hessian `Zᵀ W Z` in scaled coordinates.
    pub(crate) fn reduced_hessian(
        &self,
        q: &DVector<f64>,
        part: &Partition,
        eval: &Eval,
    ) -> DMatrix<f64> {
        let z = self.null_basis(part, eval);
        let w = self.lagrangian_hessian(q, part, eval);
        let hr = z.transpose() * w * &z;
        (&hr + hr.transpose()) * 0.5
    }
}

#[cfg(test)]
mod tests {
    //! The assembled global derivatives against central differences, on real robots at
    //! random (non-assembled, non-unit) configurations.
    use super::*;
    use crate::urdf::{load_str, ImportOptions};

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
            include_str!("../../robots/pendulum.urdf"),
            include_str!("../../robots/slider_crank.urdf"),
            include_str!("../../robots/four_bar_spatial.urdf"),
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
        let mut s = seed;
        DVector::from_fn(n, |i, _| {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let r = ((s >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0;
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
            potential(&model, &q, &mut g, Some(&mut h)).unwrap();
            let step = 1e-6;
            for i in 0..n {
                let mut qp = q.clone();
                let mut qm = q.clone();
                qp[i] += step;
                qm[i] -= step;
                let (mut gp, mut gm) = (DVector::zeros(n), DVector::zeros(n));
                let vp = potential(&model, &qp, &mut gp, None).unwrap().total;
                let vm = potential(&model, &qm, &mut gm, None).unwrap().total;
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
            let mut sys = System::new(&model, sys_cons);
            let m = sys.cons.len();
            let q = random_q(n, 11);
            let j = sys.jacobian(&q);
            let w = DVector::from_fn(m, |i, _| ((i * 37 % 11) as f64 - 5.0) * 0.1);
            let mut h = DMatrix::zeros(n, n);
            sys.cons.add_hessian(&model, &q, &w, &mut h);
            let step = 1e-6;
            for i in 0..n {
                let mut qp = q.clone();
                let mut qm = q.clone();
                qp[i] += step;
                qm[i] -= step;
                let jp = sys.jacobian(&qp);
                let php = sys.phi.clone();
                let jm = sys.jacobian(&qm);
                let phm = sys.phi.clone();
                for r in 0..m {
                    let fd = (php[r] - phm[r]) / (2.0 * step);
                    assert_fd(j[(r, i)], fd, 1e-6, || {
                        format!(
                            "{}: Φ_q[{},{i}] ({}) {} vs {fd}",
                            model.name,
                            r,
                            sys.cons.row_name(r),
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

    /// The reduced gradient equals the derivative of f(v) = V(u(v), v) along each independent
    /// coordinate (finite differences through the corrector), and the reduced Hessian the
    /// derivative of the reduced gradient.
    #[test]
    fn reduced_gradient_and_hessian_match_differences_through_the_corrector() {
        for model in models() {
            let q0 = crate::solver::initial_state(&model).q;
            let q = crate::solver::assemble_only(&model, q0, &[]).unwrap();
            let mut sys = System::new(&model, Constraints::new(&model, &[]));
            let part = sys.partition(&q);
            let e = sys.evaluate(&q, &part).unwrap();
            let hr = sys.reduced_hessian(&q, &part, &e);
            let step = 1e-5;
            for (b, &c) in part.independent.iter().enumerate() {
                let at = |sign: f64, sys: &mut System| {
                    let mut qq = q.clone();
                    qq[c] += sign * step * sys.scale[c];
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
}
