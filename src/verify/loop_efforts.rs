//! The self-check's efforts on a tree closed by loops, in joint coordinates.
//!
//! Where every tree joint has one coordinate `θ_k` (revolute, continuous or prismatic; a fixed
//! joint is rigid), every body hangs from a tree joint (no floating base) and the loops' rows
//! `Φ_L` are the loop joints' equations (no mimics, no locks of the model, nothing touching),
//! the locked system of module `held` (the model's rows and a lock on every `θ_k`) is the
//! locked tree, square as in module `tree_partition`, plus the loop rows. The tree's lock
//! multiplier of a generalized force `g` is `t_kᵀ g`, with `t_k = ∂q/∂θ_k` the motion of joint
//! `k` (the bodies below it turning about its axis or sliding along it: the tree's other rows
//! stay satisfied, the other locks too), so the efforts are
//!
//! `τ = ∂V/∂θ − J_θᵀ μ`,   `J_θ = ∂Φ_L/∂θ` (the loops' closure Jacobian in joint coordinates),
//!
//! `μ` the loop rows' multipliers. A body's gradient acts as a wrench `(F, M)` about the world
//! origin, and `t_kᵀ g = ω_k · (M − c_k × F)` for a revolute joint of world axis `ω_k` through
//! `c_k`, `ω_k · F` for a prismatic one (module `kinematics::joint_rate`). `∂V/∂θ` sums the
//! wrenches of `∇V` leaves to root, one pass;
//! `J_θ` pairs each loop row's gradient on its two bodies with the joints between each body
//! and their common ancestor (a joint above it moves both rigidly: its column is exactly zero).
//!
//! `μ` as module `held` chooses it: loops sharing a joint form one component, a small dense
//! `J_c` (rows scaled by `L^−k`, prismatic columns by `L`), partitioned by full pivoting with
//! the general partition's rank tolerance (module `full_pivoting`): the pivot rows are the loop rows kept (model rows
//! first), the pivot columns the locks dropped. With at most `MAX_DEPENDENT` loop rows (the
//! locked system's dependent rows) the efforts are the least ones, `τ_c = (I − Q Qᵀ) τ₀_c` with
//! `Q` an orthonormal basis of the kept rows' patterns; above, the basic ones: the dropped
//! locks carry nothing (`J_{R,D}ᵀ μ = τ₀_D`, `τ_D = 0`). Every coordinate is dependent, so
//! nothing is unassigned. The check stays independent: `∇V` and the rows' gradients are its
//! own evaluation at the pose read back (module `model_rows`). Where a precondition fails
//! ([`Loops::of`], checked before any work) the general partition decides.

use crate::constraints::{joint as joint_rows, Triplet};
use crate::kinematics::{wrench, JointAxis};
use crate::model::{JointId, JointKind, Model};
use nalgebra::{DMatrix, DVector, Vector3};

/// Largest `rows × joints` of a component's dense `J_c`.
const MAX_COMPONENT: usize = 200_000;

/// Largest number of joints on all loops' paths together.
const MAX_PATHS: usize = 1_000_000;

/// A loop joint: its rows and the coordinate joints between each body and their common
/// ancestor.
#[derive(Debug)]
struct Loop {
    bodies: [Option<usize>; 2],
    /// First row among the model's rows, and their length powers.
    first: usize,
    powers: Vec<i32>,
    /// The joints (index) with a coordinate on each side's path.
    path: [Vec<usize>; 2],
}

/// Loops sharing joints: their rows and joints, for one dense `J_c`.
#[derive(Debug)]
struct Component {
    loops: Vec<usize>,
    joints: Vec<usize>,
}

/// The structure of a tree closed by loops (module docs).
#[derive(Debug)]
pub(super) struct Loops {
    /// Per body: the tree joint whose child it is.
    up: Vec<usize>,
    /// Bodies, children before their parents.
    order: Vec<usize>,
    loops: Vec<Loop>,
    components: Vec<Component>,
    /// Number of loop rows (the locked system's dependent rows).
    rows: usize,
}

/// Whether a tree joint of this kind is one with a coordinate this module handles.
fn coordinate_kind(kind: JointKind) -> bool {
    matches!(
        kind,
        JointKind::Revolute | JointKind::Continuous | JointKind::Prismatic
    )
}

