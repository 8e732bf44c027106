//! The tree KKT matrix's values as assembled, kept compactly beside its factors, which
//! overwrite the flat blocks in place (module `kkt`).
//!
//! Of a node's diagonal block `K_i = [W Jᵀ; J 0]` (coordinates and rows, in the node's order)
//! only the coordinates' rows are kept, whole (`W` and `Jᵀ`): a row's entries are the
//! transposes of those (`K_ab = K_ba`, stored by the assembly from the same sums) or zero (two
//! rows); its coupling `C_i` is kept whole. From them, with the same operations in the same
//! order as on the full blocks (a term `0 · x` left out changes no finite sum):
//!
//! ```text
//! r_a −= Σ_b K_ab x_b  (one sum over b = 0, 1, …, subtracted),   s_a += Σ_b |K_ab|
//! ```
//!
//! the residual of iterative refinement and the row sums of `‖K‖∞`; and the flat blocks are
//! written back where the factors must be recomputed without a new assembly (another shift,
//! the LU fallback). A new assembly writes every slot but those of no Hessian block and no
//! Jacobian entry, which hold fill after a factorization: [`Original::clear_unwritten`] zeroes
//! them.

use super::dense;
use super::fused::Run;
use super::shape::{Shape, FIRST, SKIP};

/// A node's coordinates: the leading `c` of its unknowns (a body's coordinates, then its rows),
/// or listed.
#[derive(Clone, Copy)]
enum Coords {
    Leading(usize),
    Listed { from: usize, count: usize },
}

/// The kept values and where they lie.
pub(super) struct Original {
    /// Per node: its kept rows of `K_i` (`c × d`), then `C_i` (`d × w`).
    at: Vec<usize>,
    coords: Vec<Coords>,
    /// The listed nodes' coordinate positions (local, increasing).
    listed: Vec<u32>,
    /// Per tree-space position: the kept row of a coordinate, [`NONE`] for a row.
    rank: Vec<u32>,
    /// Runs `(start, len)` of flat slots that no assembly writes.
    unwritten: Vec<(u32, u32)>,
    /// Per coordinate: its node and its diagonal entry in `values` ([`NONE`]: in the border).
    diag: Vec<(u32, u32)>,
    pub(super) values: Vec<f64>,
}

const NONE: u32 = u32::MAX;

impl Original {
    /// The layout for `s` (values zero until saved).
    pub(super) fn new(s: &Shape) -> Self {
        let nodes = s.at.len();
        let mut rank = vec![NONE; s.tree_len];
        let (mut at, mut coords, mut listed) = (Vec::with_capacity(nodes), Vec::new(), Vec::new());
        let mut len = 0;
        let mut diag = vec![(NONE, NONE); s.n];
        for i in 0..nodes {
            let (t0, d) = (s.at[i], s.d[i]);
            let is_coord = |k: usize| s.perm[t0 + k] < s.n;
            let c = (0..d).filter(|&k| is_coord(k)).count();
            let kind = if (0..c).all(is_coord) {
                Coords::Leading(c)
            } else {
                let from = listed.len();
                listed.extend((0..d).filter(|&k| is_coord(k)).map(|k| k as u32));
                Coords::Listed { from, count: c }
            };
            let mut k = 0;
            for a in 0..d {
                if is_coord(a) {
                    rank[t0 + a] = k;
                    diag[s.perm[t0 + a]] = (i as u32, (len + k as usize * d + a) as u32);
                    k += 1;
                }
            }
            at.push(len);
            coords.push(kind);
            len += c * d + d * s.w[i];
        }
        Original {
            at,
            coords,
            listed,
            rank,
            unwritten: unwritten(s),
            diag,
            values: vec![0.0; len],
        }
    }

    fn count(&self, i: usize) -> usize {
        match self.coords[i] {
            Coords::Leading(c) => c,
            Coords::Listed { count, .. } => count,
        }
    }

    /// Node `i`'s kept rows of `K_i` and its coupling.
    fn parts(&self, s: &Shape, i: usize) -> (&[f64], &[f64]) {
        let (d, w, at) = (s.d[i], s.w[i], self.at[i]);
        let kept = self.count(i) * d;
        (
            &self.values[at..at + kept],
            &self.values[at + kept..at + kept + d * w],
        )
    }

    /// Node `i`'s coupling `C_i` as assembled.
    pub(super) fn coupling(&self, s: &Shape, i: usize) -> &[f64] {
        self.parts(s, i).1
    }

