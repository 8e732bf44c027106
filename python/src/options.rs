//! Python keyword arguments to the library's options: the importer's
//! ([`restpose::urdf::ImportOptions`]) and the solver's ([`restpose::Options`]), with the
//! command line's names and checks (a tolerance must be positive, at most 1,000 load steps).

use crate::convert::{origin, vector};
use crate::errors::argument;
use pyo3::prelude::*;
use restpose::model::Friction;
use restpose::urdf::ImportOptions;
use restpose::{Limits, LinearAlgebra, Method, Options};
use std::collections::HashMap;
use std::path::PathBuf;

/// Largest number of load steps (as `--load-steps`).
const MAX_LOAD_STEPS: usize = 1000;

/// The value(s) given for a joint in `locks=` / `initial=`: one number (coordinate 0), or one
/// per coordinate (`None`: that coordinate is not given).
#[derive(FromPyObject)]
pub(crate) enum Values {
    /// `None`: for a lock, hold coordinate 0 at its initial value.
    #[pyo3(transparent)]
    One(Option<f64>),
    /// One entry per coordinate.
    #[pyo3(transparent)]
    Many(Vec<Option<f64>>),
}

/// `(joint, dof, value)` triples from a `{"joint": value(s)}` mapping; a key `"joint[1]"`
/// addresses coordinate 1 as on the command line.
pub(crate) fn coordinates(
    map: Option<HashMap<String, Values>>,
    what: &str,
) -> PyResult<Vec<(String, usize, Option<f64>)>> {
    let mut out = Vec::new();
    let mut map: Vec<_> = map.unwrap_or_default().into_iter().collect();
    map.sort_by(|a, b| a.0.cmp(&b.0));
    for (key, values) in map {
        let (name, first) = match key.split_once('[') {
            Some((n, rest)) => {
                let dof = rest
                    .strip_suffix(']')
                    .and_then(|d| d.trim().parse::<usize>().ok())
                    .ok_or_else(|| {
                        argument(format!("{what} `{key}`: expected JOINT or JOINT[DOF]"))
                    })?;
                (n.to_string(), dof)
            }
            None => (key.clone(), 0),
        };
        match values {
            Values::One(v) => out.push((name, first, v)),
            Values::Many(vs) => {
                for (i, v) in vs.into_iter().enumerate() {
                    if v.is_some() {
                        out.push((name.clone(), first + i, v));
                    }
                }
            }
        }
    }
    if let Some((name, dof, Some(v))) = out
        .iter()
        .find(|(_, _, v)| v.is_some_and(|v| !v.is_finite()))
    {
        return Err(argument(format!(
            "{what} `{name}[{dof}]` = {v}: values must be finite"
        )));
    }
    Ok(out)
}

/// The importer's options from `load`'s keyword arguments.
pub(crate) fn import_options(
    packages: Option<HashMap<String, PathBuf>>,
    gravity: Option<[f64; 3]>,
    floating_base: bool,
    ground: bool,
    base_xyz: Option<[f64; 3]>,
    base_rpy: Option<[f64; 3]>,
    inertia_from_geometry: Option<f64>,
    locks: Option<HashMap<String, Values>>,
    initial: Option<HashMap<String, Values>>,
) -> PyResult<ImportOptions> {
    let mut opts = ImportOptions {
        floating_base,
        ground,
        inertia_density: positive(inertia_from_geometry, "inertia_from_geometry")?,
        ..Default::default()
    };
    if let Some(g) = gravity {
        finite(&g, "gravity")?;
        opts.gravity = vector(g);
    }
    if base_xyz.is_some() || base_rpy.is_some() {
        finite(&base_xyz.unwrap_or_default(), "base_xyz")?;
        finite(&base_rpy.unwrap_or_default(), "base_rpy")?;
        if base_xyz.is_some() {
            opts.base_pose = Some(origin(base_xyz, base_rpy));
        } else {
            // The orientation given, the position found by the ground start (as the CLI).
            opts.base_orientation = Some(origin(None, base_rpy).rotation);
        }
    }
    let mut packages: Vec<_> = packages.unwrap_or_default().into_iter().collect();
    packages.sort();
    opts.packages = packages;
    opts.locks = coordinates(locks, "lock")?;
    for (name, dof, value) in coordinates(initial, "initial value")? {
        let value = value.ok_or_else(|| argument(format!("initial value `{name}`: None")))?;
        opts.initial.push((name, dof, value));
    }
    Ok(opts)
}

/// A servo's value in `load`'s `servos`: a stiffness, or a stiffness and a reference.
#[derive(FromPyObject)]
pub(crate) enum Servo {
    /// `K` [N m/rad or N/m].
    Stiffness(f64),
    /// `(K, REF)`.
    About(f64, f64),
}

