//! Argument definitions (clap derive). Defaults come from the library: [`Options::default`]
//! for the solver and [`Tolerances::default`] for `verify`; the solver's enums are
//! `clap::ValueEnum` themselves (feature `cli`).

use super::parse;
use super::values::{Family, Friction, Limits, LinearAlgebra, Method, StopSearch, Topple};
use anyhow::{bail, Context};
use clap::{Parser, Subcommand, ValueEnum};
use restpose::solver::ContactPolicy;
use restpose::urdf::ImportOptions;
use restpose::verify::Tolerances;
use restpose::Options;
use std::path::PathBuf;

#[derive(Parser)]
#[command(
    name = "restpose",
    version,
    about = "Static equilibrium (rest pose) of URDF mechanisms"
)]
pub(crate) struct Cli {
    #[command(subcommand)]
    pub(crate) command: Command,
}

#[derive(Subcommand)]
pub(crate) enum Command {
    /// Solve for the stable rest pose and print a summary.
    Analyze(AnalyzeArgs),
    /// Load and validate a file without solving; print the model as understood.
    Check(CheckArgs),
    /// Solve and open the rest pose in the rerun viewer (feature `viewer`).
    View(AnalyzeArgs),
    /// Check whether a given pose is a rest pose, without moving it.
    Verify(VerifyArgs),
    /// Write a generated benchmark mechanism (URDF) to standard output.
    Generate(GenerateArgs),
}

/// How the model is read (shared by every subcommand that reads a URDF).
#[derive(clap::Args, Clone)]
pub(crate) struct InputArgs {
    /// Gravity [m/s²] when the file has no <mech:gravity>.
    #[arg(long, num_args = 3, value_names = ["X", "Y", "Z"], allow_hyphen_values = true,
          value_parser = parse::finite)]
    pub(crate) gravity: Option<Vec<f64>>,
    /// Where `package://NAME/…` meshes live (repeatable).
    #[arg(long, value_name = "NAME=DIR")]
    pub(crate) package: Vec<String>,
    /// Give links without <inertial> the mass properties of their collision (else visual)
    /// geometry at this density [kg/m³].
    #[arg(long, value_name = "DENSITY", value_parser = parse::positive)]
    pub(crate) inertia_from_geometry: Option<f64>,
    /// Leave the root link free instead of welding it to the world.
    #[arg(long)]
    pub(crate) floating_base: bool,
    /// Add the ground plane z = 0 (+z up): links with collision geometry rest on it.
    #[arg(long)]
    pub(crate) ground: bool,
    /// Start position of the floating root link [m] (overrides <mech:base xyz>).
    #[arg(long, num_args = 3, value_names = ["X", "Y", "Z"], allow_hyphen_values = true,
          value_parser = parse::finite)]
    pub(crate) base_xyz: Option<Vec<f64>>,
    /// Start orientation of the floating root link, roll pitch yaw [rad] (overrides
    /// <mech:base rpy>).
    #[arg(long, num_args = 3, value_names = ["ROLL", "PITCH", "YAW"], allow_hyphen_values = true,
          value_parser = parse::finite)]
    pub(crate) base_rpy: Option<Vec<f64>>,
    /// Hold joints like position servos: `all=K` (every revolute, continuous and prismatic
    /// joint that is not locked or a mimic) or `JOINT=K[@REF]`, a joint spring of stiffness K
    /// [N m/rad or N/m] about REF (default: the reference pose, else the initial value); a
    /// JOINT's REF is also its start; later ones override earlier ones (repeatable).
    #[arg(long, value_name = "JOINT=K[@REF]")]
    pub(crate) servo: Vec<String>,
    /// The servos' reference pose: a joint_states YAML (what --write-joint-states writes) or
    /// any pose file `verify --pose` reads.
    #[arg(long, value_name = "FILE")]
    pub(crate) servo_reference: Option<PathBuf>,
    /// An SRDF file whose `<group_state name=STATE>` (--srdf-state) is the servos' reference
    /// pose.
    #[arg(long, value_name = "FILE.srdf", requires = "srdf_state")]
    pub(crate) srdf: Option<PathBuf>,
    /// The named `group_state` of --srdf.
    #[arg(long, value_name = "NAME", requires = "srdf")]
    pub(crate) srdf_state: Option<String>,
    /// Argument of a xacro file (`FILE.xacro`, expanded in-process; repeatable).
    #[arg(long, value_name = "NAME:=VALUE")]
    pub(crate) xacro_arg: Vec<String>,
}