    /// Keeps node `i`'s values from the flat blocks `flat` (not yet factored).
    pub(super) fn save(&mut self, s: &Shape, i: usize, flat: &[f64]) {
        let (d, w, at) = (s.d[i], s.w[i], self.at[i]);
        let blk = &flat[s.diag_at[i]..s.diag_at[i] + d * d];
        let kept = self.count(i) * d;
        let (rows, c) = self.values[at..at + kept + d * w].split_at_mut(kept);
        match self.coords[i] {
            Coords::Leading(_) => rows.copy_from_slice(&blk[..kept]),
            Coords::Listed { from, count } => {
                for (k, &a) in self.listed[from..from + count].iter().enumerate() {
                    let a = a as usize;
                    rows[k * d..k * d + d].copy_from_slice(&blk[a * d..a * d + d]);
                }
            }
        }
        c.copy_from_slice(&flat[s.coup_at[i]..s.coup_at[i] + d * w]);
    }

    /// Writes node `i`'s kept values back into the flat blocks `flat`.
    pub(super) fn restore(&self, s: &Shape, i: usize, flat: &mut [f64]) {
        let (d, w, t0) = (s.d[i], s.w[i], s.at[i]);
        let (rows, c) = self.parts(s, i);
        let blk = &mut flat[s.diag_at[i]..s.diag_at[i] + d * d];
        for a in 0..d {
            let ra = self.rank[t0 + a];
            for b in 0..d {
                blk[a * d + b] = if ra != NONE {
                    rows[ra as usize * d + b]
                } else {
                    let rb = self.rank[t0 + b];
                    if rb != NONE {
                        rows[rb as usize * d + a]
                    } else {
                        0.0
                    }
                };
            }
        }
        flat[s.coup_at[i]..s.coup_at[i] + d * w].copy_from_slice(c);
    }

    /// The diagonal of `W` as assembled, by coordinate: saved for the nodes `saved` flags,
    /// else in `values` (the matrix's).
    pub(super) fn diagonal(&self, s: &Shape, values: &[f64], saved: impl Fn(usize) -> bool) -> Vec<f64> {
        let slots = s.diag_slots.iter().zip(&self.diag);
        slots
            .map(|(&slot, &(i, at))| {
                if i != NONE && saved(i as usize) {
                    self.values[at as usize]
                } else {
                    values[slot as usize]
                }
            })
            .collect()
    }

    /// Zeroes the flat slots that no assembly writes (fill of the last factors).
    pub(super) fn clear_unwritten(&self, flat: &mut [f64]) {
        for &(start, len) in &self.unwritten {
            flat[start as usize..(start + len) as usize].fill(0.0);
        }
    }

    /// Adds node `i`'s row sums of `|K_i|` and `|C_i|` (see `norm::add_node`: one partial sum
    /// per row of `K_i`, added, then `C_i`'s entries one by one) to `own` and `up`.
    pub(super) fn add_row_sums(&self, s: &Shape, i: usize, own: &mut [f64], up: &mut [f64]) {
        let (d, w, t0) = (s.d[i], s.w[i], s.at[i]);
        let (rows, c) = self.parts(s, i);
        match (self.coords[i], d, w) {
            (Coords::Leading(7), 13, 7) => return sums::<13, 7, 7>(rows, c, own, up),
            (Coords::Leading(7), 13, 0) => return sums::<13, 7, 0>(rows, c, own, up),
            (Coords::Leading(7), 14, 18) => return sums::<14, 7, 18>(rows, c, own, up),
            (Coords::Leading(14), 27, 7) => return sums::<27, 14, 7>(rows, c, own, up),
            _ => {}
        }
        let (own, up) = (&mut own[..d], &mut up[..w]);
        for a in 0..d {
            let mut sum = 0.0;
            let ra = self.rank[t0 + a];
            if ra != NONE {
                for &v in &rows[ra as usize * d..ra as usize * d + d] {
                    sum += v.abs();
                }
            } else {
                self.each_coord(i, |k, _| sum += rows[k * d + a].abs());
            }
            let mut sa = own[a] + sum;
            for (sb, &x) in up.iter_mut().zip(&c[a * w..a * w + w]) {
                let v = x.abs();
                sa += v;
                *sb += v;
            }
            own[a] = sa;
        }
    }

    /// Calls `f(k, b)` for the node's coordinates `b` (local, increasing), `k` their kept row.
    #[inline(always)]
    fn each_coord(&self, i: usize, mut f: impl FnMut(usize, usize)) {
        match self.coords[i] {
            Coords::Leading(c) => (0..c).for_each(|k| f(k, k)),
            Coords::Listed { from, count } => self.listed[from..from + count]
                .iter()
                .enumerate()
                .for_each(|(k, &b)| f(k, b as usize)),
        }
    }

