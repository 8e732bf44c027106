//! `restpose.ModelBuilder`: a mechanism built in code through the library's
//! [`restpose::model::ModelBuilder`], with its validation and errors. Bodies and joints are
//! named; `None` (or ``"world"``) is the world. Joint frames follow URDF: the child link's
//! frame is the joint frame, placed in the parent by ``xyz``/``rpy``, the axis given in it.

use crate::convert::{origin, vector};
use crate::errors::{argument, to_py_err};
use crate::model::Model;
use nalgebra::{Isometry3, Matrix3, Unit};
use pyo3::prelude::*;
use restpose::model::{
    axis_frame, BodyId, Effort, ForceLaw, Initial, JointId, JointKind, Load, Lock, Spring,
    SpringEnd, SpringMode,
};
use std::collections::HashMap;

/// Builds a ``restpose.Model`` in code: add bodies, joints and force elements by name, then
/// ``build()`` validates them (``restpose.ModelError`` / ``InputError`` as for a file).
///
/// >>> b = restpose.ModelBuilder("pendulum")
/// >>> b.add_rigid_body("arm", mass=1.0, com=(0.5, 0, 0), inertia=np.eye(3) * 1e-3)
/// >>> b.add_joint("hinge", "revolute", parent=None, child="arm", axis=(0, 1, 0))
/// >>> b.add_joint_spring("hinge", stiffness=10.0)
/// >>> model = b.build()
#[pyclass(module = "restpose")]
pub(crate) struct ModelBuilder {
    inner: Option<restpose::model::ModelBuilder>,
    bodies: HashMap<String, BodyId>,
}

impl ModelBuilder {
    fn b(&mut self) -> PyResult<&mut restpose::model::ModelBuilder> {
        self.inner
            .as_mut()
            .ok_or_else(|| argument("this ModelBuilder has been built already"))
    }

    fn body(&self, name: Option<&str>) -> PyResult<Option<BodyId>> {
        match name {
            None | Some("world") => Ok(None),
            Some(n) => self
                .bodies
                .get(n)
                .copied()
                .map(Some)
                .ok_or_else(|| argument(format!("no body named `{n}` (add it first)"))),
        }
    }

    fn joint(&mut self, name: &str) -> PyResult<JointId> {
        let b = self.b()?;
        b.joint_id(name).ok_or_else(|| {
            to_py_err(restpose::Error::UnknownJoint {
                what: "builder".into(),
                name: name.into(),
                suggestion: restpose::names::closest(
                    name,
                    b.partial().joints().iter().map(|j| j.name.as_str()),
                )
                .map(str::to_owned),
            })
        })
    }
}

/// The joint kind named `kind` (URDF and restpose names).
fn kind(kind: &str, pitch: Option<f64>, length: Option<f64>) -> PyResult<JointKind> {
    Ok(match kind {
        "revolute" => JointKind::Revolute,
        "continuous" => JointKind::Continuous,
        "prismatic" => JointKind::Prismatic,
        "fixed" => JointKind::Fixed,
        "floating" => JointKind::Floating,
        "planar" => JointKind::Planar,
        "spherical" | "ball" => JointKind::Spherical,
        "universal" => JointKind::Universal,
        "cylindrical" => JointKind::Cylindrical,
        "screw" => JointKind::Screw {
            pitch: pitch.ok_or_else(|| argument("a screw joint needs pitch= [m/rad]"))?,
        },
        "distance" => JointKind::Distance {
            length: length.ok_or_else(|| argument("a distance joint needs length= [m]"))?,
        },
        "point_on_line" => JointKind::PointOnLine,
        other => {
            return Err(argument(format!(
                "joint kind {other:?}: expected revolute, continuous, prismatic, fixed, \
                 floating, planar, spherical, universal, cylindrical, screw, distance or \
                 point_on_line"
            )))
        }
    })
}

fn law(stiffness: f64, preload: f64) -> ForceLaw {
    ForceLaw::Linear { stiffness, preload }
}

#[pymethods]
impl ModelBuilder {
    /// An empty model named ``name`` (gravity ``(0, 0, -9.81)`` m/s²).
    #[new]
    fn new(name: String) -> Self {
        ModelBuilder {
            inner: Some(restpose::model::ModelBuilder::new(name)),
            bodies: HashMap::new(),
        }
    }

    /// Sets gravity in the world frame [m/s²].
    fn set_gravity(&mut self, gravity: [f64; 3]) -> PyResult<()> {
        self.b()?.set_gravity(vector(gravity));
        Ok(())
    }

