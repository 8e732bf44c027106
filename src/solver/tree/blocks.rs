//! The off-diagonal entries of `T` (module `phi_u`) of a node as one small dense **block**:
//! node `i`'s entries `(p, q, v)` lie on its rows `p₁ … p_r` and on the columns `q₁ … q_c` of
//! other nodes (a chain body's five joint rows on its parent's dependent coordinates), so
//! that, with `C_i` the `r × c` block of their values, zero where no entry lies,
//!
//! ```text
//! Φ_u x = r:   x_p −= Σ_q C_pq x_q    (each row's terms in the block's column order)
//! Φ_uᵀ μ = g:  μ_q −= Σ_p C_pq μ_p    (each column's terms in the block's row order)
//! ```
//!
//! with both sides gathered once into registers, as one unrolled loop over a row-major block:
//! no segment list (module `segments`, which takes the nodes that do not fit). The rows are
//! taken in the order in which the entries reach them, and the columns in an order that keeps
//! every row's entries in their own order (a topological order of "`q` before `q'` in some
//! row"), so each `x_p` and each `μ_q` sees the entry-by-entry loop's subtractions in its
//! order, and `x − 0 · y` for the places no entry reaches: the same values to the last bit but
//! for the sign of a zero (`−0 − 0 · y = +0`) and a non-finite `y` (then the solve fails
//! either way). A node gets a block when each side is at most [`MAX`], the block holds at most
//! [`FILL`] times its entries, each row's entries are one run without a repeated column, and
//! the rows' column orders agree. [`Blocks::new`] also lays out the off-diagonal values of the
//! factor buffer: node after node, a block (its zeros written when the buffer is made, never
//! reached by a triplet after), or a node's entries in their order (the segments'); the
//! Jacobian's triplets are scattered straight there (`Blocks::to`, module `phi_u::split`).

/// The largest side of a block.
pub(crate) const MAX: usize = 16;
/// A block holds at most this many times its node's entries.
const FILL: usize = 3;

/// The blocks of the nodes that have one.
#[derive(Default)]
pub(crate) struct Blocks {
    /// Node `i`'s block (`r == 0`: none).
    node: Vec<Block>,
    /// Each block's row positions, then its column positions.
    idx: Vec<u32>,
    /// The index of each off-diagonal entry in the off-diagonal values.
    to: Vec<u32>,
    /// The off-diagonal values' length.
    len: usize,
}

/// An `r × c` block, its rows and columns from `idx`, its values row-major from `at` (`r == 0`:
/// no block, the node's entries' values from `at` in their order).
#[derive(Clone, Copy, Default)]
struct Block {
    r: u8,
    c: u8,
    idx: u32,
    at: u32,
}

impl Blocks {
    /// The blocks of the entries `off` (grouped by node: node `i`'s are
    /// `off[off_at[i] .. off_at[i + 1]]`, in the triplets' order), and the layout of the
    /// off-diagonal values: node after node, a block node's `r × c` block (row-major, zero
    /// where no entry lies), another node's entries in their order.
    pub(crate) fn new(off: &[(u32, u32)], off_at: &[usize]) -> Self {
        let mut b = Blocks {
            node: Vec::with_capacity(off_at.len().saturating_sub(1)),
            idx: Vec::new(),
            to: vec![0; off.len()],
            len: 0,
        };
        let mut o = Order::default();
        // The last node given a block: its entries and its block.
        let mut last: Option<(&[usize], Block)> = None;
        for w in off_at.windows(2) {
            let e = &off[w[0]..w[1]];
            if let Some((p, prev)) = last {
                if b.shifted(prev, &off[p[0]..p[1]], e, (p[0], w[0])) {
                    last = b.node.last().map(|&blk| (w, blk));
                    continue;
                }
            }
            let to = &mut b.to[w[0]..w[1]];
            if !o.of(e, to) {
                // The entries in their order.
                for (k, t) in to.iter_mut().enumerate() {
                    *t = (b.len + k) as u32;
                }
                b.node.push(Block {
                    at: b.len as u32,
                    ..Block::default()
                });
                b.len += e.len();
                continue;
            }
            let (r, c) = (o.r, o.c);
            // `to` holds (row, column as reached); the column's place in the block order.
            for t in to.iter_mut() {
                let (i, k) = (*t as usize / MAX, *t as usize % MAX);
                *t = (b.len + i * c + o.place[k] as usize) as u32;
            }
            b.node.push(Block {
                r: r as u8,
                c: c as u8,
                idx: b.idx.len() as u32,
                at: b.len as u32,
            });
            b.idx.extend_from_slice(&o.rows[..r]);
            b.idx.extend_from_slice(&o.sorted[..c]);
            b.len += r * c;
            last = b.node.last().map(|&blk| (w, blk));
        }
        b
    }

