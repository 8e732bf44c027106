//! What a joint kind's file describes ([`Spec`]) and the vocabulary it is written in: the
//! vectors of the two joint frames ([`V`]), the primitives of its constraint rows ([`Row`],
//! Haug 1989 ch. 3: a component of `d`, a dot product `aᵀb`) and of its coordinates
//! ([`Read`]).
//!
//! With `x, y, z` the axes of the joint frames `J` on parent `i` (side 0) and child `j`
//! (side 1) and `d = o_j − o_i` the difference of their origins, the rows are
//!
//! - spherical: `d = 0` (3 rows);
//! - dot-1: `a_iᵀ b_j = 0` for axes `a_i`, `b_j`;
//! - dot-2: `a_iᵀ d = 0`;
//! - length: `dᵀd − L² = 0`; thread: `d·z_i − h θ = 0` (angle `θ` on its branch).
//!
//! ## References
//! - E. J. Haug, *Computer-Aided Kinematics and Dynamics of Mechanical Systems* (1989), ch. 3.

use super::JointKind;
use crate::math::unit_quaternion;
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3, Vector4};

/// A vector of the two joint frames: `d = o₁ − o₀` or an axis of side 0 or 1.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum V {
    D,
    X0,
    Y0,
    Z0,
    X1,
    Y1,
    Z1,
}

/// One constraint row.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Row {
    /// Component `k` of `d`.
    Component(usize),
    /// The dot product `aᵀb`.
    Dot(V, V),
    /// `dᵀd − L²` for the kind's parameter `L` (a distance joint's length).
    Length,
    /// `d·z₀ − h θ` for the kind's parameter `h` (a screw's pitch) and the angle `θ` about
    /// `z₀` read on its branch; no closed form (the generic jets evaluate it).
    Thread,
}

/// A row's entries on the pair's 14 coordinates (`7 side + k`, `k`: `x y z e0 e1 e2 e3`) that
/// are not zero at every configuration, as bits ([`Row::pattern`]).
pub(crate) type Pattern = u16;

/// Every entry of the pair.
pub(crate) const ALL: Pattern = (1 << 14) - 1;

/// The Euler parameters of both sides.
const EULER: Pattern = 0b1111000 | 0b1111000 << 7;

impl Row {
    /// The entries of the row's gradient that can be nonzero (the others are zero at every
    /// `q`, by the row's form): with `∂u/∂r_k = t_k I` for a vector `u` of side `k` (`t = 1`
    /// for a point, `0` for an axis, `±1` for `d`), the position entries of
    ///
    /// - a component `d_m`: `∂d_m/∂r_k = t_k e_m`, so only `r_k`'s component `m`;
    /// - a dot product of two axes `aᵀb`: `t^a = t^b = 0`, so none;
    ///
    /// and every entry of a row with `d` in a product (`a_iᵀ d`, `dᵀd`, the thread).
    pub(crate) const fn pattern(self) -> Pattern {
        match self {
            Row::Component(m) => EULER | (1 << m) | (1 << (7 + m)),
            Row::Dot(V::D, _) | Row::Dot(_, V::D) | Row::Length | Row::Thread => ALL,
            Row::Dot(_, _) => EULER,
        }
    }
}

/// How a scalar coordinate is read from the joint frames.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Read {
    /// The angle `atan2(y₀·x₁, x₀·x₁)` about `z₀`.
    Angle,
    /// A dot product `aᵀb`.
    Dot(V, V),
    /// `atan2(aᵀb, cᵀe)` for `[[a, b], [c, e]]`.
    Atan2([V; 2], [V; 2]),
}

/// A scalar coordinate: how it is read and whether it is an angle \[rad\] (else a length
/// \[m\]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Coordinate {
    pub(crate) read: Read,
    pub(crate) angle: bool,
}

/// An angle coordinate.
pub(crate) const fn angle(read: Read) -> Coordinate {
    Coordinate { read, angle: true }
}

/// A length coordinate.
pub(crate) const fn length(read: Read) -> Coordinate {
    Coordinate { read, angle: false }
}

/// How the importer places the joint frame `J` from `<axis>`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Frame {
    /// z along the axis.
    Axis,
    /// z along the axis and x along the orthogonalized second axis (universal).
    TwoAxes,
    /// The joint origin frame itself (the kind has no axis; its values are expressed in it).
    Origin,
}

/// One entry of another tool's configuration vector from the values `v` of a joint (missing
/// values are 0).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Entry {
    /// `v[i]`.
    Value(usize),
    /// `cos v[i]`.
    Cos(usize),
    /// `sin v[i]`.
    Sin(usize),
}

/// How MuJoCo's `qpos` and Pinocchio's `q` hold a joint of this kind, read from the same URDF
/// (`None`: that tool does not read the kind from a URDF).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Configuration {
    pub(crate) mujoco: Option<&'static [Entry]>,
    pub(crate) pinocchio: Option<&'static [Entry]>,
}

/// Neither tool reads the kind from a URDF.
pub(crate) const NOT_IN_URDF: Configuration = Configuration {
    mujoco: None,
    pinocchio: None,
};

/// Both tools hold the kind's one value as it is (revolute, prismatic).
pub(crate) const ONE_VALUE: Configuration = Configuration {
    mujoco: Some(&[Entry::Value(0)]),
    pinocchio: Some(&[Entry::Value(0)]),
};

