//! Dense or sparse linear algebra, chosen once per system: [`Backend::choose`] is the one
//! place that decides (a solve by its options, [`Backend::of`]; `verify` by its own
//! `linear_algebra`), and a [`System`](super::System) is built with the backend chosen.
//!
//! Both backends partition `Φ_q = [Φ_u Φ_v]` and factor `Φ_u`; the dense one by full pivoting
//! of the dense Jacobian and nalgebra's LU, the sparse one body by body (module `sparse`) and
//! with faer's sparse LU. The sparse backend also forms the reduced Hessian column by column
//! and solves Newton steps through the KKT system instead of the dense `Zᵀ W Z`.

use super::dense_memo::dense_partition;
use super::problem::Problem;
use crate::constraints::Triplets;
use crate::model::Model;
use crate::solver::partition::Partition;
use crate::solver::LinearAlgebra;

/// Models with more coordinates than this (40 bodies) use the sparse path when the choice is
/// automatic. Below, the dense path stays the default for every model that has closed loops,
/// joint stops, contacts, locks or mimics: its full-pivoting partition picks the assembly
/// branch the robot tests are written against (from a far start the tractor-trailer reaches a
/// different, lower-energy branch on the sparse path), and its partition is checked for drift
/// as the mechanism moves.
pub(super) const SPARSE_FROM_COORDINATES: usize = 7 * 40;

/// Small models without closed loops, stops, contacts, locks or mimics take the tree factors
/// from this many bodies on (automatic choice): they cost the same as the dense path at 1 – 2
/// bodies and less from 3 (chain 3: 0.073 against 0.084 ms; chain 5: 0.13 / 0.18; chain 20:
/// 1.4 / 3.4; chain 40: 10 / 61; BENCHMARKS.md). Up to 64 degrees of freedom the minimizer
/// steps on both by the exact Newton step along the search path (module
/// `step::path_hessian`), so the Newton steps are the same up to the partition's choice of
/// independent coordinates and rounding (on the tree factors, away from stationary points,
/// by Cholesky where the Hessian along the path is positive definite, and far from the rest
/// Newton on `Ĥ` alone, module `step::path_cholesky`).
const TREE_FROM_BODIES: usize = 3;

/// The linear algebra of a system.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Backend {
    /// Dense matrices (small models).
    Dense,
    /// Sparse matrices (module `sparse`).
    Sparse,
    /// The sparse partition with tree-structured factors (module `tree`; the sparse factors
    /// where a partition does not fit a tree).
    Tree,
}

impl Backend {
    /// The backend `choice` asks for; automatic: by the size of `model`, and above
    /// [`SPARSE_FROM_COORDINATES`] the tree factors for a mechanism without joint stops (its
    /// partitions fit a tree: `O(N)` with fixed-size blocks, faster than the general sparse
    /// factors on chains and ropes, BENCHMARKS.md; with closed loops, each factor that does not
    /// fit a tree with a small border is factored by super-nodes, module `tree::merge`: a
    /// ladder's thousand loops), the sparse ones otherwise. A mechanism without closed
    /// loops but with stops is given the sparse factors here and the tree ones by each round
    /// of its solve ([`Backend::of_round`]; before the projected stop search, the tree
    /// factors' last Newton steps stalled on Romeo's finger stops at a reduced gradient of
    /// 3.7e-8, tolerance 1e-8). Contacts are rows on their body like a joint's (tested against the
    /// sparse factors: a rope on the ground, Solo-12 standing). Below, the tree factors for a
    /// model of [`TREE_FROM_BODIES`] or more bodies without closed loops, stops, contacts,
    /// locks or mimics, and the dense path otherwise.
    pub(crate) fn choose(model: &Model, choice: LinearAlgebra) -> Self {
        match choice {
            LinearAlgebra::Auto if model.coordinate_count() > SPARSE_FROM_COORDINATES => {
                if model.joints.iter().all(|j| j.limits.is_none()) {
                    Backend::Tree
                } else {
                    Backend::Sparse
                }
            }
            LinearAlgebra::Auto if small_tree(model) => Backend::Tree,
            LinearAlgebra::Auto | LinearAlgebra::Dense => Backend::Dense,
            LinearAlgebra::Sparse => Backend::Sparse,
            LinearAlgebra::Tree => Backend::Tree,
        }
    }

    /// The backend of a solve with `options` (its `linear_algebra`; automatic: by size).
    pub(crate) fn of(model: &Model, options: &crate::solver::Options) -> Self {
        Self::choose(model, options.linear_algebra)
    }

    /// The backend of one round of a solve with `options`: [`Backend::of`], but with the
    /// automatic choice the tree factors for every mechanism without closed loops, its joint
    /// stops active in the round or not (a stop's row is on its joint's child body, like the
    /// joint's own rows). The sparse factors cost Romeo hanging onto its finger stops 1.26×
    /// the CPU of its solve with `--limits ignore` (faer's numeric LU, its symbolic analysis
    /// at each round's partition and its solves: all of the difference); the tree factors
    /// 1.06× (BENCHMARKS.md). The stall [`Backend::choose`] recalls is gone since the
    /// projected stop search: `--linear-algebra tree` ends Romeo's 14 iterations at the
    /// sparse factors' rest.
    pub(crate) fn of_round(model: &Model, options: &crate::solver::Options) -> Self {
        let chosen = Self::of(model, options);
        if options.linear_algebra == LinearAlgebra::Auto && chosen == Backend::Sparse && open(model)
        {
            Backend::Tree
        } else {
            chosen
        }
    }

