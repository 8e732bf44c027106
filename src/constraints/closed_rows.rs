//! `Φ` and `Φ_q` of the joint rows with closed-form derivatives ([`crate::jet::closed`]),
//! written straight into `Φ` and the triplets.
//!
//! A joint's rows read the vectors of its frames: the origin difference
//! `d = (r₁ + A(p₁) o₁) − (r₀ + A(p₀) o₀)` and the axes `u = A(p_k) R_k e_i`, each of the form
//! `u = Σ_k t_k r_k + A(p_k) s_k`, with
//!
//! `∂u/∂r_k = t_k I`,   `∂u/∂p_k = B(p_k, s_k)` ([`crate::math::b_matrix`]),
//!
//! so a component row `d_m` has the gradient `t_k e_m` over `r_k` and row `m` of `B(p_k, s_k)`
//! over `p_k`, and a dot product `aᵀb` has `t^a_k b + t^b_k a` over `r_k` and
//! `B^a_kᵀ b + B^b_kᵀ a` over `p_k`. Each vector a row reads is formed once per joint (a
//! revolute's `z₀` serves two rows), with `B` only for the sides it reads; each side's
//! entries of a row's [`crate::joint::Row::pattern`] go into the triplets as one fixed-size
//! run (a side's `r_m` and `p`, or its `p`, or all seven). The values and gradients are
//! [`crate::jet::closed::rows_each`]'s and the triplets `Constraints::evaluate`'s general
//! `push`'s, to the last bit and in the same order (the unit test `closed_rows_equal_push`);
//! [`values`] gives the values alone, the same numbers.

use super::Triplet;
use crate::jet::closed::JointRotations;
use crate::jet::{Pair, NL};
use crate::joint::{Row, V};
use crate::math::b_matrix;
use crate::model::{BodyId, Joint};
use nalgebra::{Matrix3x4, Vector3};

/// `u = Σ_k t_k r_k + A(p_k) s_k` with `B_k = B(p_k, s_k)` on the sides it reads (`on`).
#[derive(Clone, Copy)]
struct Lean {
    v: Vector3<f64>,
    t: [f64; 2],
    b: [Matrix3x4<f64>; 2],
    on: [bool; 2],
}

impl Lean {
    /// The world direction `A(p_k) R_k e_i` of axis `i` of side `k`'s frame.
    fn axis(pair: &Pair, rots: &JointRotations, k: usize, i: usize) -> Lean {
        let s = rots.r[k].column(i).into_owned();
        let mut b = [Matrix3x4::zeros(); 2];
        b[k] = b_matrix(&pair.p[k], &s);
        let mut on = [false; 2];
        on[k] = true;
        Lean {
            v: rots.a[k] * s,
            t: [0.0; 2],
            b,
            on,
        }
    }

    /// `d = o₁ − o₀` of the joint's frame origins.
    fn origins(joint: &Joint, pair: &Pair, rots: &JointRotations) -> Lean {
        let o = |k: usize| &joint.body_from_joint[k].translation.vector;
        Lean {
            v: origin_difference(joint, pair, rots),
            t: [-1.0, 1.0],
            b: [-b_matrix(&pair.p[0], o(0)), b_matrix(&pair.p[1], o(1))],
            on: [true; 2],
        }
    }
}

/// The two vectors row `r` reads (a component or length row reads `d` twice).
fn reads(r: &Row) -> [V; 2] {
    match *r {
        Row::Component(_) | Row::Length | Row::Thread => [V::D, V::D],
        Row::Dot(a, b) => [a, b],
    }
}

/// `d = (r₁ + A(p₁) o₁) − (r₀ + A(p₀) o₀)`, the difference of the joint's frame origins.
fn origin_difference(joint: &Joint, pair: &Pair, rots: &JointRotations) -> Vector3<f64> {
    let o = |k: usize| &joint.body_from_joint[k].translation.vector;
    let point = |k: usize| rots.a[k] * o(k) + pair.r[k];
    point(1) - point(0)
}

/// `∇(aᵀb)` into the zero `g`, in [`crate::jet::closed::dot_gradient`]'s order.
fn dot_gradient(a: &Lean, b: &Lean, g: &mut [f64; NL]) {
    for k in 0..2 {
        let o = 7 * k;
        for (x, y) in [(a, b), (b, a)] {
            if x.on[k] {
                if x.t[k] != 0.0 {
                    for i in 0..3 {
                        g[o + i] += x.t[k] * y.v[i];
                    }
                }
                let gp = x.b[k].tr_mul(&y.v);
                for i in 0..4 {
                    g[o + 3 + i] += gp[i];
                }
            }
        }
    }
}

