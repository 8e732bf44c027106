//! The one error type of the library.

use std::fmt;
use thiserror::Error;

/// Where an element starts in an input file.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SourceLocation {
    /// The file (or `<string>`).
    pub file: String,
    /// Line, from 1.
    pub line: u32,
    /// Column, from 1.
    pub col: u32,
    /// The element's tag as written (`joint`, `mech:loop_joint`, `drake:joint`).
    pub element: String,
}

impl fmt::Display for SourceLocation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}:{}", self.file, self.line, self.col)
    }
}

/// The joint an error is about (or the link, for a contact's row), with where it is declared
/// when the model came from a file.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct JointSite {
    /// What it is: `joint`, or `link` for a contact point's row.
    pub kind: &'static str,
    /// Joint name (the link's for a contact point's row).
    pub joint: String,
    /// The joint's element in the input file (`None` for a model built in code).
    pub at: Option<SourceLocation>,
}

impl fmt::Display for JointSite {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.at {
            Some(at) => write!(f, "{at}: {} `{}` ({})", self.kind, self.joint, at.element),
            None => write!(f, "{} `{}`", self.kind, self.joint),
        }
    }
}

/// `"{site}: "`, or nothing without a site.
fn prefix<T: fmt::Display>(site: &Option<T>) -> String {
    site.as_ref().map(|s| format!("{s}: ")).unwrap_or_default()
}