impl InputArgs {
    /// An import error with the command line's words for it: a base pose the model cannot take
    /// (module `urdf::base`) names `--base-xyz` / `--base-rpy` and `--floating-base`.
    pub(crate) fn explain(&self, e: restpose::Error) -> anyhow::Error {
        let given = self.base_xyz.is_some() || self.base_rpy.is_some();
        if given && e.to_string().contains("base pose (`base_pose`)") {
            return anyhow::anyhow!(
                "{e}; on the command line: --base-xyz / --base-rpy place the root link that \
                 --floating-base lets float, --initial JOINT[DOF]=VALUE a `floating` joint's start"
            );
        }
        e.into()
    }

    /// The importer's options.
    pub(crate) fn options(&self) -> anyhow::Result<ImportOptions> {
        let mut opts = ImportOptions {
            floating_base: self.floating_base,
            ground: self.ground,
            inertia_density: self.inertia_from_geometry,
            ..Default::default()
        };
        let r = self.base_rpy.clone().unwrap_or_else(|| vec![0.0; 3]);
        let rotation = nalgebra::UnitQuaternion::from_euler_angles(r[0], r[1], r[2]);
        if let Some(t) = &self.base_xyz {
            opts.base_pose = Some(nalgebra::Isometry3::from_parts(
                nalgebra::Translation3::new(t[0], t[1], t[2]),
                rotation,
            ));
        } else if self.base_rpy.is_some() {
            // The orientation given, the position found by the ground start.
            opts.base_orientation = Some(rotation);
        }
        if let Some(g) = &self.gravity {
            opts.gravity = nalgebra::Vector3::new(g[0], g[1], g[2]);
        }
        for p in &self.package {
            let (n, d) = p
                .split_once('=')
                .with_context(|| format!("--package {p}: expected NAME=DIR"))?;
            opts.packages.push((n.to_string(), PathBuf::from(d)));
        }
        for s in &self.servo {
            opts.servos.push(parse::servo(s)?);
        }
        if let Some(path) = &self.servo_reference {
            opts.servo_reference
                .extend(restpose::verify::read_reference_pose(path)?);
        }
        if let (Some(path), Some(state)) = (&self.srdf, &self.srdf_state) {
            opts.servo_reference
                .extend(restpose::urdf::srdf_state(path, state)?);
        }
        for a in &self.xacro_arg {
            let (n, v) = a
                .split_once(":=")
                .with_context(|| format!("--xacro-arg {a}: expected NAME:=VALUE"))?;
            opts.xacro_args.push((n.trim().to_string(), v.to_string()));
        }
        Ok(opts)
    }
}

#[derive(clap::Args)]
pub(crate) struct CheckArgs {
    /// URDF file.
    pub(crate) file: PathBuf,
    #[command(flatten)]
    pub(crate) input: InputArgs,
    /// Output format on standard output.
    #[arg(long, value_enum, default_value = "text")]
    pub(crate) format: Format,
    /// Also write the model summary as JSON to this file (`-`: standard output, which then
    /// carries only the JSON).
    #[arg(long, value_name = "OUT.json")]
    pub(crate) json: Option<PathBuf>,
    /// Also list ignored foreign elements.
    #[arg(long, short)]
    pub(crate) verbose: bool,
}

/// Output format of `check`.
#[derive(Clone, Copy, ValueEnum)]
pub(crate) enum Format {
    Text,
    Json,
}

