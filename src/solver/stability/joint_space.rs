//! The reduced Hessian in joint coordinates, in physical units, for the stability report.
//!
//! The solver's reduced Hessian `Ĥ = Zᵀ W Z` is the second derivative of the energy along the
//! feasible motions in the partition's scaled independent coordinates `v̂`: its eigenvalues
//! depend on which Cartesian coordinates the partition made independent (and so on the start)
//! and are in J. Reported instead is the same quadratic form in joint coordinates `θ`:
//!
//! `H_θ = T_I⁻ᵀ Ĥ T_I⁻¹`,   `T = J_θ Z` (the change of every joint coordinate per `δv̂`),
//!
//! `T_I` the rows of `dof` independent joint coordinates. At a rest pose the gradient along
//! the feasible motions vanishes, so the energy's second derivative in any chart is this
//! congruent form: `H_θ` has the eigenvalues' signs of `Ĥ` (Sylvester) and the values
//! `d²V/dθ²` in N m/rad (rotations) and N/m (slides), whatever the start. A pendulum of mass
//! `m` at distance `l` hanging still gets `m g l`.
//!
//! The joint coordinates, in the model's file order: every scalar coordinate of a tree joint
//! (revolute, prismatic, ... `kinematics::coordinate`); for a spherical or floating tree joint
//! the child's rotation relative to the parent (world axes, rad) and for a floating one its
//! origin's relative displacement (m); for a joint whose coordinates do not span its motion
//! (a distance or point-on-line tree joint) those six as well; for a floating base (a body no
//! tree joint moves) its origin's displacement and rotation `[x, y, z, rx, ry, rz]`, named by
//! its link; a loop joint's scalar coordinates are listed in the modes too (never chosen as
//! independent). Where loops make joint coordinates dependent, the independent ones are chosen
//! by pivoted Gram–Schmidt on the rows of an orthonormal basis of `T`'s range (largest row
//! first, file order breaking ties): a choice that depends on the pose only. Mode shapes are
//! the eigenvectors mapped back to every joint coordinate, `δθ = T T_I⁻¹ y`, scaled so the
//! largest is ±1.

use crate::jet::{global_index, pair_of, NL};
use crate::joint::TreeMotion;
use crate::model::Model;
use crate::solver::partition::Partition;
use crate::solver::system::{Eval, System};
use nalgebra::{DMatrix, DVector, Matrix3, Matrix3x4, Vector4};

/// A sparse row of `J_θ`: (global coordinate, derivative).
type Row = Vec<(usize, f64)>;

/// The joint coordinates of `model` at `q`, grouped by joint (or floating base link), in
/// file order, with whether they may be chosen as independent (a loop joint's scalar
/// coordinates are listed in the modes only).
fn chart(model: &Model, q: &DVector<f64>) -> Vec<(String, Vec<Row>, bool)> {
    let mut out = Vec::new();
    let mut moved = vec![false; model.bodies.len()];
    // 2 E(p): world angular velocity per ṗ of body b.
    let omega = |b: usize| -> Vec<Row> {
        let i = 7 * b + 3;
        let p = Vector4::new(q[i], q[i + 1], q[i + 2], q[i + 3]);
        let e = nalgebra::Vector3::new(p[1], p[2], p[3]);
        let mut m = Matrix3x4::zeros();
        m.set_column(0, &(-e));
        m.fixed_view_mut::<3, 3>(0, 1)
            .copy_from(&(crate::math::skew(&e) + Matrix3::identity() * p[0]));
        let m = m * (2.0 / p.norm_squared().max(f64::MIN_POSITIVE));
        (0..3)
            .map(|r| (0..4).map(|c| (i + c, m[(r, c)])).collect())
            .collect()
    };
    let translation = |b: usize| -> Vec<Row> { (0..3).map(|r| vec![(7 * b + r, 1.0)]).collect() };
    let relative = |rows_c: Vec<Row>, rows_p: Option<Vec<Row>>| -> Vec<Row> {
        match rows_p {
            None => rows_c,
            Some(p) => rows_c
                .into_iter()
                .zip(p)
                .map(|(mut c, p)| {
                    c.extend(p.into_iter().map(|(g, x)| (g, -x)));
                    c
                })
                .collect(),
        }
    };
    for j in model.joints.iter().filter(|j| !j.merged) {
        if j.tree {
            if let Some(c) = j.bodies[1] {
                moved[c.0] = true;
            }
        }
        let pair = pair_of(&j.bodies, q, false);
        let mut rows: Vec<Row> = (0..j.kind.scalar_coordinates())
            .filter_map(|dof| crate::kinematics::coordinate(j, &pair, dof, 0.0))
            .map(|s| {
                (0..NL)
                    .filter_map(|i| global_index(&j.bodies, i).map(|g| (g, s.g[i])))
                    .collect()
            })
            .collect();
        let motion = j.kind.spec().tree_motion;
        let six = motion == TreeMotion::Pose;
        let (Some(c), p, true) = (j.bodies[1], j.bodies[0], j.tree) else {
            out.push((j.name.clone(), rows, j.tree));
            continue;
        };
        if six {
            rows.extend(relative(translation(c.0), p.map(|p| translation(p.0))));
        }
        if six || motion == TreeMotion::Rotation {
            rows.extend(relative(omega(c.0), p.map(|p| omega(p.0))));
        }
        out.push((j.name.clone(), rows, true));
    }
    for (b, body) in model.bodies.iter().enumerate() {
        if !moved[b] {
            let mut rows = translation(b);
            rows.extend(omega(b));
            out.push((body.name.clone(), rows, true));
        }
    }
    out
}

