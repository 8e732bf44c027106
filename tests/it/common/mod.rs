//! Shared helpers of the integration tests.

pub(crate) mod builders;
pub(crate) mod contact;
pub(crate) mod energies;
pub(crate) mod pyramid;
pub(crate) mod statics;

use restpose::state::State;
use restpose::urdf::{load_file, load_str, ImportOptions};
use restpose::{Model, Options, Report};

/// Bolt standing as in the Pinocchio corpus (`robots/bolt/`, files named from that folder):
/// a floating base on the ground, sticking contacts, servos of 1000 N m/rad about its SRDF
/// `standing` state.
pub(crate) const BOLT_STANDING: [&str; 10] = [
    "--floating-base",
    "--ground",
    "--friction",
    "stick",
    "--servo",
    "all=1000",
    "--srdf",
    "bolt.srdf",
    "--srdf-state",
    "standing",
];

/// Runs `restpose analyze -q --json OUT ARGS…` in the folder `robots/DIR`: the exit code,
/// standard error, and the result JSON (`Null` where none was written).
pub(crate) fn analyze_in(dir: &str, args: &[String]) -> (Option<i32>, String, serde_json::Value) {
    let tmp = tempfile::tempdir().unwrap();
    let json = tmp.path().join("result.json");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_restpose"))
        .current_dir(
            std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("robots")
                .join(dir),
        )
        .args(["analyze", "-q", "--json"])
        .arg(&json)
        .args(args)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    let v = std::fs::read_to_string(&json)
        .map(|t| serde_json::from_str(&t).unwrap())
        .unwrap_or(serde_json::Value::Null);
    (out.status.code(), err, v)
}

/// The potential energy of `model` at the joint values of `state` with joint `joint`'s first
/// coordinate moved by `delta` (the others held), by forward kinematics from the joint values:
/// an independent probe of a rest in joint coordinates.
pub(crate) fn energy_moved(model: &Model, state: &State, joint: &str, delta: f64) -> f64 {
    let mut v: restpose::state::JointValues = state.joint_values(model).into_iter().collect();
    v.get_mut(joint)
        .unwrap_or_else(|| panic!("no joint `{joint}`"))[0] += delta;
    restpose::verify::potential_energy(model, &State::from_joint_values(model, &v)).unwrap()
}

/// Loads `robots/NAME.urdf`.
pub(crate) fn robot(name: &str) -> Model {
    let path = format!("{}/robots/{name}.urdf", env!("CARGO_MANIFEST_DIR"));
    load_file(&path, &ImportOptions::default())
        .unwrap_or_else(|e| panic!("{e}"))
        .model
}

/// Loads URDF text.
pub(crate) fn model_from(text: &str) -> Model {
    load_str(text, "test.urdf", &ImportOptions::default())
        .unwrap_or_else(|e| panic!("{e}"))
        .model
}

/// Solves with default options and asserts convergence.
pub(crate) fn solve(model: &Model) -> (State, Report) {
    let (s, r) = restpose::solve(model, &Options::default()).unwrap_or_else(|e| panic!("{e}"));
    assert!(
        r.converged(),
        "{} did not converge: {:?}",
        model.name(),
        r.termination
    );
    (s, r)
}

/// Solves by the direct solve (`load_steps: 1`, no load ramp), the way issue 21 counts
/// iterations; the caller checks the termination.
pub(crate) fn solve_direct(model: &Model) -> (State, Report) {
    let direct = Options {
        load_steps: 1,
        ..Default::default()
    };
    restpose::solve(model, &direct).unwrap_or_else(|e| panic!("{e}"))
}

/// The distance between two angles on the circle, in `[0, π]` (rad).
pub(crate) fn angle_distance(a: f64, b: f64) -> f64 {
    let off = (a - b).rem_euclid(std::f64::consts::TAU);
    off.min(std::f64::consts::TAU - off)
}

/// Independent equilibrium checks: constraints hold, the projected gradient vanishes, and no
/// small feasible perturbation (random joint displacements, then re-assembly) lowers the
/// energy.
pub(crate) fn assert_verified_minimum(model: &Model, state: &State) {
    let b = restpose::verify::balance(model, state).unwrap();
    assert!(
        b.constraint_residual < 1e-10,
        "{}: ‖Φ‖∞ = {:e}",
        model.name(),
        b.constraint_residual
    );
    assert!(
        b.projected_gradient < 1e-6,
        "{}: projected gradient {:e}",
        model.name(),
        b.projected_gradient
    );
    let v0 = b.potential_energy;
    let mut seed = 12345u64;
    let mut rnd = || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((seed >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    };
    for trial in 0..20 {
        let mut q = state.q.clone();
        for i in 0..q.len() {
            q[i] += 1e-4 * rnd();
        }
        let perturbed = restpose::verify::assemble(
            model,
            &State {
                q,
                branches: state.branches.clone(),
            },
        )
        .unwrap();
        let moved = (&perturbed.q - &state.q).amax();
        let v = restpose::verify::potential_energy(model, &perturbed).unwrap();
        assert!(
            v >= v0 - 1e-12 * (1.0 + v0.abs()),
            "{}: trial {trial}: a feasible perturbation of size {moved:e} lowers the energy from {v0} to {v}",
            model.name()
        );
    }
}
