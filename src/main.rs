//! The `restpose` command line.

use anyhow::{bail, Context};
use clap::{Parser, Subcommand, ValueEnum};
use restpose::export::json::AnalysisResult;
use restpose::urdf::{load_file, ImportOptions};
use restpose::{LinearAlgebra, Method, Options};
use std::path::PathBuf;
use std::process::ExitCode;

/// Writes a line to standard output; a closed pipe (`restpose analyze … | head`) is not an
/// error and must not panic.
macro_rules! out {
    ($($arg:tt)*) => {{
        use std::io::Write;
        let _ = writeln!(std::io::stdout().lock(), $($arg)*);
    }};
}

/// Exit code when the solve did not converge.
const EXIT_NOT_CONVERGED: u8 = 3;
/// Exit code for invalid input.
const EXIT_INPUT: u8 = 1;
/// Exit code when `verify` finds the pose is not a rest pose.
const EXIT_NOT_BALANCED: u8 = 4;

#[derive(Parser)]
#[command(
    name = "restpose",
    version,
    about = "Static equilibrium (rest pose) of URDF mechanisms"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Solve for the stable rest pose and print a summary.
    Analyze(AnalyzeArgs),
    /// Load and validate a file without solving; print the model as understood.
    Check(CheckArgs),
    /// Solve and open the rest pose in the rerun viewer (feature `viewer`).
    View(AnalyzeArgs),
    /// Check whether a given pose is a rest pose, without moving it.
    Verify(VerifyArgs),
    /// Write a generated benchmark mechanism (URDF) to standard output.
    Generate {
        /// Family.
        #[arg(value_enum)]
        family: Family,
        /// Number of links (chains) or loops (ladder).
        #[arg(long, default_value_t = 20)]
        size: usize,
    },
}

#[derive(clap::Args, Clone)]
struct InputArgs {
    /// Gravity [m/s²] when the file has no <mech:gravity>.
    #[arg(long, num_args = 3, value_names = ["X", "Y", "Z"], allow_hyphen_values = true)]
    gravity: Option<Vec<f64>>,
    /// Where `package://NAME/…` meshes live (repeatable).
    #[arg(long, value_name = "NAME=DIR")]
    package: Vec<String>,
    /// Give links without <inertial> the mass properties of their collision (else visual)
    /// geometry at this density [kg/m³].
    #[arg(long, value_name = "DENSITY")]
    inertia_from_geometry: Option<f64>,
    /// Leave the root link free instead of welding it to the world.
    #[arg(long)]
    floating_base: bool,
}

impl InputArgs {
    fn options(&self) -> anyhow::Result<ImportOptions> {
        let mut opts = ImportOptions {
            floating_base: self.floating_base,
            inertia_density: self.inertia_from_geometry,
            ..Default::default()
        };
        if let Some(g) = &self.gravity {
            opts.gravity = nalgebra::Vector3::new(g[0], g[1], g[2]);
        }
        for p in &self.package {
            let (n, d) = p
                .split_once('=')
                .with_context(|| format!("--package {p}: expected NAME=DIR"))?;
            opts.packages.push((n.to_string(), PathBuf::from(d)));
        }
        if let Some(d) = self.inertia_from_geometry {
            if !(d.is_finite() && d > 0.0) {
                bail!("--inertia-from-geometry {d}: the density must be positive");
            }
        }
        Ok(opts)
    }
}

#[derive(clap::Args)]
struct CheckArgs {
    /// URDF file.
    file: PathBuf,
    #[command(flatten)]
    input: InputArgs,
    /// Output format.
    #[arg(long, value_enum, default_value = "text")]
    format: Format,
    /// Also list ignored foreign elements.
    #[arg(long, short)]
    verbose: bool,
}

#[derive(Clone, Copy, ValueEnum)]
enum Format {
    Text,
    Json,
}

#[derive(clap::Args)]
struct VerifyArgs {
    /// URDF file.
    file: PathBuf,
    /// Pose: restpose result JSON, a {"joint": value} JSON map, or ROS joint_states-style
    /// YAML/JSON (`name` and `position` lists).
    #[arg(long, value_name = "POSE")]
    pose: Option<PathBuf>,
    /// Joint value (repeatable; overrides the pose file): JOINT=VALUE or JOINT[DOF]=VALUE.
    #[arg(long, value_name = "JOINT=VALUE")]
    joint: Vec<String>,
    /// Largest effort a joint may need for the pose to pass [N m or N].
    #[arg(long, default_value_t = 1e-6)]
    force_tolerance: f64,
    /// Largest constraint violation for the pose to pass [m or rad].
    #[arg(long, default_value_t = 1e-8)]
    constraint_tolerance: f64,
    /// Write the verification as JSON to this file (`-` for standard output).
    #[arg(long, value_name = "OUT.json")]
    json: Option<PathBuf>,
    #[command(flatten)]
    input: InputArgs,
    /// Print only errors and the verdict.
    #[arg(long, short)]
    quiet: bool,
}

