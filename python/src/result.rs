//! `restpose.Result`: a solve's outcome. Joint values and link frames come as numpy arrays;
//! the rest of the report (energy, stability, reactions, contacts, …) as plain Python values
//! that `restpose/_records.py` wraps; `to_json` is the command line's result JSON.

use crate::convert::{homogeneous, serialize};
use crate::model::Model;
use numpy::ndarray::{Array2, Array3};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray3};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use restpose::export::json::AnalysisResult;

/// A position and a quaternion.
type Pair<'py> = (Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>);

/// The outcome of ``Model.solve``: the rest pose (or where the solver stopped) and the
/// solver's report.
#[pyclass(frozen, module = "restpose")]
pub(crate) struct Result {
    /// The model solved.
    pub(crate) model: Py<Model>,
    /// The final state (7 coordinates per body).
    pub(crate) state: restpose::State,
    /// The result as the command line writes it.
    pub(crate) result: AnalysisResult,
}

impl Result {
    /// A result of `model`.
    pub(crate) fn new(model: Py<Model>, state: restpose::State, result: AnalysisResult) -> Self {
        Result {
            model,
            state,
            result,
        }
    }

    /// Every joint's values by name.
    pub(crate) fn joint_values(&self) -> restpose::state::JointValues {
        self.result
            .joints
            .iter()
            .map(|(n, j)| (n.clone(), j.position.clone()))
            .collect()
    }

    fn link_index(&self, name: &str) -> PyResult<usize> {
        self.result
            .links
            .iter()
            .position(|(n, _)| n == name)
            .ok_or_else(|| {
                pyo3::exceptions::PyKeyError::new_err(format!("the model has no link `{name}`"))
            })
    }

    /// Link `i`'s frame in the world.
    fn link_pose(&self, i: usize) -> nalgebra::Isometry3<f64> {
        let l = &self.result.links[i].1;
        let [w, x, y, z] = l.orientation_wxyz;
        nalgebra::Isometry3::from_parts(
            nalgebra::Translation3::new(l.position[0], l.position[1], l.position[2]),
            nalgebra::UnitQuaternion::new_unchecked(nalgebra::Quaternion::new(w, x, y, z)),
        )
    }
}

#[pymethods]
impl Result {
    /// The model solved.
    #[getter]
    fn model(&self, py: Python<'_>) -> Py<Model> {
        self.model.clone_ref(py)
    }

    /// Robot name.
    #[getter]
    fn robot(&self) -> &str {
        &self.result.robot
    }

    /// Whether the solve converged to a rest pose.
    #[getter]
    fn converged(&self) -> bool {
        self.result.converged
    }

    /// Why the solver stopped: ``"converged"``, ``"max_iterations"``,
    /// ``"line_search_failed"`` or ``"unbounded"``.
    #[getter]
    fn termination(&self) -> &str {
        &self.result.termination
    }

    /// Minimizer iterations.
    #[getter]
    fn iterations(&self) -> usize {
        self.result.iterations
    }

    /// Potential energy at the result [J].
    #[getter]
    fn potential_energy(&self) -> f64 {
        self.result.potential_energy
    }

    /// Degrees of freedom.
    #[getter]
    fn dof(&self) -> usize {
        self.result.dof
    }

    /// Whether a sticking contact needs more friction than its coefficient ``mu``.
    #[getter]
    fn slipping(&self) -> bool {
        self.result.slipping
    }

    /// Names of the joints, in model order (the order of ``q`` and ``joints``).
    #[getter]
    fn joint_names(&self) -> Vec<String> {
        self.result.joints.iter().map(|(n, _)| n.clone()).collect()
    }