    /// The automatic backend of `verify` at a pose: [`Backend::choose`], but the tree factors
    /// for every mechanism without closed loops above the dense size, stops or not (they
    /// factor the same sparse partition, and give the same efforts and forces to rounding),
    /// and the dense path for every model up to that size.
    pub(crate) fn for_verify(model: &Model) -> Self {
        if model.coordinate_count() <= SPARSE_FROM_COORDINATES {
            return Backend::Dense;
        }
        match Self::choose(model, LinearAlgebra::Auto) {
            Backend::Sparse if open(model) => Backend::Tree,
            chosen => chosen,
        }
    }

    /// `"dense"`, `"sparse"` or `"tree"` (as the report's diagnostics name it).
    pub(crate) fn name(self) -> &'static str {
        match self {
            Backend::Dense => "dense",
            Backend::Sparse => "sparse",
            Backend::Tree => "tree",
        }
    }

    /// Partition of the Jacobian `jac` of `problem` (full pivoting of the dense `Φ_q`, or the
    /// sparse body-by-body elimination).
    pub(crate) fn partition(
        self,
        problem: &Problem,
        jac: &Triplets,
        coordinates: usize,
    ) -> Partition {
        let scaling = &problem.scaling;
        match self {
            Backend::Sparse | Backend::Tree => {
                let (model, m, n) = (problem.model, problem.cons.len(), coordinates);
                let (rows, columns) = (&scaling.rows, &scaling.columns);
                // The same partition, on dense copies of each body's rows where they answer.
                crate::solver::sparse::fill_free::partition(
                    model,
                    m,
                    n,
                    &jac.entries,
                    rows,
                    columns,
                )
                .unwrap_or_else(|| {
                    crate::solver::sparse::partition::partition(
                        model,
                        m,
                        n,
                        &jac.entries,
                        rows,
                        columns,
                    )
                })
            }
            Backend::Dense => dense_partition(jac, &scaling.rows, &scaling.columns),
        }
    }
}

/// Whether `model` is one of the small trees [`Backend::choose`] gives the tree factors at the
/// dense size (at most [`SPARSE_FROM_COORDINATES`] coordinates, [`small_tree`]): where the
/// minimizer may step by Cholesky away from stationary points (module `step::path_cholesky`).
pub(crate) fn is_small_tree(model: &Model) -> bool {
    model.coordinate_count() <= SPARSE_FROM_COORDINATES && small_tree(model)
}

/// Whether `model` is small and takes the tree factors ([`TREE_FROM_BODIES`]): open, at least
/// that many bodies, and no stop, contact, lock or mimic.
fn small_tree(model: &Model) -> bool {
    model.bodies.len() >= TREE_FROM_BODIES
        && open(model)
        && model.joints.iter().all(|j| j.limits.is_none())
        && model.grounds.is_empty()
        && model.obstacles.is_empty()
        && model.contact_points.is_empty()
        && model.locks.is_empty()
        && model.mimics.is_empty()
}

/// Whether the tree factors of `model` report their pivot ratio to the minimizer's drift test
/// (module `minimize`): at the dense size, where they take the place of the dense factors and
/// keep their watch (an Euler parameter taken as independent folds its chart where a leg has
/// turned by π: the hanging minitaurs stalled at `max_iterations` without it). Above it they
/// re-partition like the sparse factors (on a fold, after a failed correction): the watch is
/// not measured there (ropes and long chains, whose every body turns, might re-partition at
/// every step).
pub(crate) fn tree_watches_pivots(model: &Model) -> bool {
    model.coordinate_count() <= SPARSE_FROM_COORDINATES
}

/// Whether `model` has no closed loop (every joint a tree joint or merged).
pub(super) fn open(model: &Model) -> bool {
    model.joints.iter().all(|j| j.tree || j.merged)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::urdf::{load_str, ImportOptions};

    fn model(text: &str) -> Model {
        load_str(text, "chain.urdf", &ImportOptions::default())
            .unwrap()
            .model
    }

    /// The automatic choice: the tree factors for an open chain without stops, long or from 3
    /// bodies; the sparse ones once a long chain has stops, dense once a short one has them or
    /// below 3 bodies (and for `verify` up to 40 bodies).
    #[test]
    fn automatic_choice_keeps_the_tree_factors_to_open_chains_without_stops() {
        let free = crate::generate::chain(60, false);
        assert_eq!(
            Backend::choose(&model(&free), LinearAlgebra::Auto),
            Backend::Tree
        );
        let limited = free
            .replace("type=\"continuous\"", "type=\"revolute\"")
            .replace(
                "<axis ",
                "<limit lower=\"-3\" upper=\"3\" effort=\"1\" velocity=\"1\"/><axis ",
            );
        assert_ne!(limited, free);
        let m = model(&limited);
        assert!(m.joints.iter().any(|j| j.limits.is_some()));
        assert_eq!(Backend::choose(&m, LinearAlgebra::Auto), Backend::Sparse);
        assert_eq!(Backend::choose(&m, LinearAlgebra::Tree), Backend::Tree);
        let small = crate::generate::chain(10, false);
        assert_eq!(
            Backend::choose(&model(&small), LinearAlgebra::Auto),
            Backend::Tree
        );
        assert_eq!(Backend::for_verify(&model(&small)), Backend::Dense);
        let small_limited = small
            .replace("type=\"continuous\"", "type=\"revolute\"")
            .replace(
                "<axis ",
                "<limit lower=\"-3\" upper=\"3\" effort=\"1\" velocity=\"1\"/><axis ",
            );
        assert_eq!(
            Backend::choose(&model(&small_limited), LinearAlgebra::Auto),
            Backend::Dense
        );
        let tiny = crate::generate::chain(1, false);
        assert_eq!(
            Backend::choose(&model(&tiny), LinearAlgebra::Auto),
            Backend::Dense
        );
    }
}