#[derive(Clone, Copy, ValueEnum)]
enum Family {
    /// N-link spatial pendulum chain with joint springs (alternating joint axes).
    Chain,
    /// N-link planar chain (all axes parallel) with joint springs.
    PlanarChain,
    /// Ladder of N closed four-bar loops.
    Ladder,
}

#[derive(Clone, Copy, ValueEnum, Debug)]
enum LinearAlgebraArg {
    Auto,
    Dense,
    Sparse,
}

#[derive(Clone, Copy, ValueEnum, Debug)]
enum MethodArg {
    Newton,
    Bfgs,
    Dfp,
}

#[derive(clap::Args, Clone)]
struct AnalyzeArgs {
    /// URDF file.
    file: PathBuf,
    /// Write the result JSON here (written even when the solve does not converge).
    #[arg(long, value_name = "OUT.json")]
    json: Option<PathBuf>,
    #[command(flatten)]
    input: InputArgs,
    /// Hold a joint coordinate: JOINT=VALUE or JOINT[DOF]=VALUE (repeatable).
    #[arg(long, value_name = "JOINT=VALUE")]
    lock: Vec<String>,
    /// Initial guess of a joint coordinate: JOINT=VALUE or JOINT[DOF]=VALUE (repeatable).
    #[arg(long, value_name = "JOINT=VALUE")]
    initial: Vec<String>,
    /// Write a rerun recording (.rrd) of the rest pose and the search (feature `viewer`).
    #[arg(long, value_name = "OUT.rrd")]
    rrd: Option<PathBuf>,
    /// Write the input file with the rest pose as `mech:initial` values (only when converged).
    #[arg(long, value_name = "OUT.urdf")]
    write_urdf: Option<PathBuf>,
    /// Write the rest pose as ROS joint_states-style YAML (only when converged).
    #[arg(long, value_name = "OUT.yaml")]
    write_joint_states: Option<PathBuf>,
    /// Maximum minimizer iterations.
    #[arg(long, default_value_t = 200)]
    max_iterations: usize,
    /// Tolerance on the scaled reduced gradient [J].
    #[arg(long, default_value_t = 1e-8)]
    tolerance: f64,
    /// Tolerance on the constraint residual ‖Φ‖∞.
    #[arg(long, default_value_t = 1e-10)]
    constraint_tolerance: f64,
    /// Minimizer.
    #[arg(long, value_enum, default_value = "newton")]
    method: MethodArg,
    /// Linear algebra: dense matrices (small models), sparse (partition body by body, faer
    /// sparse LU, Newton steps from the sparse KKT system), or auto: sparse above 40 bodies.
    #[arg(long, value_enum, default_value = "auto")]
    linear_algebra: LinearAlgebraArg,
    /// Ramp gravity, loads and efforts in N steps (0: automatic, 8 steps only if the direct
    /// solve fails; 1: never).
    #[arg(long, default_value_t = 0, value_name = "N")]
    load_steps: usize,
    /// Stop at an unstable stationary point instead of leaving it.
    #[arg(long)]
    allow_unstable: bool,
    /// Print only errors.
    #[arg(long, short)]
    quiet: bool,
    /// Also list ignored foreign elements.
    #[arg(long, short)]
    verbose: bool,
}

