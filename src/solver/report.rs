//! What a solve returns besides the final state.

use crate::forces::Energy;

/// Why the minimizer stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Termination {
    /// Reduced gradient and constraint residual below tolerance.
    Converged,
    /// `max_iterations` reached.
    MaxIterations,
    /// No acceptable step even after step halving and re-partitioning.
    LineSearchFailed,
    /// The energy decreases without bound (for example a prismatic joint along gravity with
    /// no spring or limit).
    Unbounded,
    /// The active set of joint stops and contacts kept changing (`max_iterations` changes).
    ActiveSetCycling,
    /// The solver's own tests passed but the independent checks of `verify` reject the pose
    /// (set by their caller: `restpose analyze` runs them on every answer before it reports it
    /// converged).
    RejectedByVerify,
}

impl Termination {
    /// The snake-case name used in the JSON.
    pub fn as_str(&self) -> &'static str {
        match self {
            Termination::Converged => "converged",
            Termination::MaxIterations => "max_iterations",
            Termination::LineSearchFailed => "line_search_failed",
            Termination::Unbounded => "unbounded",
            Termination::ActiveSetCycling => "active_set_cycling",
            Termination::RejectedByVerify => "rejected_by_verify",
        }
    }
}

/// One accepted iterate.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct Iterate {
    /// Iteration number, counted over the whole solve (0 = the assembled initial guess; each
    /// load step and active-set round starts with a row for its start, numbered as the last
    /// row before it).
    pub iteration: usize,
    /// Potential energy \[J\] (of the load step's loads).
    pub potential_energy: f64,
    /// `‖∂V/∂v‖∞` in scaled coordinates \[J\].
    pub gradient_norm: f64,
    /// Load step: `k` of `diagnostics.load_steps` (1 without a ramp); 0 for the direct attempt
    /// at the full load that the automatic ramp replaced.
    pub load_step: usize,
    /// Active-set round: 1 for the first set of active stops and contacts, one more at each
    /// change of the set (1 without stops and contacts).
    pub round: usize,
}

/// Appends the history `rows` (and their configurations) of a later load step or round to
/// `history`, renumbering its iterations after the last row of `history`.
pub(crate) fn append_history(
    history: &mut Vec<Iterate>,
    iterates: &mut Vec<crate::State>,
    rows: Vec<Iterate>,
    states: Vec<crate::State>,
) {
    let offset = history.last().map_or(0, |h| h.iteration);
    history.extend(rows.into_iter().map(|mut h| {
        h.iteration += offset;
        h
    }));
    iterates.extend(states);
}

/// The stability verdict, from the smallest eigenvalue `λ₁` of the reduced Hessian and the
/// eigenvalue tolerance `ε`; serialized as `"stable"`, `"unstable"` or `"neutral"`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Verdict {
    /// Every eigenvalue `> ε`: a strict local minimum of the energy.
    Stable,
    /// `λ₁ < −ε` (or a negative eigenvalue counted by the KKT inertia): a saddle or maximum.
    Unstable,
    /// `|λ₁| ≤ ε`: flat to second order along some motion (higher orders decide).
    Neutral,
}

impl Verdict {
    /// The snake-case name used in the JSON.
    pub fn as_str(&self) -> &'static str {
        match self {
            Verdict::Stable => "stable",
            Verdict::Unstable => "unstable",
            Verdict::Neutral => "neutral",
        }
    }
}

impl std::fmt::Display for Verdict {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// Stability of the equilibrium from the eigenvalues of the reduced Hessian.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Stability {
    /// `stable` (all eigenvalues > tolerance), `unstable` (one < −tolerance) or `neutral`.
    pub verdict: Verdict,
    /// Eigenvalue tolerance used: `1e-10 · max(1, max |λ|)` \[J\].
    pub tolerance: f64,
    /// Smallest eigenvalues of the reduced Hessian in joint coordinates, ascending (at most 6):
    /// `d²V/dθ²` along the feasible motions \[N m/rad for rotations, N/m for slides\], the same
    /// from any start (module `solver::joint_space`; independent joint coordinates where loops
    /// make some dependent). Above 64 degrees of freedom on the tree and sparse paths they are
    /// empty unless asked for ([`crate::Options::eigenvalues`], `verify::Eigenvalues::Always`):
    /// the verdict then comes from the KKT inertia alone; asked for above 200 (Lanczos) they
    /// are those of the scaled reduced Hessian \[J\] instead. Empty when stops or contacts leave no feasible motion (verdict `stable`). The
    /// verdict and `tolerance` are those of the scaled reduced Hessian, which has the same
    /// signs (Sylvester's law of inertia).
    pub eigenvalues: Vec<f64>,
    /// Mode shape of each listed eigenvalue: the change of every joint coordinate along the
    /// eigenvector, scaled so that the largest is ±1 (a rotation in rad, a slide in m), by joint
    /// in the model's file order (a floating base by its link: `[x, y, z, rx, ry, rz]`).
    pub modes: Vec<Mode>,
}

