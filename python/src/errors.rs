//! Library errors as Python exceptions: one class per kind (defined in
//! `restpose/_errors.py`, all subclasses of `restpose.Error`), with the file, line, column,
//! element, joint and numbers of the error as attributes.

use pyo3::prelude::*;
use pyo3::types::PyDict;
use restpose::error::{JointSite, SourceLocation};
use restpose::Error;

/// The exception for a library error.
pub(crate) fn to_py_err(e: Error) -> PyErr {
    Python::attach(|py| match build(py, &e) {
        Ok(err) => err,
        Err(failed) => failed,
    })
}

/// Sets `file`, `line`, `column`, `element` from a source location.
fn located(attrs: &Bound<'_, PyDict>, at: Option<&SourceLocation>) -> PyResult<()> {
    if let Some(at) = at {
        attrs.set_item("file", &at.file)?;
        attrs.set_item("line", at.line)?;
        attrs.set_item("column", at.col)?;
        attrs.set_item("element", &at.element)?;
    }
    Ok(())
}

/// Sets `joint` and its location from a joint site.
fn site(attrs: &Bound<'_, PyDict>, site: Option<&JointSite>) -> PyResult<()> {
    if let Some(s) = site {
        attrs.set_item("joint", &s.joint)?;
        located(attrs, s.at.as_ref())?;
    }
    Ok(())
}

fn build(py: Python<'_>, e: &Error) -> PyResult<PyErr> {
    let attrs = PyDict::new(py);
    let class = match e {
        Error::Io { path, cause } => {
            attrs.set_item("file", path)?;
            attrs.set_item("errno", cause.raw_os_error())?;
            "FileError"
        }
        Error::Input {
            file,
            line,
            col,
            element,
            ..
        } => {
            attrs.set_item("file", file)?;
            attrs.set_item("line", line)?;
            attrs.set_item("column", col)?;
            attrs.set_item("element", (!element.is_empty()).then_some(element))?;
            "InputError"
        }
        Error::UnknownJoint {
            what,
            name,
            suggestion,
        } => {
            attrs.set_item("what", what)?;
            attrs.set_item("joint", name)?;
            attrs.set_item("suggestion", suggestion)?;
            "UnknownJointError"
        }
        Error::CoordinateOutOfRange {
            at,
            what,
            joint,
            kind,
            dof,
            count,
        } => {
            located(&attrs, at.as_deref())?;
            attrs.set_item("what", what)?;
            attrs.set_item("joint", joint)?;
            attrs.set_item("kind", kind)?;
            attrs.set_item("dof", dof)?;
            attrs.set_item("count", count)?;
            "CoordinateError"
        }
        Error::ValueCount {
            file,
            joint,
            kind,
            expected,
            got,
        } => {
            attrs.set_item("file", file)?;
            attrs.set_item("joint", joint)?;
            attrs.set_item("kind", kind)?;
            attrs.set_item("expected", expected.clone())?;
            attrs.set_item("count", got)?;
            "CoordinateError"
        }
        Error::Pose { file, .. } => {
            attrs.set_item("file", file)?;
            "PoseError"
        }
        Error::Model(_) => "ModelError",
        Error::InvalidNumber {
            element,
            name,
            attribute,
            value,
            ..
        } => {
            attrs.set_item("element", element)?;
            attrs.set_item("name", name)?;
            attrs.set_item("attribute", attribute)?;
            attrs.set_item("value", value)?;
            "ModelError"
        }
        Error::Assembly {
            site: s,
            residual,
            row,
            iterations,
            ..
        } => {
            site(&attrs, s.as_deref())?;
            attrs.set_item("row", row)?;
            attrs.set_item("residual", residual)?;
            attrs.set_item("iterations", iterations)?;
            "AssemblyError"
        }
        Error::Inconsistent {
            site: s,
            row,
            residual,
            ..
        } => {
            site(&attrs, s.as_deref())?;
            attrs.set_item("row", row)?;
            attrs.set_item("residual", residual)?;
            "AssemblyError"
        }
        Error::ConstantEnergy { robot, dof, file } => {
            attrs.set_item("file", file)?;
            attrs.set_item("robot", robot)?;
            attrs.set_item("dof", dof)?;
            "ConstantEnergyError"
        }
        _ => "SolveError",
    };
    let module = py.import("restpose._errors")?;
    let exc = module.getattr(class)?.call1((e.to_string(),))?;
    for (k, v) in attrs.iter() {
        let k: String = k.extract()?;
        exc.setattr(k.as_str(), v)?;
    }
    Ok(PyErr::from_value(exc))
}

/// A Python `ValueError` for a bad argument (not a library error).
pub(crate) fn argument(message: impl Into<String>) -> PyErr {
    pyo3::exceptions::PyValueError::new_err(message.into())
}