#[derive(clap::Args)]
pub(crate) struct VerifyArgs {
    /// URDF file.
    pub(crate) file: PathBuf,
    /// Pose: restpose result JSON, a {"joint": value} JSON map, or ROS joint_states-style
    /// YAML/JSON (`name` and `position` lists, restpose's `multi_dof` section, `rostopic echo`
    /// output: the last message).
    #[arg(long, value_name = "POSE")]
    pub(crate) pose: Option<PathBuf>,
    /// Joint value (repeatable; overrides the pose file): JOINT=VALUE or JOINT[DOF]=VALUE.
    #[arg(long, value_name = "JOINT=VALUE")]
    pub(crate) joint: Vec<String>,
    /// Hold a joint coordinate at its value in the pose, as `analyze --lock` held it: JOINT,
    /// JOINT[DOF] or JOINT=VALUE (repeatable). Its effort is reported as a holding effort and
    /// does not fail the pose.
    #[arg(long, value_name = "JOINT")]
    pub(crate) lock: Vec<String>,
    /// Largest effort a joint may need for the pose to pass [N m or N], plus 1e-9 of the
    /// largest generalized force on any coordinate.
    #[arg(long, default_value_t = Tolerances::default().force, value_parser = parse::positive)]
    pub(crate) force_tolerance: f64,
    /// Largest dimensionless constraint residual ‖DΦ‖∞ for the pose to pass (each row in m^k
    /// divided by L^k, L the characteristic length; the residual and default of `analyze
    /// --constraint-tolerance`).
    #[arg(long, default_value_t = Tolerances::default().constraint, value_parser = parse::positive)]
    pub(crate) constraint_tolerance: f64,
    /// Band of a stop's or contact's gap, scaled as its row (m divided by L, or rad), within
    /// which it touches and beyond which through a stop or a ground the pose fails: the band
    /// in which analyze's active set takes an inequality as touching.
    #[arg(long, default_value_t = Tolerances::default().gap, value_parser = parse::positive)]
    pub(crate) gap_tolerance: f64,
    /// Write the verification as JSON to this file (`-`: standard output, which then carries
    /// only the JSON: no report).
    #[arg(long, value_name = "OUT.json")]
    pub(crate) json: Option<PathBuf>,
    #[command(flatten)]
    pub(crate) input: InputArgs,
    #[command(flatten)]
    pub(crate) contact: ContactArgs,
    /// Verification path: dense (orthonormal null-space basis, O(n³)), sparse (the solver's
    /// sparse partition, O(N)), or auto: sparse above 40 bodies.
    #[arg(long, value_enum, default_value_t = LinearAlgebra::from(Options::default().linear_algebra))]
    pub(crate) linear_algebra: LinearAlgebra,
    /// Report the lowest eigenvalues and mode shapes of the stability verdict at any size.
    /// Without it, above 64 degrees of freedom on the tree and sparse paths the verdict comes
    /// from the inertia of the shifted KKT matrix alone (faster; `eigenvalues` and `modes`
    /// empty, `diagnostics.eigenvalues_by` "inertia"); up to 64, or on the dense path, they
    /// are always listed.
    #[arg(long)]
    pub(crate) eigenvalues: bool,
    /// Print only errors and the verdict.
    #[arg(long, short)]
    pub(crate) quiet: bool,
}

#[derive(clap::Args)]
pub(crate) struct GenerateArgs {
    /// Family.
    #[arg(value_enum)]
    pub(crate) family: Family,
    /// Number of links (chains, rope) or loops (ladder), 1 to 1,000,000.
    #[arg(long, default_value_t = 20, value_parser = parse::generate_size)]
    pub(crate) size: usize,
}

