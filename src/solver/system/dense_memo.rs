//! The dense path's partition and factors at the last inputs, kept per thread. The
//! active-set iteration computes both twice at the same point: a release trial partitions and
//! evaluates its projected start, then the round that starts there does it again (12 of
//! TIAGo Pro's 30 dense partitions and of its 48 LUs of `Φ_u`, 4 of alex's 21 and 52).
//!
//! - `partition(D Φ_q S)` is a function of the Jacobian's triplets and the scales `D`, `S`
//!   alone (module `solver::partition`): a second request with the same triplets and scales,
//!   bit for bit, gets the kept partition under a fresh id, as a new computation would.
//! - `Φ_u`'s LU and `Φ_v` are functions of the triplets and the partition's rows, dependent
//!   and independent coordinates: a second request gets the kept ones (shared, not copied).
//!
//! One of each is kept per thread, until the thread's next request replaces it (the factors
//! are let go before new ones are computed, so that two are never held for the memo's sake):
//! the triplets, one partition, and the factors of a `Φ_u` of at most [`KEPT_ROWS`] rows (the
//! automatic dense size: under a megabyte; a larger one, `--linear-algebra dense` on a long
//! chain, is not kept).

use super::backend::SPARSE_FROM_COORDINATES;
use super::dense_lu::DenseLu;
use crate::constraints::{Triplet, Triplets};
use crate::solver::partition::{next_id, partition_owned, Partition};
use nalgebra::DMatrix;
use std::cell::RefCell;
use std::sync::Arc;

/// The inputs of a partition, compared bit for bit.
#[derive(PartialEq)]
struct Key {
    rows: usize,
    cols: usize,
    entries: Vec<(u32, u32, u64)>,
    row_scale: Vec<u64>,
    col_scale: Vec<u64>,
}

impl Key {
    fn of(jac: &Triplets, row_scale: &[f64], col_scale: &[f64]) -> Self {
        let bits = |x: &[f64]| x.iter().map(|v| v.to_bits()).collect();
        Key {
            rows: jac.rows,
            cols: jac.cols,
            entries: entry_bits(&jac.entries),
            row_scale: bits(row_scale),
            col_scale: bits(col_scale),
        }
    }
}

fn entry_bits(entries: &[Triplet]) -> Vec<(u32, u32, u64)> {
    entries
        .iter()
        .map(|&(i, j, v)| (i, j, v.to_bits()))
        .collect()
}

/// The inputs of the factors: the triplets and the partition's choices.
#[derive(PartialEq)]
struct FactorsKey {
    entries: Vec<(u32, u32, u64)>,
    rows: Vec<usize>,
    dependent: Vec<usize>,
    independent: Vec<usize>,
}

/// The largest `Φ_u` (rows) whose factors are kept: the coordinates of the automatic dense
/// path's largest model (module `backend`).
pub(crate) const KEPT_ROWS: usize = SPARSE_FROM_COORDINATES;

/// The dense factors: `Φ_u`'s LU and `Φ_v`.
pub(crate) type DenseFactors = (Arc<DenseLu>, Arc<DMatrix<f64>>);

thread_local! {
    static LAST: RefCell<Option<(Key, Partition)>> = const { RefCell::new(None) };
    static LAST_FACTORS: RefCell<Option<(FactorsKey, DenseFactors)>> = const { RefCell::new(None) };
}

/// The full-pivoting partition of the dense `jac` with the scales (`partition_owned`), the
/// kept one where the inputs are the last request's.
pub(crate) fn dense_partition(jac: &Triplets, row_scale: &[f64], col_scale: &[f64]) -> Partition {
    let key = Key::of(jac, row_scale, col_scale);
    let kept = LAST.with_borrow(|last| {
        last.as_ref()
            .filter(|(k, _)| *k == key)
            .map(|(_, part)| Partition {
                id: next_id(),
                ..part.clone()
            })
    });
    if let Some(part) = kept {
        return part;
    }
    let part = partition_owned(jac.to_dense(), row_scale, col_scale);
    LAST.set(Some((key, part.clone())));
    part
}

