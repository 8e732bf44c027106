//! The off-diagonal entries of `T` (module `phi_u`) as dense **segments**: node `i`'s entries
//! `(p, q, v)` are held in the triplets' order; a run of consecutive entries on one row `p` is
//! a row, and consecutive rows with the same distinct columns `q₁ … q_c` form an `r × c`
//! segment whose values are already row-major in that order (a joint's rows on its parent's
//! dependent coordinates: on a chain, a revolute joint's two axis rows on the Euler
//! parameters as one segment and each of its three point rows as one row, since the entries
//! zero at every `q` are left out of the triplets, `joint::Row::pattern`). The solves' updates
//!
//! ```text
//! Φ_u x = r:   x_p −= Σ_q v_pq x_q    (row by row, q in the entries' order)
//! Φ_uᵀ μ = g:  μ_q −= Σ_p v_pq μ_p    (column by column, p in the entries' order)
//! ```
//!
//! are then taken with the read side gathered once per segment and each updated entry held in
//! a register across its sum. Every `x_p` (`μ_q`) sees the same subtractions `x − v·y` in the
//! same order as the entry-by-entry loop (the read side lies in other nodes, untouched by the
//! node's own updates), so the results are the same to the last bit.

/// The segments of every node.
#[derive(Default)]
pub(crate) struct Segments {
    /// Node `i`'s segments are `seg[at[i] .. at[i + 1]]`.
    at: Vec<u32>,
    seg: Vec<Seg>,
    /// Each segment's row positions, then its column positions.
    idx: Vec<u32>,
}

/// An `rows × cols` block of the off-diagonal values, row-major from `v`.
#[derive(Clone, Copy)]
struct Seg {
    rows: u32,
    cols: u32,
    idx: u32,
    v: u32,
    /// Whether the columns are distinct (always so for more than one row).
    distinct: bool,
}

/// Segments of more columns than this are updated entry by entry.
const GATHER: usize = 32;

impl Segments {
    /// The segments of the entries `off` (grouped by node: node `i`'s are
    /// `off[off_at[i] .. off_at[i + 1]]`, in the triplets' order).
    pub(crate) fn new(off: &[(u32, u32)], off_at: &[usize]) -> Self {
        // Sized for the most a segment list can hold (a row's one row and its columns per
        // entry; untouched capacity costs no page): no regrowth copies.
        let mut s = Segments {
            at: Vec::with_capacity(off_at.len()),
            seg: Vec::with_capacity(off.len()),
            idx: Vec::with_capacity(2 * off.len()),
        };
        s.at.push(0);
        for w in off_at.windows(2) {
            let mut k = w[0];
            while k < w[1] {
                // The row starting at `k`.
                let p = off[k].0;
                let end = (k..w[1]).find(|&j| off[j].0 != p).unwrap_or(w[1]);
                let cols = &off[k..end];
                let c = cols.len();
                let distinct = distinct(cols);
                let at = s.idx.len();
                s.idx.push(p);
                // Further rows with the same distinct columns join the segment.
                let mut next = end;
                while distinct && next + c <= w[1] {
                    let row = &off[next..next + c];
                    let same_row = row.iter().all(|e| e.0 == row[0].0);
                    let ends = next + c == w[1] || off[next + c].0 != row[0].0;
                    if !(same_row && ends && row.iter().zip(cols).all(|(e, f)| e.1 == f.1)) {
                        break;
                    }
                    s.idx.push(row[0].0);
                    next += c;
                }
                s.seg.push(Seg {
                    rows: (s.idx.len() - at) as u32,
                    cols: c as u32,
                    idx: at as u32,
                    v: k as u32,
                    distinct,
                });
                s.idx.extend(cols.iter().map(|e| e.1));
                k = next;
            }
            s.at.push(s.seg.len() as u32);
        }
        s
    }