/// A mode shape: per joint (or floating base link), in file order, the change of its
/// coordinates. Serialized as a JSON object in that order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mode(pub Vec<(String, Vec<f64>)>);

impl Mode {
    /// The entries in file order.
    pub fn iter(&self) -> impl Iterator<Item = (&String, &Vec<f64>)> {
        self.0.iter().map(|(n, v)| (n, v))
    }

    /// The coordinate changes of joint `name`.
    pub fn get(&self, name: &str) -> Option<&Vec<f64>> {
        self.0.iter().find(|(n, _)| n == name).map(|(_, v)| v)
    }
}

impl<'a> IntoIterator for &'a Mode {
    type Item = (&'a String, &'a Vec<f64>);
    type IntoIter = std::iter::Map<
        std::slice::Iter<'a, (String, Vec<f64>)>,
        fn(&'a (String, Vec<f64>)) -> (&'a String, &'a Vec<f64>),
    >;
    fn into_iter(self) -> Self::IntoIter {
        self.0.iter().map(|(n, v)| (n, v))
    }
}

impl std::ops::Index<&str> for Mode {
    type Output = Vec<f64>;
    /// # Panics
    /// If the mode has no joint `name`.
    fn index(&self, name: &str) -> &Vec<f64> {
        self.get(name)
            .unwrap_or_else(|| panic!("the mode has no joint `{name}`"))
    }
}

impl serde::Serialize for Mode {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let mut m = s.serialize_map(Some(self.0.len()))?;
        for (n, v) in &self.0 {
            m.serialize_entry(n, v)?;
        }
        m.end()
    }
}

/// Whether a counter is 0 (left out of the JSON).
fn is_zero(n: &usize) -> bool {
    *n == 0
}

/// Counters of what the solver had to do.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct Diagnostics {
    /// With termination `unbounded`: the motions along which the energy falls without bound
    /// (joints with the sense of their coordinate, free bodies with their direction).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub free_directions: Vec<String>,
    /// Potential evaluations (trial points that assembled).
    pub function_evaluations: usize,
    /// Trial points where the Newton corrector failed.
    pub corrector_failures: usize,
    /// Step halvings in line searches.
    pub step_halvings: usize,
    /// Re-partitions after the first.
    pub repartitions: usize,
    /// Steps taken along a direction of negative curvature (leaving a saddle or maximum).
    pub negative_curvature_steps: usize,
    /// Reduced directions computed only to decide which of several stops leave the active
    /// set together (module `inequality::release_trial`), not taken by any iteration; left
    /// out of the JSON when 0.
    #[serde(skip_serializing_if = "is_zero")]
    pub release_trials: usize,
    /// Final `‖∂V/∂v‖∞` \[J\].
    pub gradient_norm: f64,
    /// Gradient tolerance applied: the requested one, or the rounding floor
    /// `1e-13 · Σ|V_k|` of the energy's terms if larger \[J\].
    pub gradient_tolerance: f64,
    /// Load steps used (1: the full load at once).
    pub load_steps: usize,
    /// Final raw `‖Φ‖∞` \[m or rad\] (the tolerance applies to the dimensionless `‖D Φ‖∞`,
    /// module `system::residual`).
    pub constraint_residual: f64,
    /// Linear algebra used: `"dense"`, `"sparse"` or `"tree"` (see
    /// [`crate::solver::LinearAlgebra`]).
    pub linear_algebra: String,
    /// How the stability eigenvalues were found: `"exact"` (the reduced Hessian decomposed),
    /// `"lanczos"` (its low end only, for many degrees of freedom), or `"inertia"` (none: the
    /// verdict from the inertia of the shifted KKT matrix, above 64 degrees of freedom on the
    /// tree and sparse paths without [`Options::eigenvalues`](crate::Options::eigenvalues));
    /// empty without a verdict.
    pub eigenvalues_by: String,
    /// Wall time of each phase \[s\].
    pub timings: Timings,
}