/// `Φ_u`'s LU and `Φ_v` of the triplets `entries` under `part` (`compute` makes them), the
/// kept ones where the inputs are the last request's.
pub(crate) fn dense_factors(
    entries: &[Triplet],
    part: &Partition,
    compute: impl FnOnce() -> (DenseLu, DMatrix<f64>),
) -> DenseFactors {
    let key = FactorsKey {
        entries: entry_bits(entries),
        rows: part.rows.clone(),
        dependent: part.dependent.clone(),
        independent: part.independent.clone(),
    };
    let kept = LAST_FACTORS.take().filter(|(k, _)| *k == key);
    if let Some((key, factors)) = kept {
        LAST_FACTORS.set(Some((key, factors.clone())));
        return factors;
    }
    let (lu, phi_v) = compute();
    let factors = (Arc::new(lu), Arc::new(phi_v));
    if part.rows.len() <= KEPT_ROWS {
        LAST_FACTORS.set(Some((key, factors.clone())));
    }
    factors
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A repeated request gets the same partition under a new id; a changed value, scale or
    /// shape computes anew, and each equals `partition_owned` of its own inputs.
    #[test]
    fn repeats_equal_a_fresh_partition() {
        let jac = Triplets {
            rows: 2,
            cols: 3,
            entries: vec![
                (0, 0, 1.0),
                (0, 1, 2.0),
                (1, 1, 0.5),
                (1, 2, 3.0),
                (1, 2, -1.0),
            ],
        };
        let (rs, cs) = (vec![1.0, 2.0], vec![1.0, 0.5, 1.0]);
        let fresh = |j: &Triplets, r: &[f64], c: &[f64]| partition_owned(j.to_dense(), r, c);
        let same = |a: &Partition, b: &Partition| {
            (&a.dependent, &a.independent, &a.rows, &a.redundant)
                == (&b.dependent, &b.independent, &b.rows, &b.redundant)
        };
        let first = dense_partition(&jac, &rs, &cs);
        let again = dense_partition(&jac, &rs, &cs);
        assert!(same(&first, &fresh(&jac, &rs, &cs)) && same(&first, &again));
        assert_ne!(first.id, again.id);
        let mut other = jac.clone();
        other.entries[1].2 = 0.0;
        let changed = dense_partition(&other, &rs, &cs);
        assert!(same(&changed, &fresh(&other, &rs, &cs)));
        assert!(!same(&changed, &first));
        let scaled = dense_partition(&jac, &rs, &[1.0, 5.0, 1.0]);
        assert!(same(&scaled, &fresh(&jac, &rs, &[1.0, 5.0, 1.0])));
        assert!(!same(&scaled, &first));
    }

    /// The factors of a repeated request are the kept ones (shared); a changed triplet or
    /// partition computes anew.
    #[test]
    fn repeated_factors_are_shared() {
        let part = |rows: Vec<usize>, dependent: Vec<usize>, independent: Vec<usize>| Partition {
            id: next_id(),
            dependent,
            independent,
            rows,
            redundant: Vec::new(),
            second_pass: Vec::new(),
        };
        let entries = vec![(0, 0, 2.0), (0, 1, 1.0)];
        let p = part(vec![0], vec![0], vec![1]);
        let mut computed = 0;
        let mut make = |v: f64| {
            computed += 1;
            (
                DenseLu::new(DMatrix::from_element(1, 1, v)),
                DMatrix::from_element(1, 1, 1.0),
            )
        };
        let a = dense_factors(&entries, &p, || make(2.0));
        let b = dense_factors(&entries, &part(vec![0], vec![0], vec![1]), || make(2.0));
        assert!(Arc::ptr_eq(&a.0, &b.0) && Arc::ptr_eq(&a.1, &b.1));
        let changed = vec![(0, 0, 3.0), (0, 1, 1.0)];
        let c = dense_factors(&changed, &p, || make(3.0));
        assert!(!Arc::ptr_eq(&a.0, &c.0));
        let other = dense_factors(&changed, &part(vec![0], vec![1], vec![0]), || make(1.0));
        assert!(!Arc::ptr_eq(&c.0, &other.0));
        assert_eq!(computed, 3);
        // A `Φ_u` above the dense size is not kept: asked twice, computed twice.
        let rows: Vec<usize> = (0..=KEPT_ROWS).collect();
        let big = part(rows.clone(), rows, Vec::new());
        let mut made = 0;
        for _ in 0..2 {
            dense_factors(&entries, &big, || {
                made += 1;
                (DenseLu::new(DMatrix::identity(1, 1)), DMatrix::zeros(1, 0))
            });
        }
        assert_eq!(made, 2);
    }
}
