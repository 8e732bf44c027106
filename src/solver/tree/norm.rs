//! The row sums of `|K|` for `‖K‖∞ = maxᵢ Σⱼ |K_ij|` (the scale of a solve's backward error),
//! one tree node at a time: its diagonal block `K_i` (`d × d`) and its coupling `C_i`
//! (`d × w`), which counts for both of its rows (the node's own and the parent's leading `w`):
//!
//! ```text
//! s_a += Σ_b |K_i,ab|  (one partial sum, added),   s_a += |C_i,ab|,  s_p+b += |C_i,ab|  (b = 0, 1, …)
//! ```
//!
//! The sizes of a chain and a ladder run unrolled at compile time (constant `D` and `W`, the
//! parent's `W` sums kept in registers): the same additions in the same order as the general
//! loop, so the same sums to the last bit (checked in `dense_tests`).

/// Adds the row sums of node `blk` (`d × d`) and its coupling `c` (`d × w`, `w = 0` for none)
/// to `own` (`d` long) and `up` (`w` long).
pub(super) fn add_node(
    blk: &[f64],
    c: &[f64],
    own: &mut [f64],
    up: &mut [f64],
    (d, w): (usize, usize),
) {
    match (d, w) {
        (13, 7) => node::<13, 7>(blk, c, own, up),
        (13, 0) => node::<13, 0>(blk, c, own, up),
        (14, 7) => node::<14, 7>(blk, c, own, up),
        (14, 0) => node::<14, 0>(blk, c, own, up),
        (8, 7) => node::<8, 7>(blk, c, own, up),
        (27, 7) => node::<27, 7>(blk, c, own, up),
        (14, 18) => node::<14, 18>(blk, c, own, up),
        (27, 0) => node::<27, 0>(blk, c, own, up),
        _ => node_any(blk, c, own, up, (d, w)),
    }
}

/// [`add_node`] for any size (the reference of the unrolled kernel).
pub(super) fn node_any(
    blk: &[f64],
    c: &[f64],
    own: &mut [f64],
    up: &mut [f64],
    (d, w): (usize, usize),
) {
    let (blk, own) = (&blk[..d * d], &mut own[..d]);
    for (a, row) in own.iter_mut().zip(blk.chunks_exact(d.max(1))) {
        *a += row.iter().map(|v| v.abs()).sum::<f64>();
    }
    if w > 0 {
        let (c, up) = (&c[..d * w], &mut up[..w]);
        for (sa, crow) in own.iter_mut().zip(c.chunks_exact(w)) {
            for (sb, &x) in up.iter_mut().zip(crow) {
                let v = x.abs();
                *sa += v;
                *sb += v;
            }
        }
    }
}

/// [`add_node`] for `D × D` and `D × W`.
#[inline(never)]
fn node<const D: usize, const W: usize>(blk: &[f64], c: &[f64], own: &mut [f64], up: &mut [f64]) {
    let (blk, c, own) = (&blk[..D * D], &c[..D * W], &mut own[..D]);
    let mut acc = [0.0; W];
    acc.copy_from_slice(&up[..W]);
    for a in 0..D {
        let row = &blk[a * D..a * D + D];
        let mut s = 0.0;
        for &v in row {
            s += v.abs();
        }
        let mut sa = own[a] + s;
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