/// The servo options of `load` (the command line's `--servo`, `--servo-reference`, `--srdf`
/// and `--srdf-state`) added to `opts`: `servos` maps `"all"` or a joint to a stiffness or a
/// `(stiffness, reference)` pair (`"all"` first, then the joints, as later `--servo` options
/// override earlier ones); `servo_reference` is a `{joint: value}` mapping or a pose file.
pub(crate) fn add_servos(
    opts: &mut ImportOptions,
    servos: Option<HashMap<String, Servo>>,
    servo_reference: Option<Bound<'_, PyAny>>,
    srdf: Option<PathBuf>,
    srdf_state: Option<String>,
) -> PyResult<()> {
    let mut servos: Vec<(String, Servo)> = servos.unwrap_or_default().into_iter().collect();
    servos.sort_by(|a, b| (a.0 != "all", &a.0).cmp(&(b.0 != "all", &b.0)));
    for (name, value) in servos {
        let (stiffness, reference) = match value {
            Servo::Stiffness(k) => (k, None),
            Servo::About(k, r) => (k, Some(r)),
        };
        finite(
            &[stiffness, reference.unwrap_or(0.0)],
            &format!("servo `{name}`"),
        )?;
        opts.servos.push(restpose::urdf::ServoRequest {
            joint: (name != "all").then_some(name),
            stiffness,
            reference,
        });
    }
    if let Some(r) = servo_reference {
        if let Ok(values) = r.extract::<HashMap<String, f64>>() {
            let mut named: Vec<(String, f64)> = values.into_iter().collect();
            named.sort_by(|a, b| a.0.cmp(&b.0));
            finite(
                &named.iter().map(|x| x.1).collect::<Vec<_>>(),
                "servo_reference",
            )?;
            opts.servo_reference.extend(named);
        } else {
            let path: PathBuf = r.extract().map_err(|_| {
                argument("servo_reference: expected a {joint: value} mapping or a pose file")
            })?;
            opts.servo_reference.extend(
                restpose::verify::read_reference_pose(&path).map_err(crate::errors::to_py_err)?,
            );
        }
    }
    match (srdf, srdf_state) {
        (Some(path), Some(state)) => opts
            .servo_reference
            .extend(restpose::urdf::srdf_state(&path, &state).map_err(crate::errors::to_py_err)?),
        (None, None) => {}
        _ => return Err(argument("srdf and srdf_state go together")),
    }
    Ok(())
}

fn finite(v: &[f64], what: &str) -> PyResult<()> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(argument(format!(
            "{what}: values must be finite, got {v:?}"
        )))
    }
}

/// A positive finite number, or `None`.
pub(crate) fn positive(v: Option<f64>, what: &str) -> PyResult<Option<f64>> {
    match v {
        Some(x) if !(x.is_finite() && x > 0.0) => Err(argument(format!(
            "{what} = {x}: must be a positive finite number"
        ))),
        _ => Ok(v),
    }
}

/// `"newton"`, `"bfgs"`, `"dfp"`.
pub(crate) fn method(s: &str) -> PyResult<Method> {
    match s.to_ascii_lowercase().as_str() {
        "newton" => Ok(Method::Newton),
        "bfgs" => Ok(Method::Bfgs),
        "dfp" => Ok(Method::Dfp),
        _ => Err(argument(format!(
            "method = {s:?}: expected \"newton\", \"bfgs\" or \"dfp\""
        ))),
    }
}

/// `"auto"`, `"dense"`, `"sparse"`, `"tree"`.
pub(crate) fn linear_algebra(s: &str) -> PyResult<LinearAlgebra> {
    match s.to_ascii_lowercase().as_str() {
        "auto" => Ok(LinearAlgebra::Auto),
        "dense" => Ok(LinearAlgebra::Dense),
        "sparse" => Ok(LinearAlgebra::Sparse),
        "tree" => Ok(LinearAlgebra::Tree),
        _ => Err(argument(format!(
            "linear_algebra = {s:?}: expected \"auto\", \"dense\", \"sparse\" or \"tree\""
        ))),
    }
}

/// `"enforce"`, `"ignore"`.
pub(crate) fn limits(s: &str) -> PyResult<Limits> {
    match s.to_ascii_lowercase().as_str() {
        "enforce" => Ok(Limits::Enforce),
        "ignore" => Ok(Limits::Ignore),
        _ => Err(argument(format!(
            "limits = {s:?}: expected \"enforce\" or \"ignore\""
        ))),
    }
}

/// `"none"`, `"stick"`.
pub(crate) fn friction(s: &str) -> PyResult<Friction> {
    match s.to_ascii_lowercase().as_str() {
        "none" => Ok(Friction::None),
        "stick" => Ok(Friction::Stick),
        _ => Err(argument(format!(
            "friction = {s:?}: expected \"none\" or \"stick\""
        ))),
    }
}

/// The solver's options from `solve`'s keyword arguments.
pub(crate) fn solver_options(
    method_name: &str,
    linear_algebra_name: &str,
    tolerance: f64,
    constraint_tolerance: f64,
    max_iterations: usize,
    load_steps: usize,
    allow_unstable: bool,
    limits_name: &str,
    friction_name: &str,
    mu: Option<f64>,
    topple: bool,
) -> PyResult<Options> {
    positive(Some(tolerance), "tolerance")?;
    positive(Some(constraint_tolerance), "constraint_tolerance")?;
    if load_steps > MAX_LOAD_STEPS {
        return Err(argument(format!(
            "load_steps = {load_steps}: at most {MAX_LOAD_STEPS}"
        )));
    }
    Ok(Options {
        method: method(method_name)?,
        linear_algebra: linear_algebra(linear_algebra_name)?,
        gradient_tolerance: tolerance,
        constraint_tolerance,
        max_iterations,
        load_steps,
        allow_unstable,
        limits: limits(limits_name)?,
        friction: friction(friction_name)?,
        mu: positive(mu, "mu")?,
        topple: if topple {
            restpose::Topple::On
        } else {
            restpose::Topple::Off
        },
        ..Default::default()
    })
}
