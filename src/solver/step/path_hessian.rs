//! The second derivative of the energy along the search path, for the dense Newton step.
//!
//! The reduced Hessian `Ĥ` is the second derivative of `f(v̂)` in the scaled independent
//! coordinates, Cartesian coordinates of bodies. The line search does not move on straight
//! lines in them: it turns every tree joint from `θ` to `θ + α θ̇` (module `retraction`), along
//! which `v̂(α) = v̂ + α d + ½ α² c(d) + O(α³)`. The energy along the path is therefore
//!
//! `f(α) = f + α ∇fᵀd + ½ α² dᵀ(Ĥ + C) d + O(α³)`,   `dᵀC d = ∇fᵀ c(d)`,
//!
//! and its Newton step is `(Ĥ + C) d = −∇f` (for a tree, `Ĥ + C` is the Hessian in the joint
//! coordinates, expressed in `δv̂`). `C` is proportional to the gradient, so quadratic
//! convergence is the same with or without it; what it removes is the gradient's share in
//! `Ĥ`'s eigenvalues along near-neutral directions: iCub's hanging legs have two whose
//! physical curvature is about 10⁻⁹ of the largest, and `Ĥ` put them anywhere between
//! 2·10⁻⁸ and 6·10⁻⁶ J (half the gradient norm), so the Newton step along them alternated
//! between 0.17 (cut to a few per cent by the line search, the path's curvature `c(d)`
//! raising the stiff directions' energy) and 10⁻³, and the gradient oscillated between 10⁻⁸
//! and 10⁻⁵ J for 97 iterations.
//!
//! `c(d)` is exact: the path composes, from the root down, each tree edge's screw motion
//! `E_l(α): y ↦ y + α ξ_l(y) + ½ α² ω_l × ξ_l(y) + O(α³)` (`ω_l` the edge's relative angular
//! velocity, `ξ_l(y) = ω_l × (y − x_l) + w_l` its velocity field, linear in `d`), so a body's
//! origin `y` and Euler parameters `p` have the second derivatives
//!
//! `y'' = Σ_l a_l × ξ_l(y)`,   `p'' = ¼ Σ_l (a_l ⊗ ω_l) ⊗ p`,   `a_l = ω_l + 2 Σ_{k<l} ω_k`
//!
//! over the edges `l` from the root to the body (`k < l`: nearer the root; `a ⊗ ω` the
//! product of pure quaternions). Only the bodies carrying independent coordinates are needed.

use crate::math::compose;
use crate::solver::partition::Partition;
use crate::solver::stability::blocks::block_symmetric_eigen;
use crate::solver::stability::spectrum::Spectrum;
use crate::solver::step::retraction::angular_velocity;
use crate::solver::step::tr_product::add_tr_product;
use crate::solver::system::{symmetric_part, Eval, System};
use nalgebra::{DMatrix, DVector, Matrix3, MatrixView3xX, Vector3, Vector4};

/// The per-edge sums `(G_l, M_l, s_l, R_l)` of [`path_curvature`].
type EdgeSums = (Vector3<f64>, Matrix3<f64>, f64, Vector4<f64>);

/// `C` of the module docs at `q` (`dof × dof`, symmetric), with the null-space basis `Z` at
/// `q` if it is at hand (else it is solved for).
///
/// The sum over the bodies `b` carrying independent coordinates and the edges `l` above them
/// is gathered per edge: with `r_b = y_b − x_l`, the gradient weights `w_b` on `b`'s origin
/// and `ρ_b` on its Euler parameters, summed over the bodies below `l` (`G_l = Σ w_b`,
/// `M_l = Σ w_b r_bᵀ`, `s_l = Σ w_b · r_b`, `R_l = Σ ρ_b`),
///
/// `C_ij = Σ_l a_iᵀ K_l (ω_j, w_j)`,   `K_l = [M_lᵀ − (s_l + ¼ R_l0) I − ¼ [R_lv]×,  −[G_l]×]`
///
/// (`w·(a × (ω × r)) = (w·ω)(a·r) − (w·r)(a·ω)`), `O(bodies · dof²)` instead of a `dof × dof`
/// sum per body and edge.
pub(crate) fn path_curvature(
    sys: &System,
    q: &DVector<f64>,
    part: &Partition,
    eval: &Eval,
    basis: Option<&DMatrix<f64>>,
) -> DMatrix<f64> {
    curvature_of(sys, q, part, eval, basis, true)
}

