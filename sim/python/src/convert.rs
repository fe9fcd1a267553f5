//! Conversions between the engine's types and Python values: poses as `(x, y, theta)` tuples,
//! readings as numpy arrays.

use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use systems::core::Pose2;

pub type PoseTuple = (f64, f64, f64);

pub fn pose(p: Pose2) -> PoseTuple {
    (p.x, p.y, p.theta)
}

/// A pose from `(x, y)` or `(x, y, theta)`, finite.
pub fn pose_from(what: &str, v: &[f64]) -> PyResult<Pose2> {
    let p = match v {
        [x, y] => Pose2::new(*x, *y, 0.0),
        [x, y, t] => Pose2::new(*x, *y, *t),
        _ => {
            return Err(pyo3::exceptions::PyValueError::new_err(format!(
                "{what}: expected (x, y) or (x, y, theta), got {} numbers",
                v.len()
            )));
        }
    };
    Ok(p)
}

/// A point `(x, y)`.
pub fn point_from(what: &str, v: &[f64]) -> PyResult<[f64; 2]> {
    match v {
        [x, y] => Ok([*x, *y]),
        _ => Err(pyo3::exceptions::PyValueError::new_err(format!(
            "{what}: expected (x, y), got {} numbers",
            v.len()
        ))),
    }
}

/// A numpy array of `shape` filled from `data` (one copy).
pub fn array<'py, T: numpy::Element + Copy>(
    py: Python<'py>,
    data: Vec<T>,
    shape: &[usize],
) -> PyResult<Bound<'py, PyAny>> {
    let flat = PyArray1::from_vec(py, data);
    if shape.len() == 1 {
        return Ok(flat.into_any());
    }
    Ok(flat.reshape(shape)?.into_any())
}