impl Loops {
    /// The structure of `model`, or `None` where the module's preconditions fail: a joint
    /// of another kind in the tree, a body without a tree joint (a floating base), no loop,
    /// mimics, `model_locks` locks of the model, or a component too large for a dense `J_c`.
    pub(super) fn of(model: &Model, model_locks: usize) -> Option<Loops> {
        if model_locks != 0
            || !model.mimics.is_empty()
            || !model.joints.iter().any(|j| !j.tree && !j.merged)
        {
            return None;
        }
        let nb = model.bodies.len();
        let mut up = vec![usize::MAX; nb];
        let mut loops = Vec::new();
        let mut first = 0;
        for (i, j) in model.joints.iter().enumerate() {
            // The rows' order of `Constraints::new`: one block per joint with rows.
            let count = joint_rows::row_count(j);
            if j.tree && !j.merged {
                if !(coordinate_kind(j.kind) || j.kind == JointKind::Fixed) {
                    return None;
                }
                let child = j.bodies[1]?.index();
                if up[child] != usize::MAX {
                    return None;
                }
                up[child] = i;
            } else if !j.tree && !j.merged && count > 0 {
                loops.push(Loop {
                    bodies: j.bodies.map(|b| b.map(|b| b.index())),
                    first,
                    powers: joint_rows::row_names(j)
                        .iter()
                        .map(|r| joint_rows::length_power(r))
                        .collect(),
                    path: [Vec::new(), Vec::new()],
                });
            }
            first += count;
        }
        if loops.is_empty() || up.contains(&usize::MAX) {
            return None;
        }
        let parent = |b: usize| model.joints[up[b]].bodies[0].map(|p| p.index());
        // Depths (the world 0), then the bodies deepest first.
        let mut depth = vec![0usize; nb];
        let mut stack = Vec::new();
        for b in 0..nb {
            let mut s = Some(b);
            while let Some(c) = s {
                if depth[c] != 0 {
                    break;
                }
                stack.push(c);
                s = parent(c);
            }
            let mut d = s.map_or(0, |c| depth[c]);
            while let Some(c) = stack.pop() {
                d += 1;
                depth[c] = d;
            }
        }
        // A counting sort by depth, deepest first.
        let deepest = depth.iter().copied().max().unwrap_or(0);
        let mut start = vec![0usize; deepest + 2];
        for &d in &depth {
            start[deepest - d + 1] += 1;
        }
        for k in 1..start.len() {
            start[k] += start[k - 1];
        }
        let mut order = vec![0usize; nb];
        for (b, &d) in depth.iter().enumerate() {
            let at = &mut start[deepest - d];
            order[*at] = b;
            *at += 1;
        }
        // Each loop's paths up to the common ancestor.
        let mut walked = 0;
        for l in &mut loops {
            let [mut a, mut b] = l.bodies;
            let at = |s: Option<usize>| s.map_or(0, |c| depth[c]);
            while a != b {
                let side = usize::from(at(b) > at(a));
                let s = if side == 0 { &mut a } else { &mut b };
                let body = (*s)?;
                let k = up[body];
                if coordinate_kind(model.joints[k].kind) {
                    l.path[side].push(k);
                    walked += 1;
                    if walked > MAX_PATHS {
                        return None;
                    }
                }
                *s = parent(body);
            }
        }
        // Components: loops joined by the joints they share (union-find on joints).
        let nj = model.joints.len();
        let mut root: Vec<usize> = (0..nj).collect();
        fn find(root: &mut [usize], mut k: usize) -> usize {
            while root[k] != k {
                root[k] = root[root[k]];
                k = root[k];
            }
            k
        }
        for l in &loops {
            let mut joints = l.path[0].iter().chain(&l.path[1]);
            if let Some(&k0) = joints.next() {
                for &k in joints {
                    let (r0, r) = (find(&mut root, k0), find(&mut root, k));
                    root[r] = r0;
                }
            }
        }
        let mut slot = vec![usize::MAX; nj];
        let mut components: Vec<Component> = Vec::new();
        let mut seen = vec![false; nj];
        for (i, l) in loops.iter().enumerate() {
            let Some(&k0) = l.path[0].iter().chain(&l.path[1]).next() else {
                continue;
            };
            let r = find(&mut root, k0);
            if slot[r] == usize::MAX {
                slot[r] = components.len();
                components.push(Component {
                    loops: Vec::new(),
                    joints: Vec::new(),
                });
            }
            let c = &mut components[slot[r]];
            c.loops.push(i);
            for &k in l.path[0].iter().chain(&l.path[1]) {
                if !seen[k] {
                    seen[k] = true;
                    c.joints.push(k);
                }
            }
        }
        for c in &components {
            let rows: usize = c.loops.iter().map(|&i| loops[i].powers.len()).sum();
            if rows * c.joints.len() > MAX_COMPONENT {
                return None;
            }
        }
        let rows = loops.iter().map(|l| l.powers.len()).sum();
        Some(Loops {
            up,
            order,
            loops,
            components,
            rows,
        })
    }