    /// Adds a moving body carrying one link of the same name: ``mass`` [kg], centre of mass
    /// ``com`` [m] in the body frame, ``inertia`` [kg m²] about it (3×3; default zero).
    #[pyo3(signature = (name, *, mass, com=[0.0; 3], inertia=None))]
    fn add_rigid_body(
        &mut self,
        name: String,
        mass: f64,
        com: [f64; 3],
        inertia: Option<[[f64; 3]; 3]>,
    ) -> PyResult<()> {
        if self.bodies.contains_key(&name) {
            return Err(argument(format!("a body named `{name}` exists already")));
        }
        let i = inertia.unwrap_or([[0.0; 3]; 3]);
        let inertia = Matrix3::from_fn(|r, c| i[r][c]);
        let id = self
            .b()?
            .add_rigid_body(name.clone(), mass, vector(com), inertia);
        self.bodies.insert(name, id);
        Ok(())
    }

    /// Adds a joint of kind ``kind`` (``"revolute"``, ``"continuous"``, ``"prismatic"``,
    /// ``"fixed"``, ``"floating"``, ``"planar"``, ``"spherical"``, ``"universal"``,
    /// ``"cylindrical"``, ``"screw"`` with ``pitch``, ``"distance"`` with ``length``,
    /// ``"point_on_line"``) from ``parent`` to ``child`` (body names; ``None`` or ``"world"``
    /// for the world). As in URDF, the joint frame is placed in the parent's frame by ``xyz``
    /// [m] and ``rpy`` [rad], ``axis`` is given in it, and the child's frame is the joint frame
    /// (offset by ``child_xyz``/``child_rpy`` for a loop joint). ``loop=True`` adds a joint
    /// that closes a loop instead of a spanning-tree joint. ``limits=(lower, upper)`` sets
    /// the position limits of coordinate 0.
    #[pyo3(signature = (name, kind_name, *, parent, child, xyz=None, rpy=None, axis=[0.0, 0.0, 1.0],
        child_xyz=None, child_rpy=None, r#loop=false, limits=None, pitch=None, length=None))]
    fn add_joint(
        &mut self,
        name: String,
        kind_name: &str,
        parent: Option<String>,
        child: Option<String>,
        xyz: Option<[f64; 3]>,
        rpy: Option<[f64; 3]>,
        axis: [f64; 3],
        child_xyz: Option<[f64; 3]>,
        child_rpy: Option<[f64; 3]>,
        r#loop: bool,
        limits: Option<(f64, f64)>,
        pitch: Option<f64>,
        length: Option<f64>,
    ) -> PyResult<()> {
        let k = kind(kind_name, pitch, length)?;
        let axis = vector(axis);
        if !(axis.norm() > 1e-12 && axis.iter().all(|x| x.is_finite())) {
            return Err(argument(format!(
                "joint `{name}`: the axis must be a finite non-zero vector, got {axis:?}"
            )));
        }
        let axis = Unit::new_normalize(axis);
        let (p, c) = (self.body(parent.as_deref())?, self.body(child.as_deref())?);
        let parent_from_joint = axis_frame(origin(xyz, rpy), &axis);
        let child_from_joint = axis_frame(origin(child_xyz, child_rpy), &axis);
        let b = self.b()?;
        let id = if r#loop {
            b.add_loop_joint(name, k, p, parent_from_joint, c, child_from_joint)
        } else {
            b.add_joint(name, k, p, parent_from_joint, c, child_from_joint)
        };
        if let Some((lo, hi)) = limits {
            b.set_limits(id, lo, hi);
        }
        Ok(())
    }

    /// Adds a linear spring on coordinate ``dof`` of joint ``joint``: stiffness [N m/rad or
    /// N/m], torque ``preload`` at the ``reference`` value.
    #[pyo3(signature = (joint, *, stiffness, reference=0.0, preload=0.0, dof=0))]
    fn add_joint_spring(
        &mut self,
        joint: &str,
        stiffness: f64,
        reference: f64,
        preload: f64,
        dof: usize,
    ) -> PyResult<()> {
        let id = self.joint(joint)?;
        self.b()?
            .add_joint_spring(id, dof, law(stiffness, preload), reference);
        Ok(())
    }

    /// Adds a translational spring between point ``point_a`` of body ``body_a`` and
    /// ``point_b`` of ``body_b`` (body frames; ``None`` = world): ``stiffness`` [N/m],
    /// ``free_length`` [m]; ``mode`` ``"both"``, ``"tension"`` (a cable) or ``"compression"``.
    #[pyo3(signature = (name, *, body_a, point_a, body_b, point_b, stiffness, free_length=0.0,
        preload=0.0, mode="both"))]
    fn add_spring(
        &mut self,
        name: String,
        body_a: Option<String>,
        point_a: [f64; 3],
        body_b: Option<String>,
        point_b: [f64; 3],
        stiffness: f64,
        free_length: f64,
        preload: f64,
        mode: &str,
    ) -> PyResult<()> {
        let mode = match mode {
            "both" => SpringMode::Both,
            "tension" => SpringMode::Tension,
            "compression" => SpringMode::Compression,
            m => {
                return Err(argument(format!(
                    "mode = {m:?}: expected \"both\", \"tension\" or \"compression\""
                )))
            }
        };
        let ends = [
            SpringEnd {
                body: self.body(body_a.as_deref())?,
                point: vector(point_a),
            },
            SpringEnd {
                body: self.body(body_b.as_deref())?,
                point: vector(point_b),
            },
        ];
        self.b()?.add_spring(Spring {
            name,
            ends,
            free_length,
            law: law(stiffness, preload),
            mode,
        });
        Ok(())
    }

    /// Adds a constant dead load ``force`` [N, world frame] at ``point`` [m] of body ``body``.
    #[pyo3(signature = (name, *, body, point, force))]
    fn add_load(
        &mut self,
        name: String,
        body: String,
        point: [f64; 3],
        force: [f64; 3],
    ) -> PyResult<()> {
        let body = self
            .body(Some(&body))?
            .ok_or_else(|| argument("a load acts on a moving body, not the world"))?;
        self.b()?.add_load(Load {
            name,
            body,
            point: vector(point),
            force: vector(force),
        });
        Ok(())
    }

    /// Adds a constant generalized force ``value`` [N m or N] on coordinate ``dof`` of joint
    /// ``joint``.
    #[pyo3(signature = (joint, value, *, dof=0))]
    fn add_effort(&mut self, joint: &str, value: f64, dof: usize) -> PyResult<()> {
        let joint = self.joint(joint)?;
        self.b()?.add_effort(Effort { joint, dof, value });
        Ok(())
    }

    /// Holds coordinate ``dof`` of joint ``joint`` at ``value`` (``None``: its initial value).
    #[pyo3(signature = (joint, value=None, *, dof=0))]
    fn add_lock(&mut self, joint: &str, value: Option<f64>, dof: usize) -> PyResult<()> {
        let joint = self.joint(joint)?;
        self.b()?.add_lock(Lock { joint, dof, value });
        Ok(())
    }

    /// Sets the initial guess of coordinate ``dof`` of joint ``joint``.
    #[pyo3(signature = (joint, value, *, dof=0))]
    fn add_initial(&mut self, joint: &str, value: f64, dof: usize) -> PyResult<()> {
        let joint = self.joint(joint)?;
        self.b()?.add_initial(Initial { joint, dof, value });
        Ok(())
    }

    /// Adds a ground plane through ``origin`` with the outward ``normal``.
    #[pyo3(signature = (name, *, origin=[0.0; 3], normal=[0.0, 0.0, 1.0]))]
    fn add_ground(&mut self, name: String, origin: [f64; 3], normal: [f64; 3]) -> PyResult<()> {
        self.b()?
            .add_ground(name, vector(origin), vector(normal))
            .map_err(to_py_err)
    }

    /// Sets the start pose of the floating root body (``xyz`` [m], ``rpy`` [rad]).
    #[pyo3(signature = (*, xyz=None, rpy=None))]
    fn set_base_pose(&mut self, xyz: Option<[f64; 3]>, rpy: Option<[f64; 3]>) -> PyResult<()> {
        let pose: Isometry3<f64> = origin(xyz, rpy);
        self.b()?.set_base_pose(pose);
        Ok(())
    }

    /// Validates the model and returns it (the builder cannot be used afterwards). Raises
    /// ``restpose.ModelError`` naming the element at fault.
    fn build(&mut self) -> PyResult<Model> {
        let b = self
            .inner
            .take()
            .ok_or_else(|| argument("this ModelBuilder has been built already"))?;
        let model = b.build().map_err(to_py_err)?;
        Ok(Model::new(
            restpose::urdf::Loaded {
                model,
                warnings: Vec::new(),
                ignored: Vec::new(),
            },
            0.0,
        ))
    }
}