/// What moves the child of a tree joint of this kind in joint space (the stability verdict's
/// joint-space check, `solver::stability::joint_space`, and the poses `verify` reads).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum TreeMotion {
    /// Its scalar coordinates (none for a fixed joint).
    Coordinates,
    /// Its scalar coordinates and a free rotation (spherical: three angular velocities).
    Rotation,
    /// The child's whole pose (three translational and three angular velocities): a floating
    /// joint's values, or for a kind without values (distance, point-on-line) the child body's
    /// own pose.
    Pose,
}

/// Where a file may declare a joint of a type name.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Declared {
    /// A URDF `<joint type>` (a tree joint).
    pub urdf: bool,
    /// A `<mech:loop_joint type>` (a loop-closing joint).
    pub loop_joint: bool,
    /// A `<drake:joint type>` (Drake's extension).
    pub drake: bool,
}

/// A type name of a kind and where files may use it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Name {
    /// The `type` string.
    pub name: &'static str,
    /// Where files may use it.
    pub declared: Declared,
}

/// A type name accepted in a URDF `<joint>`, a `<mech:loop_joint>`, a `<drake:joint>`.
pub(crate) const fn name(name: &'static str, urdf: bool, loop_joint: bool, drake: bool) -> Name {
    Name {
        name,
        declared: Declared {
            urdf,
            loop_joint,
            drake,
        },
    }
}

/// Everything the layers above need to know of a joint kind.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Spec {
    /// Its type names; the first is the one printed (result JSON, summary, exports), the
    /// others are aliases (`ball` for `spherical`).
    pub(crate) names: &'static [Name],
    /// Scalar coordinates that springs, efforts, locks and initial values can address.
    pub(crate) coordinates: &'static [Coordinate],
    /// The numbers of values a pose may give (see [`JointKind::value_counts`]).
    pub(crate) value_counts: &'static [usize],
    /// Unit of each value of `joints.*.position` in the result JSON: `"rad"`, `"m"` or `"1"`.
    pub(crate) units: &'static [&'static str],
    /// Whether `<limit lower upper>` bounds coordinate 0.
    pub(crate) has_limits: bool,
    /// Constraint rows, in order.
    pub(crate) rows: &'static [Row],
    /// Their names (`redundant_constraints`, e.g. `axis_x`), one per row.
    pub(crate) row_names: &'static [&'static str],
    /// Whether the rows are evaluated in closed form (`jet::closed`), else by the generic
    /// jets.
    pub(crate) closed_form: bool,
    /// How `<axis>` places the joint frame.
    pub(crate) frame: Frame,
    /// What moves its child as a tree joint.
    pub(crate) tree_motion: TreeMotion,
    /// Its entries in MuJoCo's and Pinocchio's configuration vectors.
    pub(crate) configuration: Configuration,
    /// The values of a kind without scalar coordinates (a spherical joint's quaternion, a
    /// floating joint's translation and quaternion) read from the relative motion `M` of the
    /// joint frames: the inverse of `motion`. Kinds with scalar coordinates read those instead.
    pub(crate) values_of_motion: fn(&Isometry3<f64>) -> Vec<f64>,
    /// The relative motion `M(v)` of the child's `J` in the parent's `J` for the values `v`
    /// (missing values are 0; angles taken as given).
    pub(crate) motion: fn(&JointKind, &[f64]) -> Isometry3<f64>,
}

/// No values (the kinds with scalar coordinates, or none at all).
pub(crate) fn no_values(_: &Isometry3<f64>) -> Vec<f64> {
    vec![]
}

/// Value `i` of `v`, 0 if missing.
pub(crate) fn at(v: &[f64], i: usize) -> f64 {
    v.get(i).copied().unwrap_or(0.0)
}

/// `Rz(a)`.
pub(crate) fn rz(a: f64) -> UnitQuaternion<f64> {
    UnitQuaternion::from_axis_angle(&Vector3::z_axis(), a)
}

/// `Rx(a)`.
pub(crate) fn rx(a: f64) -> UnitQuaternion<f64> {
    UnitQuaternion::from_axis_angle(&Vector3::x_axis(), a)
}

/// The translation `(x, y, z)`.
pub(crate) fn t(x: f64, y: f64, z: f64) -> Translation3<f64> {
    Translation3::new(x, y, z)
}

/// The rotation of the rotation vector `(a, b, c)`.
pub(crate) fn rotvec(a: f64, b: f64, c: f64) -> UnitQuaternion<f64> {
    UnitQuaternion::from_scaled_axis(Vector3::new(a, b, c))
}

/// The rotation of the quaternion `[w, x, y, z]`.
pub(crate) fn quat(w: f64, x: f64, y: f64, z: f64) -> UnitQuaternion<f64> {
    unit_quaternion(&Vector4::new(w, x, y, z))
}

/// The rows `pos_x, pos_y, pos_z`: `d = 0`.
pub(crate) const POS: [Row; 3] = [Row::Component(0), Row::Component(1), Row::Component(2)];
/// The rows `axis_x, axis_y`: `z₀·x₁ = z₀·y₁ = 0` (the z axes parallel).
pub(crate) const PARALLEL: [Row; 2] = [Row::Dot(V::Z0, V::X1), Row::Dot(V::Z0, V::Y1)];
/// The rows `slide_x, slide_y` (or `line_x, line_y`): `x₀·d = y₀·d = 0` (the child's origin
/// on the parent's z line).
pub(crate) const ON_AXIS: [Row; 2] = [Row::Dot(V::X0, V::D), Row::Dot(V::Y0, V::D)];