    /// Gives the entries `e` (starting at `at.1`) the block `prev` of the entries `p` (starting
    /// at `at.0`) shifted, if `e` is `p` shifted by one row offset and one column offset (a
    /// chain's bodies): the same order of rows and columns, found without a search.
    fn shifted(
        &mut self,
        prev: Block,
        p: &[(u32, u32)],
        e: &[(u32, u32)],
        at: (usize, usize),
    ) -> bool {
        let (Some(&(p0, q0)), Some(&(e0, f0))) = (p.first(), e.first()) else {
            return false;
        };
        let (dp, dq) = (e0.wrapping_sub(p0), f0.wrapping_sub(q0));
        let same = p.len() == e.len()
            && p.iter()
                .zip(e)
                .all(|(a, b)| b.0 == a.0.wrapping_add(dp) && b.1 == a.1.wrapping_add(dq));
        let (r, c) = (prev.r as usize, prev.c as usize);
        let i = prev.idx as usize;
        let (rows, cols) = self.idx[i..i + r + c].split_at(r);
        let apart = same
            && cols.iter().all(|&q| {
                let q = q.wrapping_add(dq);
                rows.iter().all(|&x| x.wrapping_add(dp) != q)
            });
        if !apart {
            return false;
        }
        let (idx, len) = (self.idx.len(), self.len);
        for k in i..i + r + c {
            let d = if k < i + r { dp } else { dq };
            self.idx.push(self.idx[k].wrapping_add(d));
        }
        for k in 0..e.len() {
            self.to[at.1 + k] = self.to[at.0 + k] - prev.at + len as u32;
        }
        self.node.push(Block {
            idx: idx as u32,
            at: len as u32,
            ..prev
        });
        self.len += r * c;
        true
    }

    /// The off-diagonal values' length.
    pub(crate) fn len(&self) -> usize {
        self.len
    }

    /// Where the off-diagonal entry `k` goes in the off-diagonal values.
    pub(crate) fn to(&self, k: usize) -> usize {
        self.to[k] as usize
    }

    /// Where node `i`'s values start, if it has no block (its entries in their order).
    pub(crate) fn base(&self, i: usize) -> Option<usize> {
        let b = self.node[i];
        (b.r == 0).then_some(b.at as usize)
    }

    /// Whether node `i` has a block (else its entries are the segments').
    pub(crate) fn has(&self, i: usize) -> bool {
        self.node[i].r != 0
    }