/// [`path_curvature`], with `skip_still`: the twists of the edges that a column of `Z` does
/// not move (the body's and its parent's blocks of the column zero, `q` finite) left at zero
/// instead of computed. Computed, they are `±0` (`ω = 2 (e₀ δe − δe₀ e + e × δe) / |p|²` of
/// a zero `δp`, differences and cross products of zeros), and a zero's sign changes only the
/// sign of a zero result in the sums and products that follow; the entries of `m` below are
/// never `−0` (sums from `+0`), so `C` is the same to the last bit either way.
fn curvature_of(
    sys: &System,
    q: &DVector<f64>,
    part: &Partition,
    eval: &Eval,
    basis: Option<&DMatrix<f64>>,
    skip_still: bool,
) -> DMatrix<f64> {
    let dof = part.independent.len();
    let columns = &sys.problem.scaling.columns;
    let parents = sys.problem.retraction.parents();
    let bodies = parents.len();
    // Each edge's relative twist (ω_l, w_l at the child's origin) per unit step along e_i:
    // column `l dof + i` of `omega` and `vel` (edge `l`'s block of `dof` columns, `edge`).
    let mut omega = nalgebra::Matrix3xX::<f64>::zeros(dof * bodies);
    let mut vel = nalgebra::Matrix3xX::<f64>::zeros(dof * bodies);
    let solved;
    let z = match basis {
        Some(z) => z,
        None => {
            solved = sys.null_basis(part, eval);
            &solved
        }
    };
    // Each body's angular velocity once per column (its own edge's and its children's twists
    // read it), in one buffer for the column. Where neither the body nor its parent moves
    // along the column (`Z`'s blocks zero) the twist is zero and is left so (`skip_still`).
    let skip_still = skip_still && q.iter().all(|v| v.is_finite());
    let mut dq = DVector::zeros(z.nrows());
    let mut spin = vec![Vector3::zeros(); bodies];
    let mut moves = vec![true; bodies];
    for i in 0..dof {
        dq.copy_from(&z.column(i));
        for (b, w) in spin.iter_mut().enumerate() {
            moves[b] = !skip_still || dq.as_slice()[7 * b..7 * b + 7].iter().any(|&v| v != 0.0);
            *w = if moves[b] {
                angular_velocity(q, &dq, b)
            } else {
                Vector3::zeros()
            };
        }
        for b in 0..bodies {
            if !moves[b] && parents[b].is_none_or(|a| !moves[a]) {
                continue;
            }
            let (w, v) = twist_of(q, &dq, &spin, b, parents[b]);
            omega.set_column(dof * b + i, &w);
            vel.set_column(dof * b + i, &v);
        }
    }
    // The gradient's weight on each coordinate of the bodies with independent coordinates.
    // Per body, in the order of the bodies (as the sums below are taken).
    let mut weights: Vec<Option<[f64; 7]>> = vec![None; bodies];
    for (k, &c) in part.independent.iter().enumerate() {
        weights[c / 7].get_or_insert([0.0; 7])[c % 7] += eval.grad_v[k] / columns[c];
    }
    // Per edge l: (G_l, M_l, s_l, R_l) over the weighted bodies below it (module docs).
    let mut sums: Vec<Option<EdgeSums>> = vec![None; bodies];
    for (b, w) in weights.iter().enumerate() {
        let Some(w) = w else { continue };
        let y = position(q, b);
        let p = Vector4::new(q[7 * b + 3], q[7 * b + 4], q[7 * b + 5], q[7 * b + 6]);
        // wᵀ(P ⊗ p) = P · ρ.
        let rho = Vector4::from_fn(|k, _| {
            let mut e = Vector4::zeros();
            e[k] = 1.0;
            let ep = compose(&e, &p);
            (0..4).map(|r| w[3 + r] * ep[r]).sum::<f64>()
        });
        let wy = Vector3::new(w[0], w[1], w[2]);
        let mut l = Some(b);
        while let Some(at) = l {
            let r = y - position(q, at);
            let e =
                sums[at].get_or_insert((Vector3::zeros(), Matrix3::zeros(), 0.0, Vector4::zeros()));
            e.0 += wy;
            e.1 += wy * r.transpose();
            e.2 += wy.dot(&r);
            e.3 += rho;
            l = parents[at];
        }
    }
    // a_i = ω_i + 2 Σ_{k above l} ω_k, the sum taken from the root down. The buffers are
    // the call's, reused from edge to edge: `above` (edge `k`'s block: `Σ ω` over `k` and
    // the edges above it, once `summed[k]`), `a`, `kt` and the second product `kv`.
    let mut above = nalgebra::Matrix3xX::<f64>::zeros(dof * bodies);
    let mut summed = vec![false; bodies];
    let mut chain = Vec::new();
    let mut a = nalgebra::Matrix3xX::<f64>::zeros(dof);
    let mut kt = nalgebra::Matrix3xX::<f64>::zeros(dof);
    let mut kv = nalgebra::Matrix3xX::<f64>::zeros(dof);
    let mut m = DMatrix::zeros(dof, dof);
    for (l, sum) in sums.iter().enumerate() {
        let Some((g, mm, s, r)) = sum else { continue };
        let before = sum_above(l, &parents, &omega, &mut above, &mut summed, &mut chain);
        let span = 3 * dof * l..3 * dof * (l + 1);
        let (a_s, omega_l) = (a.as_mut_slice(), &omega.as_slice()[span]);
        match before {
            Some(k) => {
                let before = &above.as_slice()[3 * dof * k..3 * dof * (k + 1)];
                for ((a, &w), &b) in a_s.iter_mut().zip(omega_l).zip(before) {
                    *a = w + 2.0 * b;
                }
            }
            // Nothing above: `ω + 2 · 0`, which turns a `−0` of `ω` into `+0` like any zero sum.
            None => a_s
                .iter_mut()
                .zip(omega_l)
                .for_each(|(a, &w)| *a = w + 2.0 * 0.0),
        }
        let rv = Vector3::new(r[1], r[2], r[3]);
        let k_omega =
            mm.transpose() - Matrix3::identity() * (s + 0.25 * r[0]) - 0.25 * rv.cross_matrix();
        let k_vel = -g.cross_matrix();
        // `K_ω ω_l + K_v w_l`: nalgebra's products (`gemm` with β = 0 is `*`), then the sum.
        kt.gemm(1.0, &k_omega, &edge(&omega, l, dof), 0.0);
        kv.gemm(1.0, &k_vel, &edge(&vel, l, dof), 0.0);
        kt += &kv;
        add_tr_product(&mut m, &a, &kt);
    }
    symmetric_part(m)
}