/// Wall time of each phase of an analysis \[s\]. The solver fills `assembly`, `iterations`
/// and `stability`; `import`, `export` and `self_check` are the caller's (the CLI measures
/// reading the URDF, building the result and confirming the pose with `verify`'s checks;
/// writing the text is not included).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct Timings {
    /// Reading and importing the model \[s\].
    pub import: f64,
    /// Closing the loops from the initial guess \[s\].
    pub assembly: f64,
    /// The minimizer's iterations, load stages included \[s\].
    pub iterations: f64,
    /// Stability (eigenvalues or inertia: the minimizer's verdict at its rest and the
    /// active set's final one) and reactions at the rest pose \[s\].
    pub stability: f64,
    /// Building the result (joint values, link frames) \[s\].
    pub export: f64,
    /// The minimizer's iterations proper, part of `iterations`: each from one convergence
    /// test to the next (a step, its line search and corrector), summed over load stages and
    /// active-set rounds. The rest of `iterations` is what each minimization does once: the
    /// partition, the first evaluation, the final convergence test \[s\].
    pub steps: f64,
    /// The first iteration of each minimization, part of `steps`: the one in which the linear
    /// algebra's structure is built and its memory first touched, so that `(steps −
    /// first_step) / (iterations − 1)` is the time of an iteration in a steady state (one
    /// minimization) \[s\].
    pub first_step: f64,
    /// The CLI's confirmation of a converged pose by `verify`'s independent checks before it
    /// exits 0 (`analyze`; 0 where nothing was confirmed: a solve that did not converge, a
    /// library call) \[s\].
    pub self_check: f64,
}

/// The clock of the minimizer's iterations (`Timings::steps`, `Timings::first_step`): each
/// [`Laps::lap`] after the first adds the time since the last one.
#[derive(Default)]
pub(crate) struct Laps {
    last: Option<std::time::Instant>,
    laps: usize,
}

impl Laps {
    /// The end of one pass of the loop and the start of the next.
    pub(crate) fn lap(&mut self, timings: &mut Timings) {
        let now = std::time::Instant::now();
        if let Some(last) = self.last {
            let took = now.duration_since(last).as_secs_f64();
            if self.laps == 0 {
                timings.first_step = took;
            }
            timings.steps += took;
            self.laps += 1;
        }
        self.last = Some(now);
    }
}

impl Diagnostics {
    /// Adds the work counters of `other` (not its final norms).
    pub(crate) fn add_counts(&mut self, other: &Diagnostics) {
        self.function_evaluations += other.function_evaluations;
        self.corrector_failures += other.corrector_failures;
        self.step_halvings += other.step_halvings;
        self.repartitions += other.repartitions;
        self.negative_curvature_steps += other.negative_curvature_steps;
        self.release_trials += other.release_trials;
        // The time spent judging stability (every round's and stage's rest), so that the
        // caller's `iterations` (the rest of the solve) does not count it.
        self.timings.stability += other.timings.stability;
        self.timings.steps += other.timings.steps;
        self.timings.first_step += other.timings.first_step;
    }
}

/// Reaction of a joint on its child link at the joint origin.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Reaction {
    /// Force in the world frame \[N\].
    pub force_world: [f64; 3],
    /// Torque about the joint origin, world frame \[N m\].
    pub torque_world: [f64; 3],
    /// Force in the joint frame (parent side) \[N\].
    pub force_joint: [f64; 3],
    /// Torque in the joint frame (parent side) \[N m\].
    pub torque_joint: [f64; 3],
}

/// Sizes of the solved problem.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct Sizes {
    /// Moving bodies.
    pub bodies: usize,
    /// Cartesian coordinates (7 per body).
    pub coordinates: usize,
    /// Constraint rows, before redundant ones are dropped (normalization, locks and mimics
    /// included).
    pub constraint_rows: usize,
}

/// How a contact point holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ContactState {
    /// Frictionless contact: pushes along the normal only.
    Touching,
    /// Held tangentially where it first touched, within its friction coefficient (or none is
    /// given).
    Sticking,
    /// Held tangentially, needing more friction than its coefficient `mu` in the distribution
    /// reported, when no distribution within the coefficients balances the pose (module
    /// `solver::friction`): it would slide.
    Slipping,
}