    /// Node `i`'s block: its rows, its columns and its values.
    fn parts<'a>(&'a self, i: usize, vals: &'a [f64]) -> (&'a [u32], &'a [u32], &'a [f64]) {
        let b = self.node[i];
        let (r, c) = (b.r as usize, b.c as usize);
        let (rows, cols) = self.idx[b.idx as usize..b.idx as usize + r + c].split_at(r);
        (rows, cols, &vals[b.at as usize..b.at as usize + r * c])
    }

    /// `x_p −= Σ_q C_pq x_q` over node `i`'s block (`vals`: the off-diagonal values).
    pub(crate) fn forward(&self, i: usize, vals: &[f64], x: &mut [f64]) {
        let (rows, cols, v) = self.parts(i, vals);
        match (rows.len(), cols.len()) {
            (5, 5) => forward_fixed::<5, 5>(rows, cols, v, x),
            (5, 6) => forward_fixed::<5, 6>(rows, cols, v, x),
            (6, 6) => forward_fixed::<6, 6>(rows, cols, v, x),
            _ => forward_any(rows, cols, v, x),
        }
    }

    /// `x_q −= Σ_p C_pq x_p` over node `i`'s block (`vals`: the off-diagonal values).
    pub(crate) fn transposed(&self, i: usize, vals: &[f64], x: &mut [f64]) {
        let (rows, cols, v) = self.parts(i, vals);
        match (rows.len(), cols.len()) {
            (5, 5) => transposed_fixed::<5, 5>(rows, cols, v, x),
            (5, 6) => transposed_fixed::<5, 6>(rows, cols, v, x),
            (6, 6) => transposed_fixed::<6, 6>(rows, cols, v, x),
            _ => transposed_any(rows, cols, v, x),
        }
    }

    /// [`Blocks::forward`] on the `w` columns of the row-major `x` (`order × w`): each
    /// column's terms as one column's.
    pub(crate) fn forward_columns(&self, i: usize, vals: &[f64], x: &mut [f64], w: usize) {
        let (rows, cols, v) = self.parts(i, vals);
        for (&p, vr) in rows.iter().zip(v.chunks_exact(cols.len())) {
            let p = p as usize * w;
            for c in 0..w {
                let mut s = x[p + c];
                for (&u, &q) in vr.iter().zip(cols) {
                    s -= u * x[q as usize * w + c];
                }
                x[p + c] = s;
            }
        }
    }
}

/// A node's block: its rows in the order the entries reach them, its columns as reached and
/// in an order that keeps each row's (scratch reused from node to node).
#[derive(Default)]
struct Order {
    r: usize,
    c: usize,
    rows: [u32; MAX],
    cols: [u32; MAX],
    /// The columns in the block's order, and each reached column's place in it.
    sorted: [u32; MAX],
    place: [u8; MAX],
    /// `before[k]`: the columns that some row takes right before column `k`.
    before: [u32; MAX],
}

impl Order {
    /// The block of the entries `e`, with each entry's `(row, column as reached)` in `to` as
    /// `row · MAX + column`; `false` if they get none.
    fn of(&mut self, e: &[(u32, u32)], to: &mut [u32]) -> bool {
        (self.r, self.c) = (0, 0);
        self.before = [0; MAX];
        let mut k = 0;
        while k < e.len() {
            let p = e[k].0;
            if self.r == MAX || self.rows[..self.r].contains(&p) {
                return false;
            }
            self.rows[self.r] = p;
            self.r += 1;
            let (mut last, mut seen) = (None, 0u32);
            while k < e.len() && e[k].0 == p {
                let q = e[k].1;
                let at = match self.cols[..self.c].iter().position(|&x| x == q) {
                    Some(at) => at,
                    None if self.c < MAX => {
                        self.cols[self.c] = q;
                        self.c += 1;
                        self.c - 1
                    }
                    None => return false,
                };
                if seen & (1 << at) != 0 {
                    return false;
                }
                seen |= 1 << at;
                if let Some(l) = last {
                    self.before[at] |= 1u32 << l;
                }
                last = Some(at);
                to[k] = ((self.r - 1) * MAX + at) as u32;
                k += 1;
            }
        }
        let (rows, cols) = (&self.rows[..self.r], &self.cols[..self.c]);
        let apart = cols.iter().all(|q| !rows.contains(q));
        if self.r == 0 || self.r * self.c > FILL * e.len() || !apart {
            return false;
        }
        // Kahn's order over the columns, the first reached first among the ready ones.
        let mut done = 0u32;
        for n in 0..self.c {
            let ready = (0..self.c).find(|&a| done & (1 << a) == 0 && self.before[a] & !done == 0);
            let Some(a) = ready else {
                return false;
            };
            done |= 1 << a;
            self.sorted[n] = self.cols[a];
            self.place[a] = n as u8;
        }
        true
    }
}