    /// The efforts of the locks `all` (`(joint, dof, value)`, every coordinate joint's once)
    /// at `q`, from `∇V` (`grad`) and the triplets `entries` of the model's rows there
    /// (module docs); `least` for the least efforts, else the basic ones. `None` where `all`
    /// is not one lock per coordinate joint.
    pub(super) fn efforts(
        &self,
        model: &Model,
        q: &DVector<f64>,
        all: &[(JointId, usize, f64)],
        entries: &[Triplet],
        grad: &DVector<f64>,
        least: bool,
    ) -> Option<Vec<f64>> {
        let nj = model.joints.len();
        let mut lock_of = vec![usize::MAX; nj];
        for (n, &(joint, dof, _)) in all.iter().enumerate() {
            let k = joint.index();
            let j = &model.joints[k];
            if dof != 0 || !j.tree || j.merged || !coordinate_kind(j.kind) {
                return None;
            }
            if lock_of[k] != usize::MAX {
                return None;
            }
            lock_of[k] = n;
        }
        if self
            .up
            .iter()
            .any(|&k| coordinate_kind(model.joints[k].kind) && lock_of[k] == usize::MAX)
        {
            return None;
        }
        let axes = axes(model, q, &self.up);
        let mut tau = self.rates(model, q, grad, &axes);
        let jacobians = self.closure_jacobians(model, q, entries, &axes);
        // Per component: its pivots, the efforts.
        let length = model.length_scale;
        for (comp, jac) in self.components.iter().zip(&jacobians) {
            let nc = comp.joints.len();
            let row_scale: Vec<f64> = comp
                .loops
                .iter()
                .flat_map(|&i| self.loops[i].powers.iter().map(|&p| length.powi(-p)))
                .collect();
            let col_scale: Vec<f64> = comp
                .joints
                .iter()
                .map(|&k| {
                    if model.joints[k].kind == JointKind::Prismatic {
                        length
                    } else {
                        1.0
                    }
                })
                .collect();
            let (kept, dropped) = super::full_pivoting::pivots(jac, &row_scale, &col_scale);
            let tau0 = DVector::from_iterator(nc, comp.joints.iter().map(|&k| tau[k]));
            let held = if kept.is_empty() {
                tau0
            } else if least {
                // τ_c = (I − Q Qᵀ) τ₀_c, Q spanning the kept rows' patterns.
                let b = DMatrix::from_fn(nc, kept.len(), |k, r| jac[(kept[r], k)]);
                let qr = b.qr().q();
                let proj = &qr * (qr.transpose() * &tau0);
                tau0 - proj
            } else {
                // J_{R,D}ᵀ μ = τ₀_D, τ = τ₀ − J_{R,:}ᵀ μ (zero on D).
                let n = kept.len();
                let a = DMatrix::from_fn(n, n, |d, r| jac[(kept[r], dropped[d])]);
                let rhs = DVector::from_iterator(n, dropped.iter().map(|&d| tau0[d]));
                let mu = a.lu().solve(&rhs)?;
                let mut t = tau0;
                for (r, &row) in kept.iter().enumerate() {
                    for k in 0..nc {
                        t[k] -= mu[r] * jac[(row, k)];
                    }
                }
                for &d in &dropped {
                    t[d] = 0.0;
                }
                t
            };
            for (n, &k) in comp.joints.iter().enumerate() {
                tau[k] = held[n];
            }
        }
        Some(
            all.iter()
                .map(|&(joint, _, _)| tau[joint.index()])
                .collect(),
        )
    }

    /// `∂V/∂θ_k` by joint index (zero off the coordinate joints) at `q` from `∇V` (`grad`):
    /// the wrenches of the bodies' gradients summed leaves to root (module docs); `axes` the
    /// joints' at `q` ([`axes`]).
    fn rates(
        &self,
        model: &Model,
        q: &DVector<f64>,
        grad: &DVector<f64>,
        axes: &[Option<JointAxis>],
    ) -> Vec<f64> {
        let mut tau = vec![0.0; model.joints.len()];
        let mut sum = vec![(Vector3::zeros(), Vector3::zeros()); model.bodies.len()];
        for &b in &self.order {
            let (f, m) = wrench(q, b, &grad.as_slice()[7 * b..7 * b + 7]);
            let (f, m) = (sum[b].0 + f, sum[b].1 + m);
            let k = self.up[b];
            if let Some(a) = &axes[k] {
                tau[k] = a.rate(&f, &m);
            }
            if let Some(parent) = model.joints[k].bodies[0] {
                let s = &mut sum[parent.index()];
                s.0 += f;
                s.1 += m;
            }
        }
        tau
    }