    /// Every joint's coordinates concatenated in model order [rad or m; a spherical joint's
    /// quaternion ``w x y z``; a floating joint's ``x y z w qx qy qz``; nothing for fixed
    /// joints]; ``joint_slices`` says which entries belong to which joint.
    #[getter]
    fn q<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let q: Vec<f64> = (self.result.joints.iter())
            .flat_map(|(_, j)| j.position.iter().copied())
            .collect();
        q.into_pyarray(py)
    }

    /// ``{joint: slice}``: where each joint's coordinates are in ``q``.
    #[getter]
    fn joint_slices<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        let mut at = 0;
        for (n, j) in &self.result.joints {
            let end = at + j.position.len();
            d.set_item(
                n,
                pyo3::types::PySlice::new(py, at as isize, end as isize, 1),
            )?;
            at = end;
        }
        Ok(d)
    }

    /// ``{joint: array}``: every joint's coordinates, in model order.
    #[getter]
    fn joints<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (n, j) in &self.result.joints {
            d.set_item(n, PyArray1::from_slice(py, &j.position))?;
        }
        Ok(d)
    }

    /// The coordinates of joint ``name`` (an array: one value for a revolute or prismatic
    /// joint). Raises ``restpose.UnknownJointError`` (with a suggestion) for an unknown name.
    fn joint<'py>(&self, py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyArray1<f64>>> {
        match self.result.joints.iter().find(|(n, _)| n == name) {
            Some((_, j)) => Ok(PyArray1::from_slice(py, &j.position)),
            None => Err(crate::errors::to_py_err(
                self.model.get().loaded.model.unknown_joint("joint", name),
            )),
        }
    }

    /// Names of the links, in model order (the rows of the ``link_*`` arrays).
    #[getter]
    fn link_names(&self) -> Vec<String> {
        self.result.links.iter().map(|(n, _)| n.clone()).collect()
    }

    /// Link frame origins in the world, one row per link [m] (shape ``(links, 3)``).
    #[getter]
    fn link_positions<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let v: Vec<f64> = (self.result.links.iter())
            .flat_map(|(_, l)| l.position)
            .collect();
        Array2::from_shape_vec((self.result.links.len(), 3), v)
            .expect("3 numbers per link")
            .into_pyarray(py)
    }

    /// Link orientations as unit quaternions ``w x y z`` with ``w ≥ 0`` (shape ``(links, 4)``).
    #[getter]
    fn link_quaternions<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let v: Vec<f64> = (self.result.links.iter())
            .flat_map(|(_, l)| l.orientation_wxyz)
            .collect();
        Array2::from_shape_vec((self.result.links.len(), 4), v)
            .expect("4 numbers per link")
            .into_pyarray(py)
    }

    /// Link frames as homogeneous ``world_from_link`` matrices (shape ``(links, 4, 4)``).
    #[getter]
    fn link_transforms<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray3<f64>> {
        let n = self.result.links.len();
        let v: Vec<f64> = (0..n)
            .flat_map(|i| homogeneous(&self.link_pose(i)).into_iter().flatten())
            .collect();
        Array3::from_shape_vec((n, 4, 4), v)
            .expect("16 numbers per link")
            .into_pyarray(py)
    }

    /// The ``world_from_link`` homogeneous matrix (4×4) of link ``name``.
    fn link_transform<'py>(
        &self,
        py: Python<'py>,
        name: &str,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let i = self.link_index(name)?;
        let m = homogeneous(&self.link_pose(i));
        let v: Vec<f64> = m.into_iter().flatten().collect();
        Ok(Array2::from_shape_vec((4, 4), v)
            .expect("16 numbers")
            .into_pyarray(py))
    }

    /// The position [m] and quaternion ``w x y z`` of link ``name``.
    fn link_pose_of<'py>(&self, py: Python<'py>, name: &str) -> PyResult<Pair<'py>> {
        let l = &self.result.links[self.link_index(name)?].1;
        Ok((
            PyArray1::from_slice(py, &l.position),
            PyArray1::from_slice(py, &l.orientation_wxyz),
        ))
    }

    /// Potential energy by source (``restpose.Energy``: ``total``, ``gravity``, ``springs``,
    /// ``joint_springs``, ``loads`` [J]).
    #[getter]
    fn energy<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        section(py, "energy", &self.result.energy)
    }

    /// Stability verdict with the lowest eigenvalues and their modes (``restpose.Stability``;
    /// ``None`` for a structure with no degree of freedom).
    #[getter]
    fn stability<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        section(py, "stability", &self.result.stability)
    }

    /// ``{joint: restpose.Reaction}``: the reaction of each joint on its child link.
    #[getter]
    fn reactions<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        section(py, "reactions", &self.result.reactions)
    }

    /// Contact points resting on a ground (``restpose.Contact`` list).
    #[getter]
    fn contacts<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        section(py, "contacts", &self.result.contacts)
    }

    /// Joints resting on a stop (``restpose.ActiveLimit`` list).
    #[getter]
    fn active_limits<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        section(py, "active_limits", &self.result.active_limits)
    }

    /// Joints resting outside their URDF limits with ``limits="ignore"``.
    #[getter]
    fn limit_violations<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        section(py, "limit_violations", &self.result.limit_violations)
    }

    /// Bodies without contact points whose centre of mass lies inside a ground, deepest first
    /// (``restpose.BuriedBody`` list: ``body``, ``ground``, ``depth`` [m]; empty when none).
    #[getter]
    fn buried_bodies<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        section(py, "buried_bodies", &self.result.buried_bodies)
    }

    /// Floating groups that could not stand on their ground start and toppled as rigid bodies
    /// before the solve (``restpose.Toppled`` list; empty when none did).
    #[getter]
    fn topple<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        section(py, "topple", &self.result.topple)
    }

    /// Constraint rows dropped as redundant.
    #[getter]
    fn redundant_constraints(&self) -> Vec<String> {
        self.result.redundant_constraints.clone()
    }

    /// Independent coordinates of the final partition.
    #[getter]
    fn independent_coordinates(&self) -> Vec<String> {
        self.result.independent_coordinates.clone()
    }

    /// The iteration history (``restpose.Iterate`` list).
    #[getter]
    fn history<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        section(py, "history", &self.result.history)
    }

    /// Solver counters and timings (``restpose.Diagnostics``).
    #[getter]
    fn diagnostics<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        section(py, "diagnostics", &self.result.diagnostics)
    }

    /// Moving bodies, Cartesian coordinates (7 per body) and constraint rows.
    #[getter]
    fn sizes(&self) -> (usize, usize, usize) {
        (
            self.result.bodies,
            self.result.coordinates,
            self.result.constraints,
        )
    }

    /// The result JSON, exactly as ``restpose analyze --json`` writes it (the timings aside).
    fn to_json(&self) -> String {
        self.result.to_json()
    }

    /// The rest pose as ROS joint_states-style YAML, as ``restpose analyze
    /// --write-joint-states`` writes it (``restpose verify --pose`` reads it back).
    fn to_joint_states(&self) -> String {
        restpose::export::joint_states::joint_states_yaml(
            &self.model.get().loaded.model,
            &self.state,
        )
    }

    fn __repr__(&self) -> String {
        format!(
            "<restpose.Result {:?}: {} after {} iterations, V = {:.6} J, {} dof>",
            self.result.robot,
            self.result.termination,
            self.result.iterations,
            self.result.potential_energy,
            self.result.dof
        )
    }
}

/// A result section as its record (`restpose._records.wrap`).
fn section<'py, T: serde::Serialize>(
    py: Python<'py>,
    name: &str,
    value: &T,
) -> PyResult<Bound<'py, PyAny>> {
    py.import("restpose._records")?
        .getattr("wrap")?
        .call1((name, serialize(py, value)?))
}
