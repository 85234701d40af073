//! Values handed to Python: curves and vectors as 1-D numpy arrays that take over the Rust
//! vector (no copy), dense matrices as 2-D arrays, JSON documents as dicts and lists.

use faer::Mat;
use numpy::{PyArray1, PyArray2, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use serde_json::Value;

/// A vector as a numpy array owning its buffer (the `Vec` is moved, not copied).
pub fn vector(py: Python<'_>, v: Vec<f64>) -> Py<PyAny> {
    PyArray1::from_vec(py, v).into_any().unbind()
}

/// A dense matrix as a C-ordered 2-D numpy array (one copy out of faer's column-major storage).
pub fn matrix(py: Python<'_>, a: &Mat<f64>) -> PyResult<Py<PyAny>> {
    let (r, c) = (a.nrows(), a.ncols());
    let mut data = Vec::with_capacity(r * c);
    for i in 0..r {
        data.extend((0..c).map(|j| a[(i, j)]));
    }
    let arr: Bound<'_, PyArray2<f64>> = PyArray1::from_vec(py, data).reshape([r, c])?;
    Ok(arr.into_any().unbind())
}

/// A JSON value as Python objects: objects → dict, arrays → list, numbers → int or float,
/// `null` → None.
pub fn json(py: Python<'_>, v: &Value) -> PyResult<Py<PyAny>> {
    Ok(match v {
        Value::Null => py.None(),
        Value::Bool(b) => b.into_pyobject(py)?.to_owned().into_any().unbind(),
        Value::Number(n) => match (n.as_u64(), n.as_i64()) {
            (Some(u), _) => u.into_pyobject(py)?.into_any().unbind(),
            (None, Some(i)) => i.into_pyobject(py)?.into_any().unbind(),
            _ => n
                .as_f64()
                .unwrap_or(f64::NAN)
                .into_pyobject(py)?
                .into_any()
                .unbind(),
        },
        Value::String(s) => s.into_pyobject(py)?.into_any().unbind(),
        Value::Array(a) => {
            let list = PyList::empty(py);
            for x in a {
                list.append(json(py, x)?)?;
            }
            list.into_any().unbind()
        }
        Value::Object(o) => {
            let d = PyDict::new(py);
            for (k, x) in o {
                d.set_item(k, json(py, x)?)?;
            }
            d.into_any().unbind()
        }
    })
}

/// Anything serialisable as a Python object through its JSON value.
pub fn serialized<T: serde::Serialize>(py: Python<'_>, v: &T) -> PyResult<Py<PyAny>> {
    let value = serde_json::to_value(v)
        .map_err(|e| crate::errors::Error::new_err(format!("cannot convert a result: {e}")))?;
    json(py, &value)
}