    /// Per component, `J_c = ∂Φ_L/∂θ` at `q`: its loops' rows in order, its joints' columns,
    /// from the rows' triplets `entries` (module docs); `axes` the joints' at `q` ([`axes`]).
    fn closure_jacobians(
        &self,
        model: &Model,
        q: &DVector<f64>,
        entries: &[Triplet],
        axes: &[Option<JointAxis>],
    ) -> Vec<DMatrix<f64>> {
        // The loop rows' gradients on their two bodies (14 a row), from the triplets.
        let end = self.loops.iter().map(|l| l.first + l.powers.len());
        let rows = entries.iter().map(|e| e.0 as usize + 1).chain(end).max();
        let mut at_row = vec![u32::MAX; rows.unwrap_or(0)];
        let mut offset = Vec::with_capacity(self.loops.len());
        let mut row_loop = Vec::with_capacity(self.rows);
        for (i, l) in self.loops.iter().enumerate() {
            offset.push(row_loop.len());
            for r in 0..l.powers.len() {
                at_row[l.first + r] = row_loop.len() as u32;
                row_loop.push(i);
            }
        }
        let mut grads = vec![0.0; 14 * row_loop.len()];
        for &(r, c, v) in entries {
            let at = at_row[r as usize];
            if at == u32::MAX {
                continue;
            }
            let (at, c) = (at as usize, c as usize);
            let side = usize::from(self.loops[row_loop[at]].bodies[0] != Some(c / 7));
            grads[14 * at + 7 * side + c % 7] += v;
        }
        let mut column = vec![usize::MAX; model.joints.len()];
        let mut jacobians = Vec::with_capacity(self.components.len());
        for comp in &self.components {
            for (n, &k) in comp.joints.iter().enumerate() {
                column[k] = n;
            }
            let nr: usize = comp.loops.iter().map(|&i| self.loops[i].powers.len()).sum();
            let mut jac = DMatrix::zeros(nr, comp.joints.len());
            let mut r0 = 0;
            for &i in &comp.loops {
                let l = &self.loops[i];
                for r in 0..l.powers.len() {
                    let g = &grads[14 * (offset[i] + r)..14 * (offset[i] + r + 1)];
                    for side in 0..2 {
                        let Some(b) = l.bodies[side] else { continue };
                        let (f, m) = wrench(q, b, &g[7 * side..7 * side + 7]);
                        for &k in &l.path[side] {
                            if let Some(a) = &axes[k] {
                                jac[(r0 + r, column[k])] += a.rate(&f, &m);
                            }
                        }
                    }
                }
                r0 += l.powers.len();
            }
            jacobians.push(jac);
        }
        jacobians
    }

    /// The number of loop rows: the locked system's dependent rows.
    pub(super) fn dependent(&self) -> usize {
        self.rows
    }
}

/// The multipliers of `analyze`'s self-check with the locks `all` (the first `model_locks`
/// the model's own) where the module applies: the efforts from the model's rows and `∇V`
/// evaluated at the pose (`given`), the least ones up to `MAX_DEPENDENT` loop rows (else the
/// basic ones), nothing touching, nothing unassigned (every coordinate is dependent).
pub(super) fn multipliers(
    model: &Model,
    state: &crate::state::State,
    all: &[(JointId, usize, f64)],
    model_locks: usize,
    given: Option<&super::held::ModelRows>,
) -> Option<super::held::Multipliers> {
    let loops = Loops::of(model, model_locks)?;
    let (entries, grad) = given?.at(&state.q)?;
    let least = loops.dependent() <= super::held::MAX_DEPENDENT;
    Some(super::held::Multipliers {
        locks: loops.efforts(model, &state.q, all, entries, grad, least)?,
        forces: Vec::new(),
        unassigned: 0.0,
        resolved: least,
        chosen: None,
    })
}

/// The axes of the tree's coordinate joints at `q` (`up`: the joint of each body), by joint
/// index.
fn axes(model: &Model, q: &DVector<f64>, up: &[usize]) -> Vec<Option<JointAxis>> {
    let mut axes = vec![None; model.joints.len()];
    for &k in up {
        axes[k] = JointAxis::at(&model.joints[k], q);
    }
    axes
}

#[cfg(test)]
#[path = "loop_efforts_tests.rs"]
mod tests;
