//! The one error type of the library.

use thiserror::Error;

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
    },
    /// An option refers to something the model does not have, or has a bad value.
    #[error("{0}")]
    Option(String),
    /// The loop joints could not be closed from the initial guess.
    #[error(
        "cannot assemble the mechanism from the initial guess: constraint `{row}` is violated \
         by {residual:.3e} there and {iterations} damped Newton iterations could not close the \
         constraints (check the loop geometry or give `mech:initial` values near an assembled \
         pose)"
    )]
    Assembly {
        /// Residual of that row at the initial guess \[m or 1\].
        residual: f64,
        /// Name of the most violated constraint row.
        row: String,
        /// Newton iterations spent.
        iterations: usize,
    },
    /// Redundant constraint rows that the assembled pose does not satisfy.
    #[error(
        "inconsistent over-constrained model: redundant constraint `{row}` is violated by \
         {residual:.3e} when the independent rows hold (loop joints: {loops})"
    )]
    Inconsistent {
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
    /// The potential energy cannot be evaluated at the start.
    #[error("potential energy is undefined at the initial guess ({0})")]
    Undefined(String),
}

/// Result with [`enum@Error`].
pub type Result<T> = std::result::Result<T, Error>;
