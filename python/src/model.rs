//! `restpose.Model`: a loaded (or built) mechanism, with `check`, `solve` and `verify`.

use crate::convert::serialize;
use crate::errors::{argument, to_py_err};
use crate::options::{self, Values};
use crate::result::Result as PyResult_;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use restpose::export::json::AnalysisResult;
use restpose::export::summary::ModelSummary;
use restpose::urdf::Loaded;
use restpose::verify::{Eigenvalues, Tolerances, Unilaterals};
use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

/// A mechanism loaded from URDF (``restpose.load``, ``restpose.load_string``) or built in
/// code (``restpose.ModelBuilder``). Immutable; solve it with ``Model.solve``.
#[pyclass(frozen, module = "restpose")]
pub(crate) struct Model {
    /// The library's model with the importer's warnings.
    pub(crate) loaded: Arc<Loaded>,
    /// Seconds the import took (reported as `diagnostics.timings.import`).
    pub(crate) import_seconds: f64,
}

impl Model {
    /// A model from the library's.
    pub(crate) fn new(loaded: Loaded, import_seconds: f64) -> Self {
        Model {
            loaded: Arc::new(loaded),
            import_seconds,
        }
    }

    fn model(&self) -> &restpose::Model {
        &self.loaded.model
    }
}

/// Loads a URDF file (with restpose's ``mech:`` extensions).
///
/// Keyword arguments are the command line's input options: ``packages`` maps a
/// ``package://NAME`` to its folder; ``gravity`` [m/s²] applies when the file has no
/// ``<mech:gravity>``; ``floating_base`` frees the root link (its start pose from ``base_xyz``
/// [m] and ``base_rpy`` [rad]); ``ground`` adds the plane z = 0; ``inertia_from_geometry``
/// gives links without ``<inertial>`` the mass of their geometry at this density [kg/m³];
/// ``locks`` holds joint coordinates and ``initial`` sets initial guesses, both as
/// ``{"joint": value}`` (``"joint[1]"`` or a list for several coordinates; a lock of ``None``
/// holds the initial value); ``servos`` holds joints like position servos, ``{"all": K}`` or
/// ``{"JOINT": K}`` or ``{"JOINT": (K, REF)}`` (``--servo``), about the reference pose of
/// ``servo_reference`` (a ``{"joint": value}`` mapping or a pose file) or of ``srdf`` and
/// ``srdf_state`` (an SRDF ``group_state``), which is also the start.
///
/// Raises ``restpose.FileError`` if the file cannot be read, ``restpose.InputError`` (with
/// ``file``, ``line``, ``column``, ``element``) if it is not a valid restpose URDF,
/// ``restpose.UnknownJointError`` for a lock or initial value on a joint the file lacks.
#[pyfunction]
#[pyo3(signature = (path, *, packages=None, gravity=None, floating_base=false, ground=false,
    base_xyz=None, base_rpy=None, inertia_from_geometry=None, locks=None, initial=None,
    servos=None, servo_reference=None, srdf=None, srdf_state=None))]
pub(crate) fn load(
    py: Python<'_>,
    path: PathBuf,
    packages: Option<HashMap<String, PathBuf>>,
    gravity: Option<[f64; 3]>,
    floating_base: bool,
    ground: bool,
    base_xyz: Option<[f64; 3]>,
    base_rpy: Option<[f64; 3]>,
    inertia_from_geometry: Option<f64>,
    locks: Option<HashMap<String, Values>>,
    initial: Option<HashMap<String, Values>>,
    servos: Option<HashMap<String, options::Servo>>,
    servo_reference: Option<Bound<'_, PyAny>>,
    srdf: Option<PathBuf>,
    srdf_state: Option<String>,
) -> PyResult<Model> {
    let mut opts = options::import_options(
        packages,
        gravity,
        floating_base,
        ground,
        base_xyz,
        base_rpy,
        inertia_from_geometry,
        locks,
        initial,
    )?;
    options::add_servos(&mut opts, servos, servo_reference, srdf, srdf_state)?;
    let started = Instant::now();
    let loaded = py
        .detach(|| restpose::urdf::load_file(&path, &opts))
        .map_err(to_py_err)?;
    Ok(Model::new(loaded, started.elapsed().as_secs_f64()))
}

/// Loads URDF text; ``file`` names it in error messages (relative mesh paths are taken from
/// the current folder). Keyword arguments as ``restpose.load``.
#[pyfunction]
#[pyo3(signature = (text, *, file="<string>".to_string(), packages=None, gravity=None,
    floating_base=false, ground=false, base_xyz=None, base_rpy=None, inertia_from_geometry=None,
    locks=None, initial=None, servos=None, servo_reference=None, srdf=None, srdf_state=None))]