fn coord(s: &str, what: &str) -> anyhow::Result<(String, usize, f64)> {
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

fn analyze(a: &AnalyzeArgs) -> anyhow::Result<u8> {
    let mut opts = a.input.options()?;
    for l in &a.lock {
        let (n, d, v) = coord(l, "lock")?;
        opts.locks.push((n, d, Some(v)));
    }
    for l in &a.initial {
        opts.initial.push(coord(l, "initial")?);
    }
    let loaded = load_file(&a.file, &opts)?;
    if !a.quiet {
        for w in &loaded.warnings {
            eprintln!("warning: {w}");
        }
        if a.verbose {
            for i in &loaded.ignored {
                eprintln!("ignored: {}:{i}", a.file.display());
            }
        }
    }
    let options = Options {
        record_iterates: a.rrd.is_some(),
        method: match a.method {
            MethodArg::Newton => Method::Newton,
            MethodArg::Bfgs => Method::Bfgs,
            MethodArg::Dfp => Method::Dfp,
        },
        linear_algebra: match a.linear_algebra {
            LinearAlgebraArg::Auto => LinearAlgebra::Auto,
            LinearAlgebraArg::Dense => LinearAlgebra::Dense,
            LinearAlgebraArg::Sparse => LinearAlgebra::Sparse,
        },
        gradient_tolerance: a.tolerance,
        constraint_tolerance: a.constraint_tolerance,
        max_iterations: a.max_iterations,
        allow_unstable: a.allow_unstable,
        load_steps: a.load_steps,
        ..Default::default()
    };
    let model = &loaded.model;
    let (state, report) = restpose::solve(model, &options).map_err(|e| match e {
        restpose::Error::ConstantEnergy { .. } if a.input.inertia_from_geometry.is_none() => {
            anyhow::anyhow!("{e}; links without <inertial> can get masses from their geometry with --inertia-from-geometry DENSITY")
        }
        e => e.into(),
    })?;
    let result = AnalysisResult::new(model, &state, &report);
    if let Some(path) = &a.json {
        restpose::export::write_atomic(path, result.to_json().as_bytes())?;
    }
    if let Some(path) = &a.rrd {
        write_rrd(path, model, &state, &report)?;
    }
    if result.converged {
        if let Some(path) = &a.write_urdf {
            let text = std::fs::read_to_string(&a.file)
                .with_context(|| format!("{}", a.file.display()))?;
            let out = restpose::urdf::with_initial_pose(
                &text,
                &a.file.display().to_string(),
                model,
                &state,
            )?;
            restpose::export::write_atomic(path, out.as_bytes())?;
        }
        if let Some(path) = &a.write_joint_states {
            let out = restpose::export::joint_states::joint_states_yaml(model, &state);
            restpose::export::write_atomic(path, out.as_bytes())?;
        }
    } else if a.write_urdf.is_some() || a.write_joint_states.is_some() {
        eprintln!(
            "note: --write-urdf / --write-joint-states are written only for a converged rest pose"
        );
    }
    if !a.quiet {
        print_summary(&result);
    }
    if !result.converged {
        eprintln!(
            "error: {}: did not converge ({}) after {} iterations; ‖∂V/∂v‖∞ = {:.3e}, ‖Φ‖∞ = {:.3e}, corrector failures {}, step halvings {}, re-partitions {}",
            a.file.display(),
            result.termination,
            result.iterations,
            result.diagnostics.gradient_norm,
            result.diagnostics.constraint_residual,
            result.diagnostics.corrector_failures,
            result.diagnostics.step_halvings,
            result.diagnostics.repartitions
        );
        if !result.diagnostics.free_directions.is_empty() {
            eprintln!(
                "  the energy falls without bound along: {}",
                result.diagnostics.free_directions.join(", ")
            );
        }
        return Ok(EXIT_NOT_CONVERGED);
    }
    Ok(0)
}

fn verify(a: &VerifyArgs) -> anyhow::Result<u8> {
    let loaded = load_file(&a.file, &a.input.options()?)?;
    let model = &loaded.model;
    let mut values = match &a.pose {
        Some(p) => restpose::verify::read_pose(p)?,
        None => Default::default(),
    };
    for j in &a.joint {
        let (name, dof, value) = coord(j, "joint")?;
        let id = model
            .joint_id(&name)
            .with_context(|| format!("--joint {j}: the model has no joint `{name}`"))?;
        let n = model.joint(id).kind.scalar_coordinates().max(dof + 1);
        let v = values.entry(name).or_insert_with(|| vec![0.0; n]);
        if v.len() <= dof {
            v.resize(dof + 1, 0.0);
        }
        v[dof] = value;
    }
    if values.is_empty() {
        bail!("give the pose with --pose FILE or --joint NAME=VALUE");
    }
    let (state, missing) = restpose::verify::pose_state(model, &values)?;
    if !a.quiet && !missing.is_empty() {
        eprintln!(
            "warning: joints not in the pose keep their initial values: {}",
            missing.join(", ")
        );
    }
    let tol = restpose::verify::Tolerances {
        force: a.force_tolerance,
        constraint: a.constraint_tolerance,
    };
    let v = restpose::verify::verify(model, &state, &tol)?;
    if let Some(path) = &a.json {
        let text = serde_json::to_string_pretty(&v)?;
        if path.as_os_str() == "-" {
            out!("{text}");
        } else {
            restpose::export::write_atomic(path, text.as_bytes())?;
        }
    }
    let stdout_json = a.json.as_ref().is_some_and(|p| p.as_os_str() == "-");
    if !a.quiet && !stdout_json {
        out!(
            "robot `{}`: pose {}",
            model.name,
            if v.passed { "PASSES" } else { "FAILS" }
        );
        out!(
            "  constraint residual {:.3e} (tolerance {:.1e}), potential energy {:.9} J",
            v.constraint_residual,
            tol.constraint,
            v.potential_energy
        );
        for c in &v.closure {
            out!(
                "  {} `{}`: position error {:.3e} m, rotation error {:.3e} rad",
                if c.loop_joint { "loop joint" } else { "joint" },
                c.joint,
                c.position_error,
                c.rotation_error
            );
        }
        out!("  joint                          dof   effort to hold [N m or N]");
        for i in &v.imbalance {
            let flag = if i.effort.abs() > tol.force {
                "  <- out of balance"
            } else {
                ""
            };
            out!("  {:<30} {:>3}   {:>14.6e}{flag}", i.joint, i.dof, i.effort);
        }
        if v.unassigned > tol.force {
            out!(
                "  unassigned generalized force {:.3e} (spherical or floating joints)",
                v.unassigned
            );
        }
        if let Some(s) = &v.stability {
            out!("  stability: {}", s.verdict);
        }
    }
    if v.passed {
        Ok(0)
    } else {
        if let Some(m) = &v.max_imbalance {
            eprintln!(
                "{}: not a rest pose: largest imbalance {:.3e} at joint `{}` (dof {}), constraint residual {:.3e}",
                a.file.display(),
                m.effort,
                m.joint,
                m.dof,
                v.constraint_residual
            );
        } else {
            eprintln!(
                "{}: not a rest pose: constraint residual {:.3e}",
                a.file.display(),
                v.constraint_residual
            );
        }
        Ok(EXIT_NOT_BALANCED)
    }
}

#[cfg(feature = "viewer")]
fn write_rrd(
    path: &std::path::Path,
    model: &restpose::Model,
    state: &restpose::State,
    report: &restpose::Report,
) -> anyhow::Result<()> {
    restpose::view::write_recording(path, model, state, report)?;
    Ok(())
}

#[cfg(not(feature = "viewer"))]
fn write_rrd(
    path: &std::path::Path,
    _: &restpose::Model,
    _: &restpose::State,
    _: &restpose::Report,
) -> anyhow::Result<()> {
    bail!(
        "{}: this restpose was built without the `viewer` feature; rebuild with `cargo build --release --features viewer`",
        path.display()
    )
}

/// `restpose view`: solve, write a recording next to the input, open it in `rerun`.
fn view(a: &AnalyzeArgs) -> anyhow::Result<u8> {
    let rrd = a
        .rrd
        .clone()
        .unwrap_or_else(|| a.file.with_extension("rrd"));
    let mut args = AnalyzeArgs {
        rrd: Some(rrd.clone()),
        ..a.clone()
    };
    args.quiet = true;
    let code = analyze(&args)?;
    eprintln!("wrote {}", rrd.display());
    match std::process::Command::new("rerun").arg(&rrd).spawn() {
        Ok(_) => eprintln!("opened it in the rerun viewer"),
        Err(_) => eprintln!(
            "the `rerun` viewer is not on the PATH: `pip install rerun-sdk==0.36.3`, then `rerun {}`",
            rrd.display()
        ),
    }
    Ok(code)
}

fn check(a: &CheckArgs) -> anyhow::Result<u8> {
    let loaded = load_file(&a.file, &a.input.options()?)?;
    let s = restpose::export::summary::ModelSummary::new(&loaded);
    if let Format::Json = a.format {
        out!("{}", serde_json::to_string_pretty(&s)?);
    } else {
        out!(
            "robot `{}`: {} bodies, {} coordinates, {} constraint rows, {}",
            s.robot,
            s.bodies.len(),
            s.coordinates,
            s.constraints,
            s.dof.map_or(
                "does not assemble at the initial guess".to_string(),
                |d| format!("{d} degrees of freedom")
            )
        );
        out!(
            "  gravity [{}, {}, {}] m/s²",
            s.gravity[0],
            s.gravity[1],
            s.gravity[2]
        );
        out!(
            "  links welded to the world: {}",
            if s.fixed_links.is_empty() {
                "none".to_string()
            } else {
                s.fixed_links.join(", ")
            }
        );
        out!("  bodies:");
        for b in &s.bodies {
            out!(
                "    {:<28} {:>10.4} kg   links: {}",
                b.name,
                b.mass,
                b.links.join(", ")
            );
        }
        out!("  joints:");
        for j in &s.joints {
            out!(
                "    {:<28} {:<13} {:<7} {} -> {}  ({} rows)",
                j.name,
                j.kind,
                j.role,
                j.parent,
                j.child,
                j.rows
            );
        }
        for sp in &s.springs {
            out!("  spring {sp}");
        }
        for f in &s.forces {
            out!("  {f}");
        }
        if let Some(e) = &s.assembly_error {
            out!("  assembly: {e}");
        }
    }
    if !matches!(a.format, Format::Json) {
        for w in &s.warnings {
            eprintln!("warning: {w}");
        }
        if a.verbose {
            for i in &s.ignored {
                eprintln!("ignored: {}:{i}", a.file.display());
            }
        }
    }
    Ok(if s.assembly_error.is_some() {
        EXIT_INPUT
    } else {
        0
    })
}

fn print_summary(r: &AnalysisResult) {
    out!("robot `{}`", r.robot);
    out!(
        "  bodies {}, coordinates {}, constraint rows {} ({} redundant), degrees of freedom {}",
        r.bodies,
        r.coordinates,
        r.constraints,
        r.redundant_constraints.len(),
        r.dof
    );
    if !r.redundant_constraints.is_empty() {
        out!(
            "  redundant constraints: {}",
            r.redundant_constraints.join(", ")
        );
    }
    out!(
        "  independent coordinates: {}",
        r.independent_coordinates.join(", ")
    );
    out!();
    out!("  iteration   potential energy [J]   ‖∂V/∂v‖∞ [J]");
    for h in &r.history {
        out!(
            "  {:>9}   {:>20.9}   {:>12.3e}",
            h.iteration,
            h.potential_energy,
            h.gradient_norm
        );
    }
    out!();
    out!(
        "  {}: {} iterations, V = {:.9} J",
        r.termination,
        r.iterations,
        r.potential_energy
    );
    if let Some(s) = &r.stability {
        let eig: Vec<String> = s.eigenvalues.iter().map(|e| format!("{e:.4e}")).collect();
        out!(
            "  stability: {} (smallest reduced-Hessian eigenvalues {})",
            s.verdict,
            eig.join(", ")
        );
    }
    if let Some(mode) = r.stability.as_ref().and_then(|s| s.modes.first()) {
        let mut parts: Vec<(&String, f64)> = mode
            .iter()
            .flat_map(|(n, v)| v.iter().map(move |x| (n, *x)))
            .collect();
        parts.sort_by(|a, b| b.1.abs().total_cmp(&a.1.abs()));
        let shown: Vec<String> = parts
            .iter()
            .take(4)
            .map(|(n, x)| format!("{n} {x:+.3}"))
            .collect();
        out!(
            "  softest mode: {}{}",
            shown.join(", "),
            if parts.len() > 4 { ", …" } else { "" }
        );
    }
    out!();
    out!("  joint                          type          position");
    for (name, j) in &r.joints {
        let p: Vec<String> = j.position.iter().map(|v| format!("{v:.9}")).collect();
        out!("  {:<30} {:<13} [{}]", name, j.kind, p.join(", "));
    }
    for v in &r.limit_violations {
        out!(
            "  warning: joint `{}` rests at {:.6}, outside its limits [{}, {}] (limits are not enforced)",
            v.joint, v.position, v.limits[0], v.limits[1]
        );
    }
    if !r.reactions.is_empty() {
        out!();
        out!("  reaction on child at joint origin (world)   force [N]                          torque [N m]");
        for (name, re) in &r.reactions {
            let f = re.force_world;
            let t = re.torque_world;
            out!(
                "  {:<30} [{:>10.4}, {:>10.4}, {:>10.4}]   [{:>10.4}, {:>10.4}, {:>10.4}]",
                name,
                f[0],
                f[1],
                f[2],
                t[0],
                t[1],
                t[2]
            );
        }
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let out = match &cli.command {
        Command::Analyze(a) => analyze(a),
        Command::View(a) => view(a),
        Command::Verify(a) => verify(a),
        Command::Check(a) => check(a),
        Command::Generate { family, size } => {
            let text = match family {
                Family::Chain => restpose::generate::chain(*size, false),
                Family::PlanarChain => restpose::generate::chain(*size, true),
                Family::Ladder => restpose::generate::ladder(*size),
            };
            {
                use std::io::Write;
                let _ = std::io::stdout().lock().write_all(text.as_bytes());
            }
            Ok(0)
        }
    };
    match out {
        Ok(code) => ExitCode::from(code),
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(EXIT_INPUT)
        }
    }
}