/// Edge `l`'s block of `dof` columns in `per_edge` (`3 × dof · bodies`).
fn edge(per_edge: &nalgebra::Matrix3xX<f64>, l: usize, dof: usize) -> MatrixView3xX<'_, f64> {
    per_edge.columns(dof * l, dof)
}

/// The edge whose block of `memo` holds `Σ ω_k` over the edges `k` above `l` (nearer the
/// root; `None` where there are none, the sum zero): `l`'s parent edge. The running sums are
/// taken from the root down, `memo`'s block of `k` set to its parent's plus `ω_k` (to zero
/// plus `ω_k` at the root) and `summed[k]` raised; `chain` is scratch.
fn sum_above(
    l: usize,
    parents: &[Option<usize>],
    omega: &nalgebra::Matrix3xX<f64>,
    memo: &mut nalgebra::Matrix3xX<f64>,
    summed: &mut [bool],
    chain: &mut Vec<usize>,
) -> Option<usize> {
    let a = parents[l]?;
    if summed[a] {
        return Some(a);
    }
    let dof = omega.ncols() / parents.len();
    // The chain above `l`, root first, then the running sums down to `a`.
    chain.clear();
    chain.push(a);
    while let Some(p) = parents[*chain.last().unwrap_or(&a)] {
        if summed[p] {
            break;
        }
        chain.push(p);
    }
    let top = *chain.last().unwrap_or(&a);
    let mut from = parents[top].filter(|&p| summed[p]);
    for &k in chain.iter().rev() {
        let (o, m) = (omega.as_slice(), memo.as_mut_slice());
        let span = 3 * dof * k..3 * dof * (k + 1);
        match from {
            Some(p) => {
                let start = 3 * dof * p;
                for (i, c) in span.enumerate() {
                    m[c] = m[start + i] + o[c];
                }
            }
            None => span.for_each(|c| m[c] = 0.0 + o[c]),
        }
        summed[k] = true;
        from = Some(k);
    }
    Some(a)
}