pub(crate) fn load_string(
    py: Python<'_>,
    text: String,
    file: String,
    packages: Option<HashMap<String, PathBuf>>,
    gravity: Option<[f64; 3]>,
    floating_base: bool,
    ground: bool,
    base_xyz: Option<[f64; 3]>,
    base_rpy: Option<[f64; 3]>,
    inertia_from_geometry: Option<f64>,
    locks: Option<HashMap<String, Values>>,
    initial: Option<HashMap<String, Values>>,
    servos: Option<HashMap<String, options::Servo>>,
    servo_reference: Option<Bound<'_, PyAny>>,
    srdf: Option<PathBuf>,
    srdf_state: Option<String>,
) -> PyResult<Model> {
    let mut opts = options::import_options(
        packages,
        gravity,
        floating_base,
        ground,
        base_xyz,
        base_rpy,
        inertia_from_geometry,
        locks,
        initial,
    )?;
    options::add_servos(&mut opts, servos, servo_reference, srdf, srdf_state)?;
    let started = Instant::now();
    let loaded = py
        .detach(|| restpose::urdf::load_str(&text, &file, &opts))
        .map_err(to_py_err)?;
    Ok(Model::new(loaded, started.elapsed().as_secs_f64()))
}

/// `restpose._records.CLASS(plain, json)`.
fn record<'py>(
    py: Python<'py>,
    class: &str,
    plain: Bound<'py, PyAny>,
    json: String,
) -> PyResult<Bound<'py, PyAny>> {
    py.import("restpose._records")?
        .getattr(class)?
        .call1((plain, json))
}

/// A pose given to `verify`: a result of this model (its exact state), joint values, or a
/// pose file.
enum Pose {
    State(restpose::State),
    Values(restpose::state::JointValues),
}

#[pymethods]
impl Model {
    /// Robot name (``<robot name>``).
    #[getter]
    fn name(&self) -> &str {
        self.model().name()
    }

    /// Names of every joint, in model order (URDF ``<joint>`` elements in file order, then
    /// loop joints), as in ``Result.joint_names``.
    #[getter]
    fn joint_names(&self) -> Vec<String> {
        self.model()
            .joints()
            .iter()
            .map(|j| j.name.clone())
            .collect()
    }

    /// Names of every link, in model order.
    #[getter]
    fn link_names(&self) -> Vec<String> {
        self.model()
            .links()
            .iter()
            .map(|l| l.name.clone())
            .collect()
    }

    /// Number of moving rigid bodies (links welded by fixed joints are one body).
    #[getter]
    fn body_count(&self) -> usize {
        self.model().bodies().len()
    }

    /// Gravity in the world frame [m/s²].
    #[getter]
    fn gravity(&self) -> [f64; 3] {
        self.model().gravity().into()
    }