/// Everything that can go wrong loading or solving a mechanism.
///
/// Not converging is not an error: it is [`crate::solver::Termination`] in the report.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum Error {
    /// A file could not be read or written.
    #[error("{path}: {cause}")]
    Io {
        /// The file.
        path: String,
        /// The operating-system error.
        cause: std::io::Error,
    },
    /// The input file is malformed or inconsistent at a known place.
    #[error("{file}:{line}:{col}: {message}")]
    Input {
        /// The file (or `<string>`).
        file: String,
        /// Line, from 1.
        line: u32,
        /// Column, from 1.
        col: u32,
        /// What is wrong, naming the element.
        message: String,
        /// The element's tag as written (`joint`, `mech:spring`); empty where the error is
        /// not at an element (encoding, file size, XML syntax).
        element: String,
    },
    /// A joint name that the model does not have.
    #[error("{what} `{name}`: the model has no joint of that name{}", suggestion.as_ref().map(|s| format!(" (did you mean `{s}`?)")).unwrap_or_default())]
    UnknownJoint {
        /// What named it (`lock`, `initial value`, `pose`, ...).
        what: String,
        /// The name given.
        name: String,
        /// The closest joint name of the model, if one is close.
        suggestion: Option<String>,
    },
    /// A coordinate index beyond the joint's coordinates.
    #[error(
        "{}{what} `{joint}`: the joint is {kind} with {count} addressable coordinate(s), \
         coordinate {dof} is out of range",
        prefix(at)
    )]
    CoordinateOutOfRange {
        /// The joint's element in the input file, if it came from one.
        at: Option<Box<SourceLocation>>,
        /// What addressed it.
        what: String,
        /// Joint name.
        joint: String,
        /// Joint type name.
        kind: String,
        /// The coordinate index given.
        dof: usize,
        /// Number of scalar coordinates of the joint.
        count: usize,
    },
    /// A pose gives a joint the wrong number of values.
    #[error("{file}: joint `{joint}` ({kind}) takes {expected:?} value(s), got {got}")]
    ValueCount {
        /// The pose file (or `<pose>`).
        file: String,
        /// Joint name.
        joint: String,
        /// Joint type name.
        kind: String,
        /// Accepted numbers of values.
        expected: Vec<usize>,
        /// Number given.
        got: usize,
    },
    /// A pose file that is none of the accepted formats.
    #[error("{file}: {message}")]
    Pose {
        /// The pose file.
        file: String,
        /// What is wrong.
        message: String,
    },
    /// The quasi-Newton methods keep a dense matrix that would not fit.
    #[error(
        "{method}: BFGS and DFP keep a dense {dof} × {dof} matrix ({gigabytes:.1} GB) for \
         {dof} degrees of freedom; use the Newton method (sparse KKT steps) above {limit}"
    )]
    TooManyDegreesOfFreedom {
        /// The method asked for.
        method: String,
        /// Degrees of freedom.
        dof: usize,
        /// Largest number of degrees of freedom BFGS / DFP accept.
        limit: usize,
        /// Memory the matrix would take \[GB\].
        gigabytes: f64,
    },
    /// Nothing stores or releases energy while the mechanism can move: every pose is a rest
    /// pose.
    #[error(
        "{}the potential energy of `{robot}` is constant: it has {dof} degree(s) of freedom but \
         no moving body has mass under gravity and there is no spring, load or effort, so every \
         pose is a rest pose (give the moving links <inertial> masses, or add springs)",
        prefix(file)
    )]
    ConstantEnergy {
        /// The input file, when the model came from one.
        file: Option<String>,
        /// Robot name.
        robot: String,
        /// Degrees of freedom.
        dof: usize,
    },
    /// A number of the model that is negative where it must not be, or too large to compute
    /// with.
    #[error("{element}: {attribute} = {value:e} {why}")]
    InvalidNumber {
        /// The element (`link `bar``, `joint spring on `pivot``, ...).
        element: String,
        /// The element's bare name (link, joint, spring or load name).
        name: String,
        /// The attribute.
        attribute: String,
        /// Its value.
        value: f64,
        /// Why it is refused.
        why: String,
    },
    /// The loop joints could not be closed from the initial guess.
    #[error(
        "{}cannot assemble the mechanism from the initial guess: constraint `{row}` is violated \
         by {residual:.3e} there and {iterations} damped Newton iterations could not close the \
         constraints ({remedy})",
        prefix(site)
    )]
    Assembly {
        /// The joint of that row and where it is declared.
        site: Option<Box<JointSite>>,
        /// Residual of that row at the initial guess \[m or 1\].
        residual: f64,
        /// Name of the most violated constraint row.
        row: String,
        /// Newton iterations spent.
        iterations: usize,
        /// What to change: for a loop joint, its geometry or initial values; for a contact that
        /// starts inside a ground, the base's start pose.
        remedy: String,
    },
    /// Redundant constraint rows that the assembled pose does not satisfy.
    #[error(
        "{}inconsistent over-constrained model: redundant constraint `{row}` is violated by \
         {residual:.3e} when the independent rows hold (loop joints: {loops})",
        prefix(site)
    )]
    Inconsistent {
        /// The joint of that row and where it is declared.
        site: Option<Box<JointSite>>,
        /// Name of the violated redundant row.
        row: String,
        /// Its residual.
        residual: f64,
        /// The model's loop joints, which close the over-constrained loops.
        loops: String,
    },
    /// A model built in code refers to an id or coordinate it does not have, or has a
    /// non-finite or negative mass property.
    #[error("invalid model: {0}")]
    Model(String),
    /// A force table with `extrapolate="error"` is evaluated outside its range.
    #[error(
        "{element}: deflection {deflection:.6e} is outside its force table \
         [{lower:.6e}, {upper:.6e}] (extrapolate=\"error\")"
    )]
    ForceTableOutOfRange {
        /// The spring (`spring `s``, `joint spring on `j``).
        element: String,
        /// The deflection \[m or rad\].
        deflection: f64,
        /// First knot.
        lower: f64,
        /// Last knot.
        upper: f64,
    },
    /// The solve produced a non-finite number (never reported as a result).
    #[error("the solve produced a non-finite {what} at iteration {iteration}")]
    NonFinite {
        /// What (`potential energy`, `coordinate x of body `b``).
        what: String,
        /// Iteration.
        iteration: usize,
    },
    /// The potential energy or its gradient is not finite at a configuration (a number of the
    /// model too large for `f64` arithmetic): never reported as a result.
    #[error(
        "the potential energy is not finite at {at}: {term} gives a non-finite energy or force \
         (a number of the model is too large to compute with)"
    )]
    NonFiniteEnergy {
        /// Where (`the given pose`, `the initial guess`).
        at: String,
        /// The term that is not finite there (`spring `s``, `gravity on body `b``).
        term: String,
    },
    /// The constraints are not finite at a configuration.
    #[error("{}the constraint `{row}` is not finite at {at}", prefix(site))]
    NonFiniteConstraint {
        /// The joint (or contact link) of that row and where it is declared.
        site: Option<Box<JointSite>>,
        /// The row.
        row: String,
        /// Where (`the given pose`).
        at: String,
    },
    /// `verify` on the sparse path: holding every tree-joint coordinate makes model rows
    /// redundant, so the joints' efforts cannot be told apart from the loop reactions.
    #[error(
        "the efforts of the joint coordinates cannot be separated from the loop reactions \
         ({dependent} constraint rows dependent on the joint coordinates, {without} without them)"
    )]
    InseparableEfforts {
        /// Redundant model rows with every joint coordinate held.
        dependent: usize,
        /// Redundant model rows without them.
        without: usize,
    },
    /// The dependent block `Φ_u` of the constraint Jacobian is singular at a pose.
    #[error(
        "the constraint Jacobian is singular at {at}: the partition into dependent and \
         independent coordinates failed ({rows} independent rows)"
    )]
    SingularPartition {
        /// Where (`the initial guess`, `the given pose`).
        at: String,
        /// Rank found.
        rows: usize,
    },
}

/// Result with [`enum@Error`].
pub type Result<T> = std::result::Result<T, Error>;