/// The relative twist of body `b`'s tree edge for the tangent `dq` (module `retraction`):
/// `ω_b − ω_a` and the velocity `ẋ_b − ẋ_a − ω_a × (x_b − x_a)` at the child's origin.
#[cfg(test)]
fn relative_twist(
    q: &DVector<f64>,
    dq: &DVector<f64>,
    b: usize,
    parent: Option<usize>,
) -> (Vector3<f64>, Vector3<f64>) {
    let spin: Vec<Vector3<f64>> = (0..q.len() / 7)
        .map(|k| angular_velocity(q, dq, k))
        .collect();
    twist_of(q, dq, &spin, b, parent)
}

/// [`relative_twist`] with the bodies' angular velocities `spin` for `dq` at hand.
fn twist_of(
    q: &DVector<f64>,
    dq: &DVector<f64>,
    spin: &[Vector3<f64>],
    b: usize,
    parent: Option<usize>,
) -> (Vector3<f64>, Vector3<f64>) {
    let wb = spin[b];
    match parent {
        Some(a) => {
            let wa = spin[a];
            let va = position(dq, a) + wa.cross(&(position(q, b) - position(q, a)));
            (wb - wa, position(dq, b) - va)
        }
        None => (wb, position(dq, b)),
    }
}

/// The origin of body `b` in `q` (or its velocity in a tangent).
fn position(q: &DVector<f64>, b: usize) -> Vector3<f64> {
    q.fixed_rows::<3>(7 * b).into_owned()
}

/// Whether the search path keeps every row of `sys` by itself: only tree joints of one motion
/// subgroup, stops, locks, mimics and normalizations (module `retraction`). Where the
/// corrector closes other rows after each trial point (a touching contact, a loop, a
/// universal, distance or point-on-line joint), the energy along the path is no longer
/// `f(v̂(α))` with this `c(d)`, and `Ĥ` alone is used: with `C`, A1 standing on its joint
/// springs (frictionless ground, `scripts/peers_check.py`) ended `max_iterations` with 84 step
/// halvings instead of converging in 17 iterations.
pub(crate) fn path_keeps_rows(sys: &System) -> bool {
    use crate::constraints::unilateral::Unilateral;
    use crate::constraints::BlockKind;
    use crate::joint::JointKind;
    let model = sys.problem.model;
    sys.problem.cons.blocks.iter().all(|b| match &b.kind {
        BlockKind::Joint(j) => {
            let joint = &model.joints[j.0];
            joint.tree
                && !matches!(
                    joint.kind,
                    JointKind::Universal | JointKind::Distance { .. } | JointKind::PointOnLine
                )
        }
        BlockKind::Unilateral(a) => matches!(a.row, Unilateral::Limit { .. }),
        _ => true,
    })
}

/// The spectrum of `Ĥ + C` from the exact spectrum `e` of `Ĥ` at `q`: the Hessian the dense
/// Newton step uses (module docs).
pub(crate) fn along_path(
    sys: &System,
    q: &DVector<f64>,
    part: &Partition,
    eval: &Eval,
    e: &Spectrum,
) -> Spectrum {
    spectrum_of(&path_matrix(sys, q, part, eval, e))
}

/// `Ĥ + C` at `q`, `Ĥ` as `V Λ Vᵀ` from its exact spectrum `e`, symmetrized: the matrix
/// [`along_path`] decomposes.
pub(crate) fn path_matrix(
    sys: &System,
    q: &DVector<f64>,
    part: &Partition,
    eval: &Eval,
    e: &Spectrum,
) -> DMatrix<f64> {
    let mut h = &e.vectors * DMatrix::from_diagonal(&e.values) * e.vectors.transpose();
    h += path_curvature(sys, q, part, eval, e.basis.as_ref());
    symmetric_part(h)
}

/// The exact spectrum of the symmetric `Ĥ + C`.
pub(crate) fn spectrum_of(h: &DMatrix<f64>) -> Spectrum {
    // Per decoupled block (fingers, legs): each eigenvector on one of them.
    let (values, vectors) = block_symmetric_eigen(h);
    Spectrum {
        largest: values.amax(),
        values,
        vectors,
        exact: true,
        negative_by_inertia: None,
        basis: None,
    }
}

#[cfg(test)]
#[path = "path_hessian_tests.rs"]
mod tests;