    /// The rows, the columns and the values of a segment.
    fn parts<'a>(&'a self, s: &Seg, off: &'a [f64]) -> (&'a [u32], &'a [u32], &'a [f64]) {
        let (r, c) = (s.rows as usize, s.cols as usize);
        let (rows, cols) = self.idx[s.idx as usize..s.idx as usize + r + c].split_at(r);
        (rows, cols, &off[s.v as usize..s.v as usize + r * c])
    }

    /// `x_p −= Σ_q v_pq x_q` over node `i`'s entries (`off`: the off-diagonal values).
    pub(crate) fn forward(&self, i: usize, off: &[f64], x: &mut [f64]) {
        for s in &self.seg[self.at[i] as usize..self.at[i + 1] as usize] {
            let (rows, cols, v) = self.parts(s, off);
            match cols.len() {
                3 => forward_fixed::<3>(rows, cols, v, x),
                4 => forward_fixed::<4>(rows, cols, v, x),
                5 => forward_fixed::<5>(rows, cols, v, x),
                6 => forward_fixed::<6>(rows, cols, v, x),
                7 => forward_fixed::<7>(rows, cols, v, x),
                c if c <= GATHER => {
                    let mut y = [0.0; GATHER];
                    for (y, &q) in y.iter_mut().zip(cols) {
                        *y = x[q as usize];
                    }
                    for (&p, vr) in rows.iter().zip(v.chunks_exact(c)) {
                        let mut acc = x[p as usize];
                        for (&w, &y) in vr.iter().zip(&y[..c]) {
                            acc -= w * y;
                        }
                        x[p as usize] = acc;
                    }
                }
                c => {
                    for (&p, vr) in rows.iter().zip(v.chunks_exact(c)) {
                        for (&w, &q) in vr.iter().zip(cols) {
                            x[p as usize] -= w * x[q as usize];
                        }
                    }
                }
            }
        }
    }

    /// `x_q −= Σ_p v_pq x_p` over node `i`'s entries (`off`: the off-diagonal values).
    pub(crate) fn transposed(&self, i: usize, off: &[f64], x: &mut [f64]) {
        for s in &self.seg[self.at[i] as usize..self.at[i + 1] as usize] {
            let (rows, cols, v) = self.parts(s, off);
            match cols.len() {
                3 if s.distinct => transposed_fixed::<3>(rows, cols, v, x),
                4 if s.distinct => transposed_fixed::<4>(rows, cols, v, x),
                5 if s.distinct => transposed_fixed::<5>(rows, cols, v, x),
                6 if s.distinct => transposed_fixed::<6>(rows, cols, v, x),
                7 if s.distinct => transposed_fixed::<7>(rows, cols, v, x),
                c if s.distinct && c <= GATHER => {
                    let mut acc = [0.0; GATHER];
                    for (a, &q) in acc.iter_mut().zip(cols) {
                        *a = x[q as usize];
                    }
                    for (&p, vr) in rows.iter().zip(v.chunks_exact(c)) {
                        let y = x[p as usize];
                        for (a, &w) in acc[..c].iter_mut().zip(vr) {
                            *a -= w * y;
                        }
                    }
                    for (&a, &q) in acc.iter().zip(cols) {
                        x[q as usize] = a;
                    }
                }
                // In the entries' order (a repeated column, or many).
                c => {
                    for (&p, vr) in rows.iter().zip(v.chunks_exact(c)) {
                        let y = x[p as usize];
                        for (&w, &q) in vr.iter().zip(cols) {
                            x[q as usize] -= w * y;
                        }
                    }
                }
            }
        }
    }
}

/// Whether the entries' columns are distinct: by a bit per column above the least where
/// they span fewer than 64 positions (a row's entries on one body), else pair by pair.
fn distinct(cols: &[(u32, u32)]) -> bool {
    let lo = cols.iter().fold(u32::MAX, |a, e| a.min(e.1));
    let mut seen = 0u64;
    for e in cols {
        let d = e.1 - lo;
        if d >= 64 {
            return (1..cols.len()).all(|a| cols[..a].iter().all(|e| e.1 != cols[a].1));
        }
        if (seen >> d) & 1 != 0 {
            return false;
        }
        seen |= 1 << d;
    }
    true
}

/// [`Segments::forward`] on a segment of `C` columns (unrolled, the read side in registers).
#[inline(always)]
fn forward_fixed<const C: usize>(rows: &[u32], cols: &[u32], v: &[f64], x: &mut [f64]) {
    let mut y = [0.0; C];
    for (y, &q) in y.iter_mut().zip(cols) {
        *y = x[q as usize];
    }
    for (&p, vr) in rows.iter().zip(v.chunks_exact(C)) {
        let mut acc = x[p as usize];
        for k in 0..C {
            acc -= vr[k] * y[k];
        }
        x[p as usize] = acc;
    }
}

