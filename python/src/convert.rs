//! Conversions between the library's values and Python objects: serde values to plain
//! Python objects (dicts, lists, floats), frames to numpy arrays, Python arguments to
//! nalgebra types.

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

/// A serde value as the plain Python object `json.loads` would give.
pub(crate) fn to_py<'py>(py: Python<'py>, v: &serde_json::Value) -> PyResult<Bound<'py, PyAny>> {
    use serde_json::Value;
    Ok(match v {
        Value::Null => py.None().into_bound(py),
        Value::Bool(b) => b.into_pyobject(py)?.to_owned().into_any(),
        Value::Number(n) => match (n.as_i64(), n.as_u64()) {
            (Some(i), _) => i.into_pyobject(py)?.into_any(),
            (None, Some(u)) => u.into_pyobject(py)?.into_any(),
            _ => n.as_f64().unwrap_or(f64::NAN).into_pyobject(py)?.into_any(),
        },
        Value::String(s) => s.into_pyobject(py)?.into_any(),
        Value::Array(a) => {
            let list = PyList::empty(py);
            for x in a {
                list.append(to_py(py, x)?)?;
            }
            list.into_any()
        }
        Value::Object(o) => {
            let dict = PyDict::new(py);
            for (k, x) in o {
                dict.set_item(k, to_py(py, x)?)?;
            }
            dict.into_any()
        }
    })
}

/// Any serializable value of the library as a plain Python object.
pub(crate) fn serialize<'py, T: serde::Serialize>(
    py: Python<'py>,
    value: &T,
) -> PyResult<Bound<'py, PyAny>> {
    let v = serde_json::to_value(value)
        .map_err(|e| pyo3::exceptions::PyValueError::new_err(e.to_string()))?;
    to_py(py, &v)
}

/// A vector from three numbers.
pub(crate) fn vector(v: [f64; 3]) -> Vector3<f64> {
    Vector3::new(v[0], v[1], v[2])
}

/// The URDF `<origin xyz rpy>` transform (`rpy` = `Rz(y) Ry(p) Rx(r)`).
pub(crate) fn origin(xyz: Option<[f64; 3]>, rpy: Option<[f64; 3]>) -> Isometry3<f64> {
    let t = xyz.unwrap_or([0.0; 3]);
    let r = rpy.unwrap_or([0.0; 3]);
    Isometry3::from_parts(
        Translation3::new(t[0], t[1], t[2]),
        UnitQuaternion::from_euler_angles(r[0], r[1], r[2]),
    )
}

/// A rigid transform as a row-major 4×4 homogeneous matrix.
pub(crate) fn homogeneous(pose: &Isometry3<f64>) -> [[f64; 4]; 4] {
    let m = pose.to_homogeneous();
    let mut out = [[0.0; 4]; 4];
    for (r, row) in out.iter_mut().enumerate() {
        for (c, x) in row.iter_mut().enumerate() {
            *x = m[(r, c)];
        }
    }
    out
}
