//! The independent rows and columns of a small dense matrix `A` (a component's `J_c` in
//! module `loop_efforts`): Gaussian elimination with full pivoting of `D_r A D_c`, the largest
//! remaining entry the pivot, until the entries left are at most `RANK_TOLERANCE · max|D_r A D_c|`
//! (the general partition's rank test, module `solver::partition`).

use crate::solver::partition::RANK_TOLERANCE;
use nalgebra::DMatrix;

/// Full pivoting of `jac` scaled by `row_scale` and `col_scale`: the pivot rows and columns in
/// pivot order, up to the rank (pivots above `RANK_TOLERANCE` times the largest entry).
pub(super) fn pivots(
    jac: &DMatrix<f64>,
    row_scale: &[f64],
    col_scale: &[f64],
) -> (Vec<usize>, Vec<usize>) {
    let (nr, nc) = jac.shape();
    let mut a = DMatrix::from_fn(nr, nc, |r, c| jac[(r, c)] * row_scale[r] * col_scale[c]);
    let tol = (RANK_TOLERANCE * a.amax()).max(f64::MIN_POSITIVE);
    let (mut rows, mut cols) = (Vec::new(), Vec::new());
    let (mut row_free, mut col_free) = (vec![true; nr], vec![true; nc]);
    for _ in 0..nr.min(nc) {
        let mut best = (0, 0, 0.0);
        for r in (0..nr).filter(|&r| row_free[r]) {
            for c in (0..nc).filter(|&c| col_free[c]) {
                if a[(r, c)].abs() > best.2 {
                    best = (r, c, a[(r, c)].abs());
                }
            }
        }
        if best.2 <= tol {
            break;
        }
        let (pr, pc) = (best.0, best.1);
        row_free[pr] = false;
        col_free[pc] = false;
        rows.push(pr);
        cols.push(pc);
        let pivot = a[(pr, pc)];
        for r in (0..nr).filter(|&r| row_free[r]) {
            let f = a[(r, pc)] / pivot;
            if f != 0.0 {
                for c in (0..nc).filter(|&c| col_free[c]) {
                    a[(r, c)] -= f * a[(pr, c)];
                }
            }
        }
    }
    (rows, cols)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A `5 × 3` matrix of rank 2 (its third column the sum of the others, rounded; two rows
    /// of rounding-level entries, as a planar loop's out-of-plane rows): two pivots, the
    /// largest entry first; a column scale changes which column comes first.
    #[test]
    fn the_pivots_stop_at_the_rank_and_follow_the_scaling() {
        #[rustfmt::skip]
        let a = DMatrix::from_row_slice(
            5,
            3,
            &[
                0.3, -2.0, -1.7,
                1.0, 0.5, 1.5,
                1e-17, 0.0, 2e-17,
                0.0, 3e-18, 0.0,
                0.7, 0.25, 0.95,
            ],
        );
        let (rows, cols) = pivots(&a, &[1.0; 5], &[1.0; 3]);
        assert_eq!((rows.len(), cols.len()), (2, 2));
        assert_eq!((rows[0], cols[0]), (0, 1));
        assert!(rows.iter().all(|&r| r != 2 && r != 3), "{rows:?}");
        let (rows, cols) = pivots(&a, &[1.0; 5], &[10.0, 1.0, 1.0]);
        assert_eq!((rows.len(), rows[0], cols[0]), (2, 1, 0));
        assert!(rows.iter().all(|&r| r != 2 && r != 3), "{rows:?}");
    }
}