/// A contact point resting on a ground.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Contact {
    /// The link whose collision shape touches.
    pub link: String,
    /// The ground it rests on.
    pub ground: String,
    /// The touching point (on the shape's surface), world frame \[m\].
    pub point_world: [f64; 3],
    /// The ground's normal (out of the ground), world frame.
    pub normal_world: [f64; 3],
    /// Gap `g` at the rest pose (0 up to the constraint tolerance) \[m\].
    pub gap: f64,
    /// Normal force the ground exerts on the link \[N\] (≥ 0).
    pub normal_force: f64,
    /// Tangential (friction) force the ground exerts on the link, world frame \[N\].
    pub tangential_force: [f64; 3],
    /// Friction coefficient the contact needs in the distribution reported, `|f_t| / f_n` (0
    /// when frictionless): its `needs_mu`.
    pub required_friction: f64,
    /// Touching, sticking or slipping.
    pub state: ContactState,
}

/// A joint resting on one of its stops.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct ActiveLimit {
    /// Joint name.
    pub joint: String,
    /// `lower` or `upper`.
    pub bound: String,
    /// The stop's position \[rad or m\].
    pub value: f64,
    /// Generalized force the stop exerts on the joint coordinate \[N m or N\]: positive on a
    /// lower stop, negative on an upper one.
    pub effort: f64,
    /// The joint's effort limit (URDF `<limit effort>`) \[N m or N\], when given.
    pub effort_limit: Option<f64>,
    /// Whether `|effort|` exceeds `effort_limit`: the actuator cannot hold this pose.
    pub exceeds_effort_limit: bool,
}

/// The friction verdict of a pose with sticking contacts (module `solver::friction`).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct FrictionVerdict {
    /// The smallest friction coefficient, common to every sticking contact, for which forces
    /// balancing the pose exist (each contact inside its friction cone, each stop within its
    /// joint's effort limit).
    pub required_mu: f64,
    /// The coefficient given to every sticking contact, when they share one.
    pub mu: Option<f64>,
    /// `mu − required_mu`, when they share one.
    pub margin: Option<f64>,
    /// Whether no distribution within the given coefficients balances the pose.
    pub slipping: bool,
}

/// The solve's report.
#[derive(Clone, Debug, PartialEq)]
pub struct Report {
    /// Why it stopped.
    pub termination: Termination,
    /// Minimizer iterations.
    pub iterations: usize,
    /// Energy at the final state \[J\].
    pub energy: Energy,
    /// Degrees of freedom `n − rank(Φ_q)`.
    pub dof: usize,
    /// Iteration history (iteration 0 = start): every load step and active-set round, in
    /// order (see [`Iterate`]).
    pub history: Vec<Iterate>,
    /// Names of the independent coordinates of the final partition.
    pub independent_coordinates: Vec<String>,
    /// Names of the constraint rows found redundant.
    pub redundant_constraints: Vec<String>,
    /// Stability verdict at the final state.
    pub stability: Option<Stability>,
    /// Reactions of every joint with constraint rows, by joint name.
    pub reactions: Vec<(String, Reaction)>,
    /// Counters.
    pub diagnostics: Diagnostics,
    /// Sizes of the problem.
    pub sizes: Sizes,
    /// The configuration at each entry of `history` (only with `Options::record_iterates`):
    /// every load step and active-set round.
    pub iterates: Vec<crate::State>,
    /// Contact points resting on the grounds.
    pub contacts: Vec<Contact>,
    /// Joints resting on a stop.
    pub active_limits: Vec<ActiveLimit>,
    /// Changes of the set of active stops and contacts (additions and releases).
    pub active_set_changes: usize,
    /// The friction verdict, with sticking contacts.
    pub friction: Option<FrictionVerdict>,
    /// Support polygon, centre of mass and stability margin of a free mechanism standing on
    /// its contacts.
    pub balance: Option<crate::solver::balance::Balance>,
    /// The floating groups that could not stand on their ground start and toppled before the
    /// solve (module `solver::topple`; empty when none did).
    pub toppled: Vec<crate::solver::Toppled>,
}

impl Report {
    /// Whether the solve converged.
    pub fn converged(&self) -> bool {
        self.termination == Termination::Converged
    }
}

#[cfg(test)]
mod tests {
    use super::Verdict;

    /// The JSON keeps the strings it had before the verdict became an enum.
    #[test]
    fn verdict_serializes_as_before() {
        for (v, s) in [
            (Verdict::Stable, "stable"),
            (Verdict::Unstable, "unstable"),
            (Verdict::Neutral, "neutral"),
        ] {
            assert_eq!(serde_json::to_string(&v).unwrap(), format!("\"{s}\""));
            assert_eq!(v.to_string(), s);
        }
    }
}