    /// `r −= K x` over the tree part (tree-space order), as the full blocks' products
    /// (`dense::sub_mul` of `K_i` and of `C_i`, `dense::sub_tr_mul` of `C_i`).
    pub(super) fn sub_product(&self, s: &Shape, x: &[f64], r: &mut [f64]) {
        for i in 0..s.at.len() {
            let (at, d, w) = (s.at[i], s.d[i], s.w[i]);
            let (rows, c) = self.parts(s, i);
            match (self.coords[i], d) {
                (Coords::Leading(7), 13) => diag::<13, 7>(rows, &x[at..], &mut r[at..]),
                (Coords::Leading(7), 14) => diag::<14, 7>(rows, &x[at..], &mut r[at..]),
                (Coords::Leading(14), 27) => diag::<27, 14>(rows, &x[at..], &mut r[at..]),
                _ => self.diag_any(i, (at, d), rows, &x[at..at + d], &mut r[at..at + d]),
            }
            if s.parent[i] != u32::MAX {
                let pa = s.at[s.parent[i] as usize];
                dense::sub_mul(c, &x[pa..pa + w], &mut r[at..at + d], d, w);
                dense::sub_tr_mul(c, &x[at..at + d], &mut r[pa..pa + w], d, w);
            }
        }
    }

    /// `r −= K_i x` for any node (the reference of [`diag`]).
    fn diag_any(&self, i: usize, (t0, d): (usize, usize), rows: &[f64], x: &[f64], r: &mut [f64]) {
        for a in 0..d {
            let mut sum = 0.0;
            let ra = self.rank[t0 + a];
            if ra != NONE {
                let row = &rows[ra as usize * d..ra as usize * d + d];
                for b in 0..d {
                    sum += row[b] * x[b];
                }
            } else {
                self.each_coord(i, |k, b| sum += rows[k * d + a] * x[b]);
            }
            r[a] -= sum;
        }
    }
}

/// `r −= K_i x` for a node of `D` unknowns whose leading `C` are coordinates: `rows` (`C × D`)
/// its kept rows.
#[inline(never)]
fn diag<const D: usize, const C: usize>(rows: &[f64], x: &[f64], r: &mut [f64]) {
    let (rows, x, r) = (&rows[..C * D], &x[..D], &mut r[..D]);
    for a in 0..C {
        let row = &rows[a * D..a * D + D];
        let mut sum = 0.0;
        for b in 0..D {
            sum += row[b] * x[b];
        }
        r[a] -= sum;
    }
    let mut sums = [0.0; D];
    for b in 0..C {
        let (row, xb) = (&rows[b * D..b * D + D], x[b]);
        for a in C..D {
            sums[a] += row[a] * xb;
        }
    }
    for a in C..D {
        r[a] -= sums[a];
    }
}

/// [`Original::add_row_sums`] for a node of `D` unknowns whose leading `C` are coordinates,
/// coupled to `W` of its parent's.
#[inline(never)]
fn sums<const D: usize, const C: usize, const W: usize>(
    rows: &[f64],
    c: &[f64],
    own: &mut [f64],
    up: &mut [f64],
) {
    let (rows, c, own) = (&rows[..C * D], &c[..D * W], &mut own[..D]);
    let mut s = [0.0; D];
    for a in 0..C {
        let mut sum = 0.0;
        for &v in &rows[a * D..a * D + D] {
            sum += v.abs();
        }
        s[a] = sum;
    }
    for b in 0..C {
        let row = &rows[b * D..b * D + D];
        for a in C..D {
            s[a] += row[a].abs();
        }
    }
    let mut acc = [0.0; W];
    acc.copy_from_slice(&up[..W]);
    for a in 0..D {
        let mut sa = own[a] + s[a];
        let crow = &c[a * W..a * W + W];
        for b in 0..W {
            let v = crow[b].abs();
            sa += v;
            acc[b] += v;
        }
        own[a] = sa;
    }
    up[..W].copy_from_slice(&acc);
}

/// Runs `(start, len)` of the flat slots below `s.flat_len` that neither a Hessian block's run
/// nor a Jacobian entry nor the bare diagonal reaches.
fn unwritten(s: &Shape) -> Vec<(u32, u32)> {
    let mut hit = vec![false; s.flat_len];
    let mut mark = |slot: usize| {
        if slot < hit.len() {
            hit[slot] = true;
        }
    };
    for &run in &s.block_runs {
        match run {
            Run::Skip => {}
            Run::Dense { start, stride } => {
                (0..7).for_each(|i| (0..7).for_each(|j| mark(start + i * stride + j)));
            }
            Run::Scattered { at } => s.scattered_slots[at as usize]
                .iter()
                .filter(|&&slot| slot != SKIP)
                .for_each(|&slot| mark(slot as usize)),
        }
    }
    for slots in &s.jac_slots {
        for &slot in slots.iter().filter(|&&slot| slot != SKIP) {
            mark((slot & !FIRST) as usize);
        }
    }
    s.bare_diag.iter().for_each(|&slot| mark(slot as usize));
    let mut runs = Vec::new();
    let mut k = 0;
    while k < hit.len() {
        if hit[k] {
            k += 1;
            continue;
        }
        let start = k;
        while k < hit.len() && !hit[k] {
            k += 1;
        }
        runs.push((start as u32, (k - start) as u32));
    }
    runs
}
