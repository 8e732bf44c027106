//! The constraint equations `Φ(q) = 0`, their Jacobian `Φ_q` (assembled as sparse triplets)
//! and the weighted Hessian `Σ_k w_k ∇²Φ_k`.
//!
//! Rows come in blocks: the equations of each joint (module `joint`), one Euler-parameter
//! normalization `p_iᵀ p_i − 1 = 0` per body, locks `θ(q) − θ̄ = 0` and mimic couplings
//! `θ_a(q) − m θ_b(q) − c = 0`.

mod closed_rows;
pub(crate) mod joint;
mod pair_sum;
mod triplets;
pub(crate) mod unilateral;

use crate::jet::{closed, pair_of, HessianSink, Scalar};
use crate::joint::{Pattern, ALL};
use crate::kinematics::{coordinate, on_branch, revolute_first_order, Branches};
use crate::model::{BodyId, JointId, JointKind, Model};
use nalgebra::{DVector, Matrix3};
use pair_sum::PairSum;
pub(crate) use triplets::{Triplet, Triplets};

/// What a block of rows expresses.
#[derive(Clone, Debug)]
pub(crate) enum BlockKind {
    /// The equations of a joint.
    Joint(JointId),
    /// `pᵀp − 1` of a body.
    Normalization(BodyId),
    /// A held joint coordinate.
    Lock {
        joint: JointId,
        dof: usize,
        value: f64,
    },
    /// A mimic coupling (index into `Model::mimics`).
    Mimic(usize),
    /// An active inequality: a joint stop or a touching contact (1 or 3 rows).
    Unilateral(unilateral::Active),
}

/// A block of consecutive rows.
#[derive(Clone, Debug)]
pub(crate) struct Block {
    pub(crate) kind: BlockKind,
    pub(crate) first: usize,
}

/// One contribution to a row: `c f` for a local jet `f` of a body pair (its entries outside
/// the [`Pattern`] zero at every `q`, left out of `Φ_q`'s triplets), or a normalization row.
enum Term<'a> {
    Jet(&'a [Option<BodyId>; 2], &'a Scalar, f64, Pattern),
    Normalization(BodyId),
    /// The rows of a joint with closed-form derivatives ([`crate::jet::closed`]), from
    /// `row` on, with the rotations they are formed from.
    Closed(
        &'a crate::model::Joint,
        &'a crate::jet::Pair,
        &'a closed::JointRotations<'a>,
    ),
    /// A row's value alone (the rows of stops and contacts when only `Φ` is asked for).
    Value(f64),
}

/// The full set of constraint rows of a model, with locks resolved to values.
#[derive(Clone, Debug)]
pub(crate) struct Constraints {
    pub(crate) blocks: Vec<Block>,
    len: usize,
    /// Power of length in each row's unit (0, 1 or 2).
    length_power: Vec<i32>,
    /// The branch each joint angle is read on (lock, mimic and screw rows); the solver moves
    /// it along with the configuration.
    pub(crate) branches: Branches,
    /// Joint rows by their closed-form derivatives where one exists (else by the generic
    /// jets, the reference the closed forms are tested against).
    pub(crate) closed_form: bool,
    /// `R_k` of each joint's frames ([`closed::frame_rotations`]), by joint: formed once, not
    /// at every evaluation of the joint's rows.
    frame_rotations: Vec<[Matrix3<f64>; 2]>,
}

impl Constraints {
    /// Builds the rows of `model` plus the locks `(joint, dof, value)`.
    pub(crate) fn new(model: &Model, locks: &[(JointId, usize, f64)]) -> Self {
        // One block per joint, body and lock; about six rows per joint and one per body.
        let mut blocks = Vec::with_capacity(
            model.joints.len() + model.bodies.len() + locks.len() + model.mimics.len(),
        );
        let mut length_power =
            Vec::with_capacity(6 * model.joints.len() + model.bodies.len() + locks.len());
        let mut len = 0;
        let mut push = |kind: BlockKind, count: usize, blocks: &mut Vec<Block>| {
            blocks.push(Block { kind, first: len });
            len += count;
        };
        for (i, j) in model.joints.iter().enumerate() {
            let count = joint::row_count(j);
            if count > 0 {
                push(BlockKind::Joint(JointId(i)), count, &mut blocks);
                for r in joint::row_names(j) {
                    length_power.push(joint::length_power(r));
                }
            }
        }
        for i in 0..model.bodies.len() {
            push(BlockKind::Normalization(BodyId(i)), 1, &mut blocks);
            length_power.push(0);
        }
        for &(joint, dof, value) in locks {
            push(BlockKind::Lock { joint, dof, value }, 1, &mut blocks);
            let j = &model.joints[joint.0];
            length_power.push(if j.kind.is_angle(dof) { 0 } else { 1 });
        }
        for (i, m) in model.mimics.iter().enumerate() {
            push(BlockKind::Mimic(i), 1, &mut blocks);
            let j = &model.joints[m.joint.0];
            length_power.push(if j.kind.is_angle(0) { 0 } else { 1 });
        }
        Constraints {
            blocks,
            len,
            length_power,
            branches: Branches::default(),
            closed_form: true,
            frame_rotations: model.joints.iter().map(closed::frame_rotations).collect(),
        }
    }