#[derive(clap::Args, Clone)]
pub(crate) struct AnalyzeArgs {
    /// URDF file.
    pub(crate) file: PathBuf,
    /// Write the result JSON here (written even when the solve does not converge; `-`:
    /// standard output, which then carries only the JSON: no summary).
    #[arg(long, value_name = "OUT.json")]
    pub(crate) json: Option<PathBuf>,
    #[command(flatten)]
    pub(crate) input: InputArgs,
    /// Hold a joint coordinate: JOINT=VALUE or JOINT[DOF]=VALUE (repeatable).
    #[arg(long, value_name = "JOINT=VALUE")]
    pub(crate) lock: Vec<String>,
    /// Initial guess of a joint coordinate: JOINT=VALUE or JOINT[DOF]=VALUE (repeatable).
    #[arg(long, value_name = "JOINT=VALUE")]
    pub(crate) initial: Vec<String>,
    /// Write a rerun recording (.rrd) of the rest pose and the search (feature `viewer`).
    #[arg(long, value_name = "OUT.rrd")]
    pub(crate) rrd: Option<PathBuf>,
    /// Write the input file with the rest pose as `mech:initial` values (only when converged;
    /// `-`: standard output, which then carries only this file).
    #[arg(long, value_name = "OUT.urdf")]
    pub(crate) write_urdf: Option<PathBuf>,
    /// Write the rest pose as ROS joint_states-style YAML (only when converged; `-`: standard
    /// output, which then carries only this file).
    #[arg(long, value_name = "OUT.yaml")]
    pub(crate) write_joint_states: Option<PathBuf>,
    #[command(flatten)]
    pub(crate) formats: FormatArgs,
    /// Maximum minimizer iterations.
    #[arg(long, default_value_t = Options::default().max_iterations)]
    pub(crate) max_iterations: usize,
    /// Tolerance on the scaled reduced gradient [J].
    #[arg(long, default_value_t = Options::default().gradient_tolerance, value_parser = parse::positive)]
    pub(crate) tolerance: f64,
    /// Tolerance on the dimensionless constraint residual ‖DΦ‖∞: each row in m^k divided by
    /// L^k, L the characteristic length (rotations as they are), so that it means the same in
    /// any length unit. The reported `constraint_residual` is the raw ‖Φ‖∞ [m or rad].
    #[arg(long, default_value_t = Options::default().constraint_tolerance, value_parser = parse::positive)]
    pub(crate) constraint_tolerance: f64,
    /// Minimizer.
    #[arg(long, value_enum, default_value_t = Method::from(Options::default().method))]
    pub(crate) method: Method,
    /// Linear algebra: dense matrices (small models), sparse (partition body by body, faer
    /// sparse LU, Newton steps from the sparse KKT system), tree (the sparse partition factored
    /// along the kinematic tree), or auto: tree or sparse above 40 bodies, tree below for
    /// open models without stops or contacts, dense otherwise.
    #[arg(long, value_enum, default_value_t = LinearAlgebra::from(Options::default().linear_algebra))]
    pub(crate) linear_algebra: LinearAlgebra,
    /// Ramp gravity, loads and efforts in N steps (0: automatic, 8 steps only if the direct
    /// solve fails; 1: never; at most 1000).
    #[arg(long, default_value_t = Options::default().load_steps, value_name = "N",
          value_parser = parse::load_steps)]
    pub(crate) load_steps: usize,
    /// How a step that reaches joint stops is searched: cut where it reaches the first (one
    /// stop per iteration), or projected (each joint held at a stop it reaches, the others
    /// moving on; every stop reached joins at once). See docs/method.md, "The search path".
    #[arg(long, value_enum, default_value_t = StopSearch::from(Options::default().stop_search))]
    pub(crate) stop_search: StopSearch,
    /// A floating base placed on the ground (no base position given) whose centre of mass is
    /// not over its support there: topple it as a rigid body over its support's edges onto the
    /// points it lands on first (the JSON's `topple`), or solve from where it was placed.
    /// Only with one ground, sticking contacts and no loads on it. See docs/servo.md.
    #[arg(long, value_enum, default_value_t = Topple::from(Options::default().topple))]
    pub(crate) topple: Topple,
    /// Stop at an unstable stationary point instead of leaving it.
    #[arg(long)]
    pub(crate) allow_unstable: bool,
    /// Report the lowest eigenvalues and mode shapes of the stability verdict at any size.
    /// Without it, above 64 degrees of freedom on the tree and sparse paths the verdict comes
    /// from the inertia of the shifted KKT matrix alone (faster; `eigenvalues` and `modes`
    /// empty, `diagnostics.eigenvalues_by` "inertia"); up to 64, or on the dense path, they
    /// are always listed.
    #[arg(long)]
    pub(crate) eigenvalues: bool,
    #[command(flatten)]
    pub(crate) contact: ContactArgs,
    /// Print only errors.
    #[arg(long, short)]
    pub(crate) quiet: bool,
    /// Also list ignored foreign elements.
    #[arg(long, short)]
    pub(crate) verbose: bool,
}