/// [`Blocks::forward`] on an `R × C` block (unrolled, both sides in registers).
#[inline(always)]
fn forward_fixed<const R: usize, const C: usize>(
    rows: &[u32],
    cols: &[u32],
    v: &[f64],
    x: &mut [f64],
) {
    let (rows, cols, v) = (&rows[..R], &cols[..C], &v[..R * C]);
    let mut y = [0.0; C];
    for (y, &q) in y.iter_mut().zip(cols) {
        *y = x[q as usize];
    }
    for (&p, vr) in rows.iter().zip(v.chunks_exact(C)) {
        let mut s = x[p as usize];
        for k in 0..C {
            s -= vr[k] * y[k];
        }
        x[p as usize] = s;
    }
}

/// [`Blocks::transposed`] on an `R × C` block (unrolled, both sides in registers).
#[inline(always)]
fn transposed_fixed<const R: usize, const C: usize>(
    rows: &[u32],
    cols: &[u32],
    v: &[f64],
    x: &mut [f64],
) {
    let (rows, cols, v) = (&rows[..R], &cols[..C], &v[..R * C]);
    let mut a = [0.0; C];
    for (a, &q) in a.iter_mut().zip(cols) {
        *a = x[q as usize];
    }
    for (&p, vr) in rows.iter().zip(v.chunks_exact(C)) {
        let y = x[p as usize];
        for k in 0..C {
            a[k] -= vr[k] * y;
        }
    }
    for (&a, &q) in a.iter().zip(cols) {
        x[q as usize] = a;
    }
}

/// [`Blocks::forward`] on a block of any size.
fn forward_any(rows: &[u32], cols: &[u32], v: &[f64], x: &mut [f64]) {
    let c = cols.len();
    let mut y = [0.0; MAX];
    for (y, &q) in y.iter_mut().zip(cols) {
        *y = x[q as usize];
    }
    for (&p, vr) in rows.iter().zip(v.chunks_exact(c)) {
        let mut s = x[p as usize];
        for (&w, &y) in vr.iter().zip(&y[..c]) {
            s -= w * y;
        }
        x[p as usize] = s;
    }
}