/// The rows of `joint` (`layout`, its [`crate::joint::Spec::rows`]) from `row` on: values
/// added into `phi`, the entries of each row's pattern appended to `entries`.
pub(super) fn write(
    joint: &Joint,
    layout: &[Row],
    pair: &Pair,
    rots: &JointRotations,
    row: usize,
    phi: &mut [f64],
    entries: &mut Vec<Triplet>,
) {
    // Every vector the rows read, formed once, before any row reads it.
    let mut memo: [Option<Lean>; 7] = [None; 7];
    for r in layout {
        for v in reads(r) {
            memo[v as usize].get_or_insert_with(|| match v {
                V::D => Lean::origins(joint, pair, rots),
                _ => Lean::axis(pair, rots, (v as usize - 1) / 3, (v as usize - 1) % 3),
            });
        }
    }
    let vector = |v: V| -> &Lean {
        match &memo[v as usize] {
            Some(x) => x,
            None => unreachable!("every vector of the layout is formed above"),
        }
    };
    for (k, r) in layout.iter().enumerate() {
        let mut g = [0.0; NL];
        let value = match *r {
            Row::Component(m) => {
                let d = vector(V::D);
                for s in 0..2 {
                    g[7 * s + m] += d.t[s];
                    for i in 0..4 {
                        g[7 * s + 3 + i] += d.b[s][(m, i)];
                    }
                }
                d.v[m]
            }
            Row::Dot(a, b) => {
                let (a, b) = (vector(a), vector(b));
                dot_gradient(a, b, &mut g);
                a.v.dot(&b.v)
            }
            Row::Length => {
                let d = vector(V::D);
                dot_gradient(d, d, &mut g);
                let length = joint.kind.parameter();
                d.v.dot(&d.v) - length * length
            }
            Row::Thread => unreachable!("a thread row has no closed form (Spec::closed_form)"),
        };
        phi[row + k] += value;
        append(entries, (row + k) as u32, &joint.bodies, &g, r.pattern());
    }
}

/// The values alone of the rows of `joint` (`layout`) from `row` on, added into `phi`: each
/// vector formed once, by the same arithmetic as [`write`] (the same numbers).
pub(super) fn values(
    joint: &Joint,
    layout: &[Row],
    pair: &Pair,
    rots: &JointRotations,
    row: usize,
    phi: &mut [f64],
) {
    let mut memo: [Option<Vector3<f64>>; 7] = [None; 7];
    for r in layout {
        for v in reads(r) {
            memo[v as usize].get_or_insert_with(|| match v {
                V::D => origin_difference(joint, pair, rots),
                _ => {
                    let (k, i) = ((v as usize - 1) / 3, (v as usize - 1) % 3);
                    rots.a[k] * rots.r[k].column(i).into_owned()
                }
            });
        }
    }
    let vector = |v: V| -> &Vector3<f64> {
        match &memo[v as usize] {
            Some(x) => x,
            None => unreachable!("every vector of the layout is formed above"),
        }
    };
    for (k, r) in layout.iter().enumerate() {
        phi[row + k] += match *r {
            Row::Component(m) => vector(V::D)[m],
            Row::Dot(a, b) => vector(a).dot(vector(b)),
            Row::Length => {
                let length = joint.kind.parameter();
                vector(V::D).dot(vector(V::D)) - length * length
            }
            Row::Thread => unreachable!("a thread row has no closed form (Spec::closed_form)"),
        };
    }
}

