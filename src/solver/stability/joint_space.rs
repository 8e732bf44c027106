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
    // joints): all are chosen (the rows of an orthogonal `U` stay of norm 1 through the
    // Gram–Schmidt steps), and only the rank is needed from the decomposition.
    let all = rows.len() == dof && selectable.iter().all(|&s| s);
    let svd = super::eigen::svd(t.clone(), !all, false)?;
    let top = svd.singular_values.max();
    let rank = svd
        .singular_values
        .iter()
        .filter(|&&s| s > 1e-9 * top)
        .count();
    if rank < dof || top <= 0.0 {
        return None;
    }
    let chosen: Vec<usize> = if all {
        (0..dof).collect()
    } else {
        // An orthonormal basis of T's range, then the rows with the most independent motion.
        let u = svd.u.as_ref()?;
        let cols: Vec<usize> = (0..svd.singular_values.len())
            .filter(|&k| svd.singular_values[k] > 1e-9 * top)
            .collect();
        let mut basis = DMatrix::from_fn(rows.len(), dof, |r, c| u[(r, cols[c])]);
        let mut chosen = Vec::with_capacity(dof);
        for _ in 0..dof {
            let (best, norm) = (0..rows.len())
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
            for r in 0..rows.len() {
                let d = basis.row(r).dot(&pivot.transpose());
                let mut row = basis.row_mut(r);
                row -= pivot.transpose() * d;
            }
        }
        chosen.sort_unstable();
        chosen
    };
    let t_i = DMatrix::from_fn(dof, dof, |r, c| t[(chosen[r], c)]);
    let m = t_i.try_inverse()?;
    let h_theta = m.transpose() * h * &m;
    let h_theta = (&h_theta + h_theta.transpose()) * 0.5;
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