/// [`Blocks::transposed`] on a block of any size.
fn transposed_any(rows: &[u32], cols: &[u32], v: &[f64], x: &mut [f64]) {
    let c = cols.len();
    let mut a = [0.0; MAX];
    for (a, &q) in a.iter_mut().zip(cols) {
        *a = x[q as usize];
    }
    for (&p, vr) in rows.iter().zip(v.chunks_exact(c)) {
        let y = x[p as usize];
        for (a, &w) in a[..c].iter_mut().zip(vr) {
            *a -= w * y;
        }
    }
    for (&a, &q) in a.iter().zip(cols) {
        x[q as usize] = a;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The blocks' updates equal the entry-by-entry loops bit for bit, both ways, on a chain
    /// body's `5 × 6` block (rows of 4 and 5 entries), a `3 × 3` one with its rows and columns
    /// out of position order and a `2 × 2` one; the nodes left to the segments are named.
    #[test]
    fn blocks_equal_the_entry_loops_bit_for_bit() {
        let mut lcg = crate::lcg::Lcg::new(11);
        let mut rnd = || lcg.signed();
        let n = 160u32;
        let block = |rows: &[u32], cols: &[u32]| -> Vec<(u32, u32)> {
            rows.iter()
                .flat_map(|&p| cols.iter().map(move |&q| (p, q)))
                .collect()
        };
        let chain = [
            block(&[0, 1], &[12, 13, 14, 15]),
            block(&[2], &[10, 12, 13, 14, 15]),
            block(&[3], &[11, 12, 13, 14, 15]),
            block(&[4], &[13, 14, 15]),
        ]
        .concat();
        // The next body's (the block shifted, without a search), then one shifted onto its
        // own rows.
        let next = chain.iter().map(|&(p, q)| (p + 5, q + 6)).collect();
        let onto = chain.iter().map(|&(p, q)| (p + 10, q + 2)).collect();
        let nodes: Vec<(Vec<(u32, u32)>, bool)> = vec![
            (chain, true),
            (next, true),
            (onto, false),
            (block(&[24, 22, 20], &[35, 31, 33]), true),
            (block(&[40, 42], &[50, 53]), true),
            // A row too long, too sparse, rows among the columns, a row in two runs, a
            // column twice in a row, rows that order the columns both ways, nothing.
            (block(&[60, 61], &(70..90).collect::<Vec<_>>()), false),
            ((0..4).map(|k| (91 + k, 100 + k)).collect(), false),
            (vec![(110, 111), (111, 110)], false),
            (vec![(120, 130), (121, 131), (120, 132)], false),
            (vec![(125, 135), (125, 135)], false),
            (vec![(140, 150), (140, 151), (141, 151), (141, 150)], false),
            (Vec::new(), false),
        ];
        let mut off = Vec::new();
        let mut off_at = vec![0];
        for (node, _) in &nodes {
            off.extend_from_slice(node);
            off_at.push(off.len());
        }
        let vals: Vec<f64> = off.iter().map(|_| rnd()).collect();
        let x0: Vec<f64> = (0..n).map(|_| rnd()).collect();
        let blocks = Blocks::new(&off, &off_at);
        // The blocks, then the other nodes' entries one by one.
        assert_eq!(blocks.len(), 30 + 30 + 9 + 4 + 21 + 40 + 4 + 2 + 3 + 2 + 4);
        let mut packed = vec![0.0; blocks.len()];
        for (k, &v) in vals.iter().enumerate() {
            packed[blocks.to(k)] = v;
        }
        for (i, (_, has)) in nodes.iter().enumerate() {
            let at = blocks.base(i);
            assert_eq!(at.is_none(), *has, "node {i}");
            if let Some(at) = at {
                let r = off_at[i]..off_at[i + 1];
                assert_eq!(&packed[at..at + r.len()], &vals[r], "node {i} in order");
            }
        }
        let bits = |x: &[f64]| x.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        for (i, (_, has)) in nodes.iter().enumerate() {
            assert_eq!(blocks.has(i), *has, "node {i}");
            if !has {
                continue;
            }
            let r = off_at[i]..off_at[i + 1];
            let (mut a, mut b) = (x0.clone(), x0.clone());
            for (&(p, q), &v) in off[r.clone()].iter().zip(&vals[r.clone()]) {
                a[p as usize] -= v * a[q as usize];
            }
            blocks.forward(i, &packed, &mut b);
            assert_eq!(bits(&a), bits(&b), "forward, node {i}");
            assert_ne!(bits(&a), bits(&x0), "node {i} updates something");
            let (mut a, mut b) = (x0.clone(), x0.clone());
            for (&(p, q), &v) in off[r.clone()].iter().zip(&vals[r]) {
                a[q as usize] -= v * a[p as usize];
            }
            blocks.transposed(i, &packed, &mut b);
            assert_eq!(bits(&a), bits(&b), "transposed, node {i}");
            // Three columns at once: each column's forward update.
            let w = 3;
            let cols: Vec<Vec<f64>> = (0..w).map(|_| (0..n).map(|_| rnd()).collect()).collect();
            let mut wide: Vec<f64> = (0..n as usize * w).map(|k| cols[k % w][k / w]).collect();
            blocks.forward_columns(i, &packed, &mut wide, w);
            for (c, col) in cols.iter().enumerate() {
                let mut one = col.clone();
                blocks.forward(i, &packed, &mut one);
                let got: Vec<f64> = (0..n as usize).map(|k| wide[k * w + c]).collect();
                assert_eq!(bits(&got), bits(&one), "forward, {w} columns, node {i}");
            }
        }
    }
}