/// The entries of `g` in `pattern`, side by side, each side's as one fixed-size run.
#[inline(always)]
fn append(
    entries: &mut Vec<Triplet>,
    row: u32,
    bodies: &[Option<BodyId>; 2],
    g: &[f64; NL],
    pattern: crate::joint::Pattern,
) {
    for (k, body) in bodies.iter().enumerate() {
        let Some(b) = body else {
            continue;
        };
        let (o, c) = (7 * k, 7 * b.0 as u32);
        let e = |i: usize| (row, c + i as u32, g[o + i]);
        const P: u16 = 0b111_1000;
        match (pattern >> o) & 0x7f {
            P => entries.extend_from_slice(&[e(3), e(4), e(5), e(6)]),
            0x7f => entries.extend_from_slice(&[e(0), e(1), e(2), e(3), e(4), e(5), e(6)]),
            bits if bits & P == P && (bits & 7).count_ones() == 1 => {
                let m = (bits & 7).trailing_zeros() as usize;
                entries.extend_from_slice(&[e(m), e(3), e(4), e(5), e(6)]);
            }
            bits => entries.extend((0..7).filter(|i| bits & (1 << i) != 0).map(e)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::jet::closed::{self, OwnedRotations};
    use crate::jet::testing::{every_kind, sample_joint, sample_pair, shifted};

    /// [`write`] and [`values`] give [`closed::rows_each`]'s values and, of each row, the
    /// entries of its pattern on the sides with a body in local order (what the general
    /// `push` appends), to the last bit: every closed-form kind, between two bodies and with
    /// either side the ground.
    #[test]
    fn closed_rows_equal_push() {
        let (a, b) = (Some(BodyId(0)), Some(BodyId(1)));
        let mut checked = 0;
        for kind in every_kind() {
            for bodies in [[a, b], [None, b], [b, None]] {
                let mut j = sample_joint(kind);
                j.bodies = bodies;
                if !closed::supports(&j) {
                    continue;
                }
                let layout = kind.spec().rows;
                for seed in 0..4 {
                    let what = format!("{} {bodies:?} seed {seed}", kind.name());
                    let pair = sample_pair(seed);
                    let (phi, entries) = evaluate(&j, &pair);
                    let (mut phi_ref, mut entries_ref) = (vec![0.5; 2 + layout.len()], Vec::new());
                    let owned = OwnedRotations::of(&j, &pair);
                    closed::rows_each(&j, &pair, &owned.view(), |k, v, g| {
                        phi_ref[2 + k] += v;
                        for i in 0..NL {
                            let global = crate::jet::global_index(&j.bodies, i);
                            if let Some(c) = global.filter(|_| layout[k].pattern() & (1 << i) != 0)
                            {
                                entries_ref.push(((2 + k) as u32, c as u32, 1.0 * g[i]));
                            }
                        }
                    });
                    let bits = |x: &[f64]| x.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
                    assert_eq!(bits(&phi), bits(&phi_ref), "{what}");
                    let mut alone = vec![0.5; 2 + layout.len()];
                    values(&j, layout, &pair, &owned.view(), 2, &mut alone);
                    assert_eq!(bits(&alone), bits(&phi_ref), "{what}");
                    let key = |e: &[Triplet]| {
                        e.iter()
                            .map(|&(r, c, v)| (r, c, v.to_bits()))
                            .collect::<Vec<_>>()
                    };
                    assert_eq!(key(&entries), key(&entries_ref), "{what}");
                    checked += 1;
                }
            }
        }
        assert!(checked >= 24, "{checked} cases");
    }

    /// `Φ` and its triplets of one joint at `pair` (rows from 2 on, `Φ` starting at 0.5).
    fn evaluate(j: &Joint, pair: &Pair) -> (Vec<f64>, Vec<Triplet>) {
        let layout = j.kind.spec().rows;
        let owned = OwnedRotations::of(j, pair);
        let (mut phi, mut entries) = (vec![0.5; 2 + layout.len()], Vec::new());
        write(j, layout, pair, &owned.view(), 2, &mut phi, &mut entries);
        (phi, entries)
    }

    /// Every triplet of [`write`] is the central difference of its row's value in its
    /// coordinate (bodies 0 and 1: the column is the local index), and every coordinate a
    /// row's value moves with has a triplet.
    #[test]
    fn closed_rows_match_central_differences() {
        for kind in every_kind() {
            let j = sample_joint(kind);
            if !closed::supports(&j) {
                continue;
            }
            for seed in 0..4 {
                let pair = sample_pair(seed);
                let (_, entries) = evaluate(&j, &pair);
                let h = 1e-6;
                for i in 0..NL {
                    let moved = |step: f64| evaluate(&j, &shifted(&pair, i, step)).0;
                    let (fp, fm) = (moved(h), moved(-h));
                    for row in 2..fp.len() {
                        let fd = (fp[row] - fm[row]) / (2.0 * h);
                        let at = |e: &&Triplet| e.0 as usize == row && e.1 as usize == i;
                        let got = entries.iter().find(at).map_or(0.0, |e| e.2);
                        let what = format!("{} seed {seed} row {row} coordinate {i}", kind.name());
                        assert!(
                            (fd - got).abs() < 1e-7 * (1.0 + got.abs()),
                            "{what}: {fd} {got}"
                        );
                    }
                }
            }
        }
    }
}