    /// The same rows plus the active inequalities `active`, in their order.
    pub(crate) fn with_active(mut self, model: &Model, active: &[unilateral::Active]) -> Self {
        for a in active {
            self.blocks.push(Block {
                kind: BlockKind::Unilateral(*a),
                first: self.len,
            });
            let power = unilateral::length_power(model, &a.row);
            for _ in 0..a.row_count() {
                self.length_power.push(power);
            }
            self.len += a.row_count();
        }
        self
    }

    /// The same rows with joint angles read on `branches`.
    pub(crate) fn on_branches(mut self, branches: Branches) -> Self {
        self.branches = branches;
        self
    }

    /// Power of length in the unit of row `i`.
    pub(crate) fn length_power(&self, i: usize) -> i32 {
        self.length_power[i]
    }

    /// Number of rows `m`.
    pub(crate) fn len(&self) -> usize {
        self.len
    }

    /// Name of row `i` of `model`'s rows (`joint.row`, `body.normalization`,
    /// `joint.lock[dof]`, `joint.mimic`, `joint.lower_limit`, `link.contact[k]@ground.t1`),
    /// made when asked (an error names one row; a model has tens of thousands).
    pub(crate) fn row_name(&self, model: &Model, i: usize) -> String {
        // The blocks are in row order: row `i` is in the last block starting at or before it.
        let at = self.blocks.partition_point(|b| b.first <= i);
        let Some(block) = at.checked_sub(1).map(|k| &self.blocks[k]) else {
            return format!("row {i}");
        };
        let k = i - block.first;
        match &block.kind {
            BlockKind::Joint(id) => {
                let j = &model.joints[id.0];
                format!("{}.{}", j.name, joint::row_names(j).get(k).unwrap_or(&"?"))
            }
            BlockKind::Normalization(b) => format!("{}.normalization", model.bodies[b.0].name),
            BlockKind::Lock { joint, dof, .. } => {
                format!("{}.lock[{dof}]", model.joints[joint.0].name)
            }
            BlockKind::Mimic(m) => format!("{}.mimic", model.joints[model.mimics[*m].joint.0].name),
            BlockKind::Unilateral(a) => {
                let suffix = ["", ".t1", ".t2"].get(k).unwrap_or(&"");
                format!("{}{suffix}", unilateral::name(model, &a.row))
            }
        }
    }

    /// Whether row `i` is a body's normalization row.
    pub(crate) fn is_normalization(&self, i: usize) -> bool {
        let at = self.blocks.partition_point(|b| b.first <= i);
        at.checked_sub(1)
            .is_some_and(|k| matches!(self.blocks[k].kind, BlockKind::Normalization(_)))
    }