/// [`Segments::transposed`] on a segment of `C` distinct columns: their values held in
/// registers while the rows stream past (each column's subtractions in row order).
#[inline(always)]
fn transposed_fixed<const C: usize>(rows: &[u32], cols: &[u32], v: &[f64], x: &mut [f64]) {
    let mut acc = [0.0; C];
    for (a, &q) in acc.iter_mut().zip(cols) {
        *a = x[q as usize];
    }
    for (&p, vr) in rows.iter().zip(v.chunks_exact(C)) {
        let y = x[p as usize];
        for k in 0..C {
            acc[k] -= vr[k] * y;
        }
    }
    for (&a, &q) in acc.iter().zip(cols) {
        x[q as usize] = a;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The segment updates give the entry-by-entry loops' results bit for bit, both ways, on
    /// uniform blocks (`5 × 6`, `7`-wide, 3 to 5 columns as a chain's rows give, wide ones),
    /// rows of differing columns, a repeated column, a row split in two runs and rows longer
    /// than the gathered side.
    #[test]
    fn segments_equal_the_entry_loops_bit_for_bit() {
        let mut lcg = crate::lcg::Lcg::new(5);
        let mut rnd = || lcg.signed();
        let n = 120u32;
        let block = |rows: &[u32], cols: &[u32]| -> Vec<(u32, u32)> {
            rows.iter()
                .flat_map(|&p| cols.iter().map(move |&q| (p, q)))
                .collect()
        };
        let wide: Vec<u32> = (60..100).collect();
        let tall: Vec<u32> = (60..100).collect();
        let nodes: Vec<Vec<(u32, u32)>> = vec![
            block(&[0, 1, 2, 3, 4], &[10, 11, 12, 14, 15, 16]),
            block(&[5, 6], &[20, 21, 22, 23, 24, 25, 26]),
            block(&[7, 8, 9], &[30, 31, 32, 33, 34, 35, 36, 37, 38, 39, 40]),
            [block(&[13], &[41, 42]), block(&[17], &[41, 43])].concat(),
            block(&[18, 19], &[44, 44, 45]),
            [
                block(&[27], &[46]),
                block(&[28], &[47]),
                block(&[27], &[48]),
            ]
            .concat(),
            block(&[29, 49], &wide),
            block(&tall, &[50, 51]),
            block(&[100, 101, 102], &[103, 104, 105, 106, 107]),
            block(&[108, 109], &[110, 111, 112, 113]),
            block(&[114, 115], &[116, 117, 118]),
            Vec::new(),
        ];
        let mut off = Vec::new();
        let mut off_at = vec![0];
        for node in &nodes {
            off.extend_from_slice(node);
            off_at.push(off.len());
        }
        let vals: Vec<f64> = off.iter().map(|_| rnd()).collect();
        let x0: Vec<f64> = (0..n).map(|_| rnd()).collect();
        let seg = Segments::new(&off, &off_at);
        assert_eq!(seg.at.len(), nodes.len() + 1);
        // Distinct columns: near each other or far apart, a repeat either way.
        let row = |cols: &[u32]| cols.iter().map(|&q| (0, q)).collect::<Vec<_>>();
        assert!(distinct(&row(&[])) && distinct(&row(&[9])));
        assert!(distinct(&row(&[12, 10, 11, 70])) && distinct(&row(&[5, 200, 6])));
        assert!(!distinct(&row(&[12, 10, 12])) && !distinct(&row(&[5, 200, 6, 200])));
        // The chain's block is one segment.
        assert_eq!((seg.seg[0].rows, seg.seg[0].cols), (5, 6));
        let bits = |x: &[f64]| x.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        for i in 0..nodes.len() {
            let r = off_at[i]..off_at[i + 1];
            let (mut a, mut b) = (x0.clone(), x0.clone());
            for (&(p, q), &v) in off[r.clone()].iter().zip(&vals[r.clone()]) {
                a[p as usize] -= v * a[q as usize];
            }
            seg.forward(i, &vals, &mut b);
            assert_eq!(bits(&a), bits(&b), "forward, node {i}");
            let (mut a, mut b) = (x0.clone(), x0.clone());
            for (&(p, q), &v) in off[r.clone()].iter().zip(&vals[r]) {
                a[q as usize] -= v * a[p as usize];
            }
            seg.transposed(i, &vals, &mut b);
            assert_eq!(bits(&a), bits(&b), "transposed, node {i}");
            if i != nodes.len() - 1 {
                assert_ne!(bits(&a), bits(&x0), "node {i} updates something");
            }
        }
    }
}
