//! Rust errors as Python exceptions. The classes live in `fuzzyvox/_errors.py` so that they can
//! derive from both `fuzzyvox.FuzzyvoxError` and the matching built-in (`ValueError`, `OSError`,
//! `RuntimeError`); each carries the Rust message.

use fuzzyvox_core::Error;
use fuzzyvox_plan::PlanError;
use pyo3::prelude::*;

/// An instance of `fuzzyvox._errors.<class>` carrying `message`, as a `PyErr`. Falls back to a
/// plain `RuntimeError` if the Python half of the package cannot be imported.
fn raise(py: Python<'_>, class: &str, message: String) -> PyErr {
    let made = py
        .import("fuzzyvox._errors")
        .and_then(|module| module.getattr(class))
        .and_then(|class| class.call1((message.clone(),)));
    match made {
        Ok(instance) => PyErr::from_value(instance),
        Err(_) => pyo3::exceptions::PyRuntimeError::new_err(message),
    }
}

/// An instance of `fuzzyvox._errors.<class>` carrying `message`, as a `PyErr`.
pub fn raise_class(class: &str, message: String) -> PyErr {
    Python::attach(|py| raise(py, class, message))
}

/// Bad input: `fuzzyvox.InvalidInputError`, a `ValueError`.
pub fn invalid(message: impl Into<String>) -> PyErr {
    Python::attach(|py| raise(py, "InvalidInputError", message.into()))
}

/// A fuzzyvox error as the matching Python exception: file problems become
/// `fuzzyvox.MapFileError` (an `OSError`), a refused plan `fuzzyvox.PlanError`, anything else
/// `fuzzyvox.InvalidInputError` (a `ValueError`).
pub fn to_py(error: Error) -> PyErr {
    let message = error.to_string();
    let class = match &error {
        Error::Io { .. } => "MapFileError",
        Error::Format { path, .. } | Error::Parse { path, .. }
            if path.as_os_str() != "<memory>" =>
        {
            "MapFileError"
        }
        Error::Plan(_) => "PlanError",
        _ => "InvalidInputError",
    };
    Python::attach(|py| raise(py, class, message))
}

/// A plan that was refused or found no path: `fuzzyvox.PlanError` with a `failure` attribute
/// (`out_of_region`, `start_unsafe`, `goal_unsafe`, `disconnected`); a bad request (a map or
/// configuration error) is `fuzzyvox.InvalidInputError`.
pub fn plan_error(error: PlanError) -> PyErr {
    let failure = match &error {
        PlanError::OutOfRegion(_) => "out_of_region",
        PlanError::StartUnsafe(_) => "start_unsafe",
        PlanError::GoalUnsafe(_) => "goal_unsafe",
        // The Python planner avoids no voxels, so this one does not arise; named for completeness.
        PlanError::GoalAvoided => "goal_avoided",
        PlanError::Disconnected { .. } => "disconnected",
        PlanError::Map(_) => return to_py(Error::from(error)),
    };
    let message = error.to_string();
    Python::attach(|py| {
        let err = raise(py, "PlanError", message);
        // The attribute is a convenience; the message says the same.
        let _ = err.value(py).setattr("failure", failure);
        err
    })
}

/// Turns a fuzzyvox result into a Python one.
pub trait OrRaise<T> {
    /// The value, or the error as a Python exception.
    fn or_raise(self) -> PyResult<T>;
}

impl<T> OrRaise<T> for fuzzyvox_core::Result<T> {
    fn or_raise(self) -> PyResult<T> {
        self.map_err(to_py)
    }
}