/// The reduced Hessian `h` (scaled independent coordinates of `part`) in joint coordinates:
/// its eigenvalues (ascending) and the mode shape of each of the lowest `shown`, by joint in
/// file order (`basis`: the null-space basis `Z` at `q` if at hand). `None` where the joint
/// coordinates do not span the feasible motions.
#[allow(clippy::type_complexity)]
pub(crate) fn joint_spectrum(
    sys: &System,
    q: &DVector<f64>,
    part: &Partition,
    eval: &Eval,
    basis: Option<&DMatrix<f64>>,
    h: &DMatrix<f64>,
    shown: usize,
) -> Option<(Vec<f64>, Vec<Vec<(String, Vec<f64>)>>)> {
    let dof = part.independent.len();
    let solved;
    let z = match basis {
        Some(z) => z,
        None => {
            solved = sys.null_basis(part, eval);
            &solved
        }
    };
    let chart = chart(sys.problem.model, q);
    let rows: Vec<&Row> = chart.iter().flat_map(|(_, r, _)| r).collect();
    let selectable: Vec<bool> = chart
        .iter()
        .flat_map(|(_, r, s)| r.iter().map(move |_| *s))
        .collect();
    let t = DMatrix::from_fn(rows.len(), dof, |r, c| {
        rows[r].iter().map(|&(g, x)| x * z[(g, c)]).sum()
    });
    // Every coordinate selectable and as many as the degrees of freedom (a tree of scalar
    // joints): all are chosen, `T_I = T`, and the rank test is the inverse's conditioning,
    // where it settles it (else the general path's singular values decide).
    let all = rows.len() == dof && selectable.iter().all(|&s| s);
    let m = if all {
        well_conditioned_inverse(&t).or_else(|| chosen_inverse(&t, &selectable))?
    } else {
        chosen_inverse(&t, &selectable)?
    };
    let h_theta = m.transpose() * h * &m;
    let h_theta = crate::solver::system::symmetric_part(h_theta);
    let (vals, vecs) = super::eigen::symmetric_eigen(&h_theta);
    let modes = (0..shown.min(dof))
        .map(|k| {
            let d = &t * (&m * vecs.column(k));
            let big = d.amax();
            let scale = if big > 0.0 { 1.0 / big } else { 1.0 };
            let mut at = 0;
            chart
                .iter()
                .filter(|(_, r, _)| !r.is_empty())
                .map(|(name, r, _)| {
                    // Rounding noise (below 1e-12 of the largest change) shown as 0.
                    let v: Vec<f64> = (at..at + r.len())
                        .map(|i| d[i] * scale)
                        .map(|x| if x.abs() < 1e-12 { 0.0 } else { x })
                        .collect();
                    at += r.len();
                    (name.clone(), v)
                })
                .collect()
        })
        .collect();
    Some((vals.iter().copied().collect(), modes))
}

/// The smallest singular value of `T` counted, relative to the largest: below, the joint
/// coordinates are taken not to span the feasible motions (rounding).
const RELATIVE: f64 = 1e-9;