    /// The importer's warnings (repaired input, ignored content that may matter).
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.loaded.warnings.clone()
    }

    /// Foreign elements the importer ignored, as ``"LINE:COL <name>"``.
    #[getter]
    fn ignored(&self) -> Vec<String> {
        self.loaded.ignored.clone()
    }

    /// Everything ``restpose check`` says of the model (a ``restpose.CheckReport``: bodies,
    /// joints with their roles, forces, degrees of freedom at the initial guess, assembly
    /// error, warnings); its ``to_json()`` is ``restpose check --format json``.
    fn check<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let summary = py.detach(|| {
            let check = restpose::verify::check(self.model());
            ModelSummary::of_model(&self.loaded).with_check(&check)
        });
        let json = serde_json::to_string_pretty(&summary).map_err(|e| argument(e.to_string()))?;
        record(py, "CheckReport", serialize(py, &summary)?, json)
    }

    /// Solves for the stable rest pose; the GIL is released while the solver runs.
    ///
    /// Keyword arguments are the command line's solver options: ``method`` (``"newton"``,
    /// ``"bfgs"``, ``"dfp"``), ``linear_algebra`` (``"auto"``, ``"dense"``, ``"sparse"``, ``"tree"``),
    /// ``tolerance`` (scaled reduced gradient [J]), ``constraint_tolerance`` (‖DΦ‖∞, dimensionless),
    /// ``max_iterations``, ``load_steps`` (0: automatic), ``allow_unstable``, ``limits``
    /// (``"enforce"``, ``"ignore"``), ``friction`` (``"none"``, ``"stick"``), ``mu``, ``topple``
    /// (a floating group that cannot stand on its ground start topples as a rigid body before
    /// the solve, ``--topple on|off``: see ``Result.topple``).
    ///
    /// Not converging is not an exception: see ``Result.converged``. Raises
    /// ``restpose.AssemblyError`` if the initial guess cannot be assembled,
    /// ``restpose.ConstantEnergyError`` if nothing stores energy, ``restpose.SolveError``
    /// for the other failures.
    #[pyo3(signature = (*, method="newton", linear_algebra="auto", tolerance=1e-8,
        constraint_tolerance=1e-10, max_iterations=200, load_steps=0, allow_unstable=false,
        limits="enforce", friction="none", mu=None, topple=true))]
    fn solve(
        slf: &Bound<'_, Self>,
        method: &str,
        linear_algebra: &str,
        tolerance: f64,
        constraint_tolerance: f64,
        max_iterations: usize,
        load_steps: usize,
        allow_unstable: bool,
        limits: &str,
        friction: &str,
        mu: Option<f64>,
        topple: bool,
    ) -> PyResult<PyResult_> {
        let opts = options::solver_options(
            method,
            linear_algebra,
            tolerance,
            constraint_tolerance,
            max_iterations,
            load_steps,
            allow_unstable,
            limits,
            friction,
            mu,
            topple,
        )?;
        let this = slf.get();
        let loaded = this.loaded.clone();
        let import = this.import_seconds;
        let (state, result) = slf
            .py()
            .detach(move || -> restpose::Result<_> {
                let model = &loaded.model;
                let (state, mut report) = restpose::solve(model, &opts)?;
                report.diagnostics.timings.import = import;
                let started = Instant::now();
                let mut result = AnalysisResult::new(model, &state, &report);
                result.diagnostics.timings.export = started.elapsed().as_secs_f64();
                Ok((state, result))
            })
            .map_err(to_py_err)?;
        Ok(PyResult_::new(slf.clone().unbind(), state, result))
    }

    /// Verifies that ``pose`` is a rest pose without moving it (``restpose verify``): the
    /// pose is a ``restpose.Result`` (of this model: its exact state; of another: its joint
    /// values), a ``{joint: value(s)}`` dict, or a pose file (result JSON, joint map, ROS
    /// joint_states). Returns a ``restpose.Verification`` (``passed``, the effort each joint
    /// needs, …; ``to_json()`` is ``restpose verify --json``). The GIL is released while it
    /// runs. Options as ``restpose verify``.
    #[pyo3(signature = (pose, *, force_tolerance=1e-6, constraint_tolerance=1e-10,
        gap_tolerance=1e-9, limits="enforce", friction="none", mu=None, linear_algebra="auto",
        eigenvalues=false))]
    fn verify<'py>(
        slf: &Bound<'py, Self>,
        pose: &Bound<'py, PyAny>,
        force_tolerance: f64,
        constraint_tolerance: f64,
        gap_tolerance: f64,
        limits: &str,
        friction: &str,
        mu: Option<f64>,
        linear_algebra: &str,
        eigenvalues: bool,
    ) -> PyResult<Bound<'py, PyAny>> {
        let py = slf.py();
        let this = slf.get();
        options::positive(Some(force_tolerance), "force_tolerance")?;
        options::positive(Some(constraint_tolerance), "constraint_tolerance")?;
        options::positive(Some(gap_tolerance), "gap_tolerance")?;
        let tol = Tolerances {
            force: force_tolerance,
            constraint: constraint_tolerance,
            gap: gap_tolerance,
            ..Default::default()
        };
        let uni = Unilaterals {
            limits: options::limits(limits)?,
            friction: options::friction(friction)?,
            mu: options::positive(mu, "mu")?,
        };
        let la = options::linear_algebra(linear_algebra)?;
        let eig = if eigenvalues {
            Eigenvalues::Always
        } else {
            Eigenvalues::WhenCheap
        };
        let pose = if let Ok(r) = pose.cast::<PyResult_>() {
            let r = r.get();
            if Arc::ptr_eq(&r.model.get().loaded, &this.loaded) {
                Pose::State(r.state.clone())
            } else {
                Pose::Values(r.joint_values())
            }
        } else if let Ok(d) = pose.cast::<PyDict>() {
            let mut values = restpose::state::JointValues::new();
            for (k, v) in d.iter() {
                let name: String = k.extract()?;
                let v = match v.extract::<f64>() {
                    Ok(x) => vec![x],
                    Err(_) => v.extract::<Vec<f64>>()?,
                };
                values.insert(name, v);
            }
            Pose::Values(values)
        } else {
            let path: PathBuf = pose.extract().map_err(|_| {
                argument(
                    "pose: expected a restpose.Result, a {joint: value} dict or a pose file path",
                )
            })?;
            Pose::Values(
                py.detach(|| restpose::verify::read_pose(&path))
                    .map_err(to_py_err)?,
            )
        };
        let loaded = this.loaded.clone();
        let v = py
            .detach(move || -> restpose::Result<_> {
                let model = &loaded.model;
                let state = match pose {
                    Pose::State(s) => s,
                    Pose::Values(values) => restpose::verify::pose_state(model, &values)?.0,
                };
                restpose::verify::verify_reporting(model, &state, &tol, &uni, la, eig)
            })
            .map_err(to_py_err)?;
        let json = serde_json::to_string_pretty(&v).map_err(|e| argument(e.to_string()))?;
        record(py, "Verification", serialize(py, &v)?, json)
    }

    fn __repr__(&self) -> String {
        let m = self.model();
        format!(
            "<restpose.Model {:?}: {} bodies, {} joints, {} links>",
            m.name(),
            m.bodies().len(),
            m.joints().len(),
            m.links().len()
        )
    }
}