    /// Evaluates each block's rows and hands them to `visit(row, term)`; with `weights`, not
    /// a stop or contact whose rows all weigh 0 (`Σ w_i ∇²Φ_i` reads nothing of them).
    fn for_each_row(
        &self,
        model: &Model,
        q: &DVector<f64>,
        hess: bool,
        (values_only, weights): (bool, Option<&DVector<f64>>),
        mut visit: impl FnMut(usize, Term),
    ) {
        let mut buf = Vec::with_capacity(6);
        let mut values = [0.0; 3];
        // `A(p)` of every body once (the closed-form rows of a chain read each body's twice),
        // the identity for the ground, as `pair_of` gives it.
        let a = if self.closed_form {
            crate::jet::body_rotations(q)
        } else {
            Vec::new()
        };
        let ground = crate::jet::ground_rotation();
        let side = |b: Option<BodyId>| b.map_or(&ground, |b| &a[b.0]);
        for block in &self.blocks {
            match &block.kind {
                BlockKind::Joint(id) => {
                    let j = &model.joints[id.0];
                    let pair = pair_of(&j.bodies, q, hess);
                    if self.closed_form && crate::jet::closed::supports(j) {
                        let rots = closed::JointRotations {
                            a: [side(j.bodies[0]), side(j.bodies[1])],
                            r: &self.frame_rotations[id.0],
                        };
                        visit(block.first, Term::Closed(j, &pair, &rots));
                        continue;
                    }
                    joint::rows(j, &pair, self.branches.get(*id, 0), &mut buf);
                    let layout = j.kind.spec().rows;
                    for (k, (s, row)) in buf.iter().zip(layout).enumerate() {
                        visit(block.first + k, Term::Jet(&j.bodies, s, 1.0, row.pattern()));
                    }
                }
                BlockKind::Normalization(b) => visit(block.first, Term::Normalization(*b)),
                BlockKind::Lock {
                    joint: id,
                    dof,
                    value,
                } => {
                    let j = &model.joints[id.0];
                    let pair = pair_of(&j.bodies, q, hess);
                    let branch = self.branches.get(*id, *dof);
                    // A revolute angle without its Hessian in closed form (module
                    // `kinematics::revolute_angle`), any other coordinate by the jets.
                    let closed_angle = !hess
                        && self.closed_form
                        && *dof == 0
                        && matches!(j.kind, JointKind::Revolute | JointKind::Continuous);
                    let angle = closed_angle.then(|| {
                        let rots = [side(j.bodies[0]), side(j.bodies[1])];
                        let f = revolute_first_order(&pair, rots, &self.frame_rotations[id.0]);
                        let s = Scalar {
                            v: f.v,
                            g: f.g,
                            h: None,
                        };
                        on_branch(s, branch)
                    });
                    if let Some(s) = angle.or_else(|| coordinate(j, &pair, *dof, branch)) {
                        visit(
                            block.first,
                            Term::Jet(&j.bodies, &s.minus(*value), 1.0, ALL),
                        );
                    }
                }
                BlockKind::Unilateral(a) => {
                    let unweighted = |w: &DVector<f64>| {
                        let rows = w.rows(block.first, a.row_count());
                        rows.iter().all(|&x| x == 0.0)
                    };
                    if weights.is_some_and(unweighted) {
                        continue;
                    }
                    let bodies = unilateral::bodies(model, &a.row);
                    let pair = pair_of(&bodies, q, hess);
                    if values_only {
                        let k = unilateral::values(model, a, &pair, &self.branches, &mut values);
                        for (k, &v) in values.iter().take(k.unwrap_or(0)).enumerate() {
                            visit(block.first + k, Term::Value(v));
                        }
                    } else if unilateral::rows_into(model, a, &pair, &self.branches, &mut buf)
                        .is_some()
                    {
                        for (k, s) in buf.iter().enumerate() {
                            visit(block.first + k, Term::Jet(&bodies, s, 1.0, ALL));
                        }
                    }
                }
                BlockKind::Mimic(i) => {
                    let m = &model.mimics[*i];
                    let ja = &model.joints[m.joint.0];
                    let jb = &model.joints[m.reference.0];
                    let pa = pair_of(&ja.bodies, q, hess);
                    let pb = pair_of(&jb.bodies, q, hess);
                    if let (Some(a), Some(b)) = (
                        coordinate(ja, &pa, 0, self.branches.get(m.joint, 0)),
                        coordinate(jb, &pb, 0, self.branches.get(m.reference, 0)),
                    ) {
                        let a = a.minus(m.offset);
                        visit(block.first, Term::Jet(&ja.bodies, &a, 1.0, ALL));
                        visit(block.first, Term::Jet(&jb.bodies, &b, -m.multiplier, ALL));
                    }
                }
            }
        }
    }

    /// An upper bound on the number of triplets of `Φ_q`: the entries of each joint row's
    /// pattern, 14 for every other row (a mimic row's two jets: 28).
    fn triplet_bound(&self, model: &Model) -> usize {
        let mut bound = 0;
        for (k, block) in self.blocks.iter().enumerate() {
            let end = self.blocks.get(k + 1).map_or(self.len, |b| b.first);
            bound += match &block.kind {
                BlockKind::Joint(id) => {
                    let rows = model.joints[id.0].kind.spec().rows;
                    rows.iter().map(|r| r.pattern().count_ones() as usize).sum()
                }
                BlockKind::Mimic(_) => 28,
                _ => 14 * (end - block.first),
            };
        }
        bound
    }