impl AnalyzeArgs {
    /// The outputs given as `-` (standard output), as their options.
    pub(crate) fn stdout_outputs(&self) -> Vec<&'static str> {
        [
            ("--json", &self.json),
            ("--write-urdf", &self.write_urdf),
            ("--write-joint-states", &self.write_joint_states),
            ("--write-mujoco-key", &self.formats.write_mujoco_key),
            ("--write-srdf", &self.formats.write_srdf),
        ]
        .into_iter()
        .filter(|(_, p)| super::print::is_stdout(p.as_ref()))
        .map(|(o, _)| o)
        .collect()
    }

    /// A usage error (exit code 2) when more than one output is standard output: their texts
    /// would be interleaved in one stream.
    pub(crate) fn check_outputs(&self) -> Result<(), clap::Error> {
        let to_stdout = self.stdout_outputs();
        if to_stdout.len() > 1 {
            return Err(<Cli as clap::CommandFactory>::command().error(
                clap::error::ErrorKind::ArgumentConflict,
                format!(
                    "{} {} write to standard output (`-`); only one output can go there: \
                     give the others a file name",
                    to_stdout.join(" and "),
                    if to_stdout.len() == 2 { "both" } else { "all" }
                ),
            ));
        }
        Ok(())
    }

    /// The solver's options.
    pub(crate) fn solver_options(&self) -> Options {
        Options {
            record_iterates: self.rrd.is_some(),
            method: self.method.into(),
            linear_algebra: self.linear_algebra.into(),
            gradient_tolerance: self.tolerance,
            constraint_tolerance: self.constraint_tolerance,
            max_iterations: self.max_iterations,
            allow_unstable: self.allow_unstable,
            eigenvalues: self.eigenvalues,
            load_steps: self.load_steps,
            stop_search: self.stop_search.into(),
            topple: self.topple.into(),
            ..Default::default()
        }
        .with_contact(self.contact.policy())
    }
}

/// The stops' and contacts' options, shared by `analyze` and `verify` (one definition, one
/// help text): the [`ContactPolicy`].
#[derive(clap::Args, Clone, Debug)]
pub(crate) struct ContactArgs {
    /// URDF joint limits: enforce (a joint can rest on its stop, which carries an effort, and
    /// may not go beyond it) or ignore (a pose outside them is only reported).
    #[arg(long, value_enum, default_value_t = Limits::from(ContactPolicy::default().limits))]
    pub(crate) limits: Limits,
    /// Contacts without a friction setting in <mech:contact>: none (frictionless) or stick
    /// (held where they first touch, carrying a tangential force; the needed friction
    /// coefficient is reported).
    #[arg(long, value_enum, default_value_t = Friction::from(ContactPolicy::default().friction))]
    pub(crate) friction: Friction,
    /// Friction coefficient of sticking contacts without `mu` in <mech:contact>: a contact
    /// needing more is reported as slipping (`verify`: the pose fails).
    #[arg(long, value_name = "MU", value_parser = parse::positive)]
    pub(crate) mu: Option<f64>,
}

impl ContactArgs {
    /// The policy these options give.
    pub(crate) fn policy(&self) -> ContactPolicy {
        ContactPolicy {
            limits: self.limits.into(),
            friction: self.friction.into(),
            mu: self.mu,
        }
    }
}

/// The rest pose in other tools' files (`analyze`; written only when converged).
#[derive(clap::Args, Clone)]
pub(crate) struct FormatArgs {
    /// Write the rest pose as a MuJoCo keyframe: an MJCF file that loads the URDF (the
    /// `--write-urdf` file when given) with `<key name="rest" qpos>` (`-`: standard output).
    #[arg(long, value_name = "OUT.xml")]
    pub(crate) write_mujoco_key: Option<PathBuf>,
    /// Write the rest pose as a MoveIt SRDF `<group_state>` (`-`: standard output).
    #[arg(long, value_name = "OUT.srdf")]
    pub(crate) write_srdf: Option<PathBuf>,
    /// The SRDF group of `--write-srdf` (every moving joint).
    #[arg(long, value_name = "NAME", default_value = "all")]
    pub(crate) group: String,
    /// The SRDF named state of `--write-srdf`.
    #[arg(long, value_name = "NAME", default_value = "rest")]
    pub(crate) state: String,
}

/// A joint coordinate given as `JOINT=VALUE` or `JOINT[DOF]=VALUE` to option `--{what}`.
pub(crate) fn coord(s: &str, what: &str) -> anyhow::Result<(String, usize, f64)> {
    let (name, value) = s
        .split_once('=')
        .with_context(|| format!("--{what} {s}: expected JOINT=VALUE"))?;
    let value: f64 = value
        .trim()
        .parse()
        .with_context(|| format!("--{what} {s}: `{value}` is not a number"))?;
    if !value.is_finite() {
        bail!("--{what} {s}: value must be finite");
    }
    let (name, dof) = match name.split_once('[') {
        Some((n, rest)) => {
            let d = rest
                .trim_end_matches(']')
                .parse()
                .with_context(|| format!("--{what} {s}: bad [DOF]"))?;
            (n, d)
        }
        None => (name, 0),
    };
    Ok((name.to_string(), dof, value))
}
