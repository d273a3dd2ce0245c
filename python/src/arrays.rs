//! numpy arrays in and out. Inputs go through `numpy.asarray(x, dtype=...)`, which returns the
//! array itself (no copy) when it already has the dtype, and are then read in place: as one
//! slice when C-contiguous, element by element otherwise. Values are copied once, into the
//! Rust types the maps take, before the GIL is released (so that another Python thread
//! writing to the array cannot change them mid-call).

use nalgebra::{Matrix4, Point3};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::invalid;

/// `numpy.asarray(obj, dtype=dtype)` read as an array of `T`.
fn as_array<'py, T: numpy::Element>(
    obj: &Bound<'py, PyAny>,
    dtype: &str,
    what: &str,
) -> PyResult<PyReadonlyArrayDyn<'py, T>> {
    let py = obj.py();
    let kwargs = PyDict::new(py);
    kwargs.set_item("dtype", dtype)?;
    let array = py
        .import("numpy")?
        .call_method("asarray", (obj,), Some(&kwargs))
        .map_err(|e| invalid(format!("{what}: not convertible to a {dtype} array ({e})")))?;
    array
        .extract::<PyReadonlyArrayDyn<'py, T>>()
        .map_err(|e| invalid(format!("{what}: {e}")))
}

/// A shape as Python prints it: `(3, 2)`.
fn shape_str(shape: &[usize]) -> String {
    match shape {
        [one] => format!("({one},)"),
        _ => format!(
            "({})",
            shape
                .iter()
                .map(usize::to_string)
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

/// The values of an array in C order: a copy of its slice when C-contiguous, else gathered
/// element by element.
fn values<T: numpy::Element + Copy>(array: &PyReadonlyArrayDyn<'_, T>) -> Vec<T> {
    match c_slice(array) {
        Some(slice) => slice.to_vec(),
        None => array.as_array().iter().copied().collect(),
    }
}

/// The array's memory as one slice in C order, when it is laid out so (`as_slice` also accepts
/// Fortran order, whose slice is column-major).
fn c_slice<'a, T: numpy::Element>(array: &'a PyReadonlyArrayDyn<'_, T>) -> Option<&'a [T]> {
    if array.is_c_contiguous() {
        array.as_slice().ok()
    } else {
        None
    }
}

/// An `(N, 3)` float64 array as points.
pub fn points(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<Point3<f64>>> {
    let array = as_array::<f64>(obj, "float64", what)?;
    let shape = array.shape();
    if shape.len() != 2 || shape[1] != 3 {
        return Err(invalid(format!(
            "{what} must be an (N, 3) array, got shape {}",
            shape_str(shape)
        )));
    }
    let to_point = |c: &[f64]| Point3::new(c[0], c[1], c[2]);
    Ok(match c_slice(&array) {
        Some(slice) => slice.chunks_exact(3).map(to_point).collect(),
        None => array
            .as_array()
            .rows()
            .into_iter()
            .map(|row| Point3::new(row[0], row[1], row[2]))
            .collect(),
    })
}

/// A point given as any sequence of three numbers; it must be finite.
pub fn point(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Point3<f64>> {
    let array = as_array::<f64>(obj, "float64", what)?;
    if array.shape() != [3] {
        return Err(invalid(format!(
            "{what} must hold 3 numbers (x, y, z), got shape {}",
            shape_str(array.shape())
        )));
    }
    let v = values(&array);
    if let Some(bad) = v.iter().find(|x| !x.is_finite()) {
        return Err(invalid(format!("{what} must be finite, got {bad}")));
    }
    Ok(Point3::new(v[0], v[1], v[2]))
}

/// An `(N,)` float32 array (per-point values).
pub fn vector_f32(obj: &Bound<'_, PyAny>, what: &str, len: usize) -> PyResult<Vec<f32>> {
    let array = as_array::<f32>(obj, "float32", what)?;
    if array.shape() != [len] {
        return Err(invalid(format!(
            "{what} must be an ({len},) array, got shape {}",
            shape_str(array.shape())
        )));
    }
    Ok(values(&array))
}

/// An `(H, W)` float32 image plane, row-major, with its size.
pub fn plane_f32(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<(usize, usize, Vec<f32>)> {
    let array = as_array::<f32>(obj, "float32", what)?;
    let shape = array.shape();
    if shape.len() != 2 {
        return Err(invalid(format!(
            "{what} must be an (H, W) array, got shape {}",
            shape_str(shape)
        )));
    }
    let (h, w) = (shape[0], shape[1]);
    Ok((h, w, values(&array)))
}

/// A 4×4 float64 matrix (row-major, as numpy prints it).
pub fn matrix4(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Matrix4<f64>> {
    let array = as_array::<f64>(obj, "float64", what)?;
    if array.shape() != [4, 4] {
        return Err(invalid(format!(
            "{what} must be a 4x4 array, got shape {}",
            shape_str(array.shape())
        )));
    }
    Ok(Matrix4::from_row_slice(&values(&array)))
}

/// Points as an `(N, 3)` float64 array.
pub fn points_out<'py>(py: Python<'py>, points: &[Point3<f64>]) -> Bound<'py, PyArray2<f64>> {
    let flat: Vec<f64> = points.iter().flat_map(|p| [p.x, p.y, p.z]).collect();
    rows_out(py, flat, 3)
}

/// A flat row-major vector as an `(len / cols, cols)` array.
pub fn rows_out<'py, T: numpy::Element>(
    py: Python<'py>,
    flat: Vec<T>,
    cols: usize,
) -> Bound<'py, PyArray2<T>> {
    let rows = flat.len() / cols;
    numpy::ndarray::Array2::from_shape_vec((rows, cols), flat)
        .map(|a| a.into_pyarray(py))
        .unwrap_or_else(|_| PyArray2::zeros(py, [0, cols], false))
}

/// A vector as an `(N,)` array.
pub fn vector_out<'py, T: numpy::Element>(py: Python<'py>, v: Vec<T>) -> Bound<'py, PyArray1<T>> {
    v.into_pyarray(py)
}