/// `T⁻¹` for a square `t` whose Frobenius condition number `κ_F = ‖T‖_F ‖T⁻¹‖_F` is below
/// `1/RELATIVE`: it bounds the spectral one (`κ₂ ≤ κ_F ≤ dof · κ₂`), so every `T` accepted
/// is one [`chosen_inverse`]'s rank test accepts; from the inverse itself, without a
/// singular value decomposition. `None` leaves the decision to [`chosen_inverse`].
fn well_conditioned_inverse(t: &DMatrix<f64>) -> Option<DMatrix<f64>> {
    let m = t.clone().try_inverse()?;
    (RELATIVE * (t.norm() * m.norm()) < 1.0).then_some(m)
}

/// `T_I⁻¹` for the `dof` rows of `t` chosen (the selectable ones, `selectable`) by pivoted
/// Gram–Schmidt on an orthonormal basis of `T`'s range (module docs); `None` where `T`'s
/// rank (singular values above `RELATIVE` times the largest) is below `dof`.
fn chosen_inverse(t: &DMatrix<f64>, selectable: &[bool]) -> Option<DMatrix<f64>> {
    let (rows, dof) = t.shape();
    let svd = super::svd::svd(t.clone(), true, false)?;
    let top = svd.singular_values.max();
    let kept: Vec<usize> = (0..svd.singular_values.len())
        .filter(|&k| svd.singular_values[k] > RELATIVE * top)
        .collect();
    if kept.len() < dof || top <= 0.0 {
        return None;
    }
    // An orthonormal basis of T's range, then the rows with the most independent motion.
    let u = svd.u.as_ref()?;
    let mut basis = DMatrix::from_fn(rows, dof, |r, c| u[(r, kept[c])]);
    let mut chosen = Vec::with_capacity(dof);
    for _ in 0..dof {
        let (best, norm) = (0..rows)
            .filter(|&r| selectable[r] && !chosen.contains(&r))
            .map(|r| (r, basis.row(r).norm()))
            .fold((usize::MAX, 0.0), |a, b| {
                if b.1 > a.1 * (1.0 + 1e-9) {
                    b
                } else {
                    a
                }
            });
        if best == usize::MAX || norm <= 1e-9 {
            return None;
        }
        chosen.push(best);
        let pivot = basis.row(best).transpose() / norm;
        for r in 0..rows {
            let d = basis.row(r).dot(&pivot.transpose());
            let mut row = basis.row_mut(r);
            row -= pivot.transpose() * d;
        }
    }
    chosen.sort_unstable();
    DMatrix::from_fn(dof, dof, |r, c| t[(chosen[r], c)]).try_inverse()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `T` (`dof × dof`) with half its singular values 1 and half `1/condition` (`κ₂` =
    /// `condition`, `κ_F = (dof/2) κ₂`): `U diag(σ) Vᵀ`, `U` and `V` orthogonal from QR of
    /// pseudo-random matrices.
    fn conditioned(dof: usize, condition: f64, seed: u64) -> DMatrix<f64> {
        let mut lcg = crate::lcg::Lcg::new(seed);
        let mut r = || lcg.signed();
        let u = DMatrix::from_fn(dof, dof, |_, _| r()).qr().q();
        let v = DMatrix::from_fn(dof, dof, |_, _| r()).qr().q();
        let s = DVector::from_fn(dof, |i, _| if 2 * i < dof { 1.0 } else { 1.0 / condition });
        u * DMatrix::from_diagonal(&s) * v.transpose()
    }

    /// The inverse without a singular value decomposition equals the general path's (every
    /// row chosen) to rounding where `T` is well conditioned; where `κ_F` is above `10⁹` but
    /// `κ₂` below, it declines and the general path accepts (the decision stays the general
    /// path's); where `κ₂` is above `10⁹`, both decline.
    #[test]
    fn the_inverse_without_svd_decides_as_the_singular_values() {
        let dof = 20;
        let all = vec![true; dof];
        for (seed, condition) in [(1, 1.0), (2, 1e3), (3, 1e6)] {
            let t = conditioned(dof, condition, seed);
            let fast = well_conditioned_inverse(&t).expect("well conditioned");
            let general = chosen_inverse(&t, &all).expect("full rank");
            let err = (&fast - &general).amax() / general.amax();
            assert!(
                err < 1e-12 * condition,
                "κ {condition}: inverses differ by {err:e}"
            );
        }
        // κ₂ = 5·10⁸ < 10⁹ < κ_F = 5·10⁹.
        let t = conditioned(dof, 5e8, 4);
        assert!(well_conditioned_inverse(&t).is_none());
        assert!(chosen_inverse(&t, &all).is_some());
        let t = conditioned(dof, 1e11, 5);
        assert!(well_conditioned_inverse(&t).is_none());
        assert!(chosen_inverse(&t, &all).is_none());
    }
}