    /// `Φ(q)` into `phi`, and `Φ_q` into `jac` when given.
    pub(crate) fn evaluate(
        &self,
        model: &Model,
        q: &DVector<f64>,
        phi: &mut DVector<f64>,
        mut jac: Option<&mut Triplets>,
    ) {
        phi.fill(0.0);
        if let Some(t) = jac.as_deref_mut() {
            t.rows = self.len;
            t.cols = q.len();
            t.entries.clear();
            // Reserve once, exactly, rather than by doubling (a quarter of the triplets' memory
            // on large models).
            if t.entries.capacity() == 0 {
                t.entries.reserve_exact(self.triplet_bound(model));
            }
        }
        fn push(
            phi: &mut DVector<f64>,
            jac: Option<&mut Triplets>,
            row: usize,
            bodies: &[Option<BodyId>; 2],
            (v, g): (f64, &crate::jet::LVec),
            c: f64,
            pattern: Pattern,
        ) {
            phi[row] += c * v;
            if let Some(t) = jac {
                // The entries of the row's pattern, zeros too: the sparsity pattern must not
                // depend on `q`. Those outside it are zero at every `q` (`Row::pattern`).
                if let [Some(a), Some(b)] = bodies {
                    // One exact-size run (the same triplets, in the same order, as below).
                    let (a, b) = (7 * a.0, 7 * b.0);
                    if pattern == ALL {
                        t.entries.extend((0..crate::jet::NL).map(|i| {
                            let gi = if i < 7 { a + i } else { b + i - 7 };
                            (row as u32, gi as u32, c * g[i])
                        }));
                    } else {
                        let kept = (0..crate::jet::NL).filter(|i| pattern & (1 << i) != 0);
                        t.entries.extend(kept.map(|i| {
                            let gi = if i < 7 { a + i } else { b + i - 7 };
                            (row as u32, gi as u32, c * g[i])
                        }));
                    }
                    return;
                }
                let mut bits = pattern;
                while bits != 0 {
                    let i = bits.trailing_zeros() as usize;
                    bits &= bits - 1;
                    if let Some(gi) = crate::jet::global_index(bodies, i) {
                        t.entries.push((row as u32, gi as u32, c * g[i]));
                    }
                }
            }
        }
        let values_only = (jac.is_none(), None);
        self.for_each_row(model, q, false, values_only, |row, term| match term {
            Term::Jet(bodies, s, c, pattern) => {
                push(
                    phi,
                    jac.as_deref_mut(),
                    row,
                    bodies,
                    (s.v, &s.g),
                    c,
                    pattern,
                );
            }
            // `push`'s `phi[row] += 1.0 · v`.
            Term::Value(v) => phi[row] += 1.0 * v,
            Term::Closed(j, pair, rots) => {
                let (layout, phi) = (j.kind.spec().rows, phi.as_mut_slice());
                match jac.as_deref_mut() {
                    Some(t) => closed_rows::write(j, layout, pair, rots, row, phi, &mut t.entries),
                    None => closed_rows::values(j, layout, pair, rots, row, phi),
                }
            }
            Term::Normalization(b) => {
                let i = 7 * b.0 + 3;
                let p = q.rows(i, 4);
                phi[row] = p.dot(&p) - 1.0;
                if let Some(t) = jac.as_deref_mut() {
                    for k in 0..4 {
                        t.entries.push((row as u32, (i + k) as u32, 2.0 * q[i + k]));
                    }
                }
            }
        });
    }

    /// Adds `Σ_k w_k ∇²Φ_k(q)` to `h`; the rows of a joint are summed into one local
    /// Hessian before they reach the sink.
    pub(crate) fn add_hessian(
        &self,
        model: &Model,
        q: &DVector<f64>,
        w: &DVector<f64>,
        h: &mut dyn HessianSink,
    ) {
        let mut sum = PairSum::new();
        self.for_each_row(model, q, true, (false, Some(w)), |row, term| match term {
            Term::Jet(bodies, s, c, _) => {
                if w[row] != 0.0 {
                    sum.of(bodies, h);
                    if let Some(sh) = s.h.as_deref() {
                        *sum.full() += sh * (c * w[row]);
                    }
                }
            }
            Term::Closed(j, pair, rots) => {
                let ws = &w.as_slice()[row..row + joint::row_count(j)];
                if ws.iter().any(|&x| x != 0.0) {
                    match sum.of(&j.bodies, h) {
                        Some(hp) if closed::euler::euler_only(j) => {
                            closed::euler::add_weighted_hessian_euler(j, pair, rots, ws, hp);
                        }
                        _ => closed::add_weighted_hessian(j, pair, rots, ws, sum.full()),
                    }
                }
            }
            Term::Normalization(b) => {
                let i = 7 * b.0 + 3;
                for k in 0..4 {
                    h.add_entry(i + k, i + k, 2.0 * w[row]);
                }
            }
            Term::Value(_) => {}
        });
        sum.flush(h);
    }
}

#[cfg(test)]
mod tests;
