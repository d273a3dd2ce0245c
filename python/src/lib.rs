//! The native half of the `fuzzyvox` Python package (`fuzzyvox._native`): the three maps,
//! integration of point clouds and interval depth images from numpy arrays, queries, native
//! files and exports, the operator catalogue, planning, and the simulated scenarios with their
//! ground truth, and the held-out experiments on real data (`rgbd`, `mono`).
//! `python/fuzzyvox/__init__.py` re-exports it; `docs/python.md` is the tour.
//!
//! Every long call releases the GIL (`Python::detach`); input arrays are read in place where
//! their layout allows; fuzzyvox errors become `fuzzyvox.FuzzyvoxError` subclasses carrying the
//! Rust message.

mod arrays;
mod bag;
mod errors;
mod held_out;
mod maps;
mod plan;
mod rgbd;
mod scenario;

use fuzzyvox_core::{AnyMap, Family, TConorm};
use numpy::PyArray2;
use pyo3::prelude::*;

use crate::errors::{OrRaise, invalid};

/// A map of whichever class the bytes of a native file (``to_bytes``) hold.
#[pyfunction]
fn from_bytes(py: Python<'_>, data: &[u8]) -> PyResult<Py<PyAny>> {
    let data = data.to_vec();
    let map = py.detach(|| AnyMap::from_bytes(&data)).or_raise()?;
    maps::wrap(py, map)
}

/// Loads a native ``.fvx`` map file of any kind.
#[pyfunction]
fn load(py: Python<'_>, path: std::path::PathBuf) -> PyResult<Py<PyAny>> {
    let map = py.detach(|| AnyMap::load(&path)).or_raise()?;
    maps::wrap(py, map)
}

/// The t-conorm catalogue: one representative of every family, as ``NAME`` or ``NAME:PARAM``
/// (default parameters), each accepted by ``FuzzyMap(res, op=...)``.
#[pyfunction]
fn operators() -> Vec<String> {
    Family::catalogue().iter().map(|f| f.to_string()).collect()
}

/// A parsed t-conorm.
#[pyclass(module = "fuzzyvox", frozen)]
struct Operator {
    conorm: TConorm,
}

#[pymethods]
impl Operator {
    /// ``Operator("dombi:2")`` is ``parse_operator("dombi:2")``.
    #[new]
    fn new(text: &str) -> PyResult<Self> {
        parse_operator(text)
    }

    /// Pickles as its canonical name.
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> (Bound<'py, pyo3::types::PyType>, (String,)) {
        (slf.get_type(), (slf.get().conorm.family().to_string(),))
    }

    fn __eq__(&self, other: &Self) -> bool {
        self.conorm.family() == other.conorm.family()
    }

    fn __hash__(&self) -> u64 {
        use std::hash::{Hash, Hasher};
        let mut h = std::collections::hash_map::DefaultHasher::new();
        self.conorm.family().to_string().hash(&mut h);
        h.finish()
    }

    /// The family's name (``dombi``).
    #[getter]
    fn name(&self) -> &'static str {
        self.conorm.family().name()
    }

    /// The t-conorm's own name (``Dombi t-conorm`` style, as the reports print it).
    #[getter]
    fn conorm_name(&self) -> &'static str {
        self.conorm.family().conorm_name()
    }

    /// The family's parameter, or None for families without one.
    #[getter]
    fn parameter(&self) -> Option<f64> {
        self.conorm.family().parameter()
    }

    /// The parameter's name (``lambda``), or None.
    #[getter]
    fn parameter_name(&self) -> Option<&'static str> {
        self.conorm.family().parameter_name()
    }

    /// ``S(x, y)`` for two memberships in [0, 1].
    fn apply(&self, x: f32, y: f32) -> PyResult<f32> {
        if !(0.0..=1.0).contains(&x) || !(0.0..=1.0).contains(&y) {
            return Err(invalid(format!(
                "memberships must lie in [0, 1], got {x} and {y}"
            )));
        }
        Ok(self.conorm.apply(x, y))
    }

    fn __str__(&self) -> String {
        self.conorm.family().to_string()
    }

    fn __repr__(&self) -> String {
        format!("Operator({:?})", self.conorm.family().to_string())
    }
}

/// Parses a t-conorm given as ``NAME`` or ``NAME:PARAM`` (case-insensitive; ``"dombi:2"``,
/// ``"max"``); raises ``fuzzyvox.InvalidInputError`` for an unknown name or a bad parameter.
#[pyfunction]
fn parse_operator(text: &str) -> PyResult<Operator> {
    Ok(Operator {
        conorm: maps::operator_of(text)?,
    })
}

/// Reads a text point cloud (``x y z`` or ``x y z confidence`` per line, as OctoMap's
/// ``scan.dat``): returns ``(points, confidence)``, an (N, 3) float64 array and an (N,) float32
/// array or None.
#[pyfunction]
#[allow(clippy::type_complexity)]
fn read_cloud<'py>(
    py: Python<'py>,
    path: std::path::PathBuf,
) -> PyResult<(
    Bound<'py, PyArray2<f64>>,
    Option<Bound<'py, numpy::PyArray1<f32>>>,
)> {
    let cloud = py
        .detach(|| fuzzyvox_io::read_text_cloud(&path, nalgebra::Point3::origin()))
        .or_raise()?;
    let points = arrays::points_out(py, cloud.points());
    let confidence = cloud
        .confidence()
        .map(|c| arrays::vector_out(py, c.to_vec()));
    Ok((points, confidence))
}

/// The native module.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<maps::FuzzyMap>()?;
    m.add_class::<maps::LogOddsMap>()?;
    m.add_class::<maps::AlphaCutMap>()?;
    m.add_class::<plan::Plan>()?;
    m.add_class::<Operator>()?;
    m.add_class::<rgbd::RgbdFolder>()?;
    m.add_class::<scenario::Scenario>()?;
    m.add_class::<scenario::GroundTruth>()?;
    m.add_class::<scenario::Experiment>()?;
    m.add_function(wrap_pyfunction!(from_bytes, m)?)?;
    m.add_function(wrap_pyfunction!(load, m)?)?;
    m.add_function(wrap_pyfunction!(operators, m)?)?;
    m.add_function(wrap_pyfunction!(parse_operator, m)?)?;
    m.add_function(wrap_pyfunction!(read_cloud, m)?)?;
    m.add_function(wrap_pyfunction!(bag::bag_info, m)?)?;
    m.add_function(wrap_pyfunction!(bag::read_bag, m)?)?;
    m.add_function(wrap_pyfunction!(plan::plan, m)?)?;
    m.add_function(wrap_pyfunction!(scenario::run_experiment, m)?)?;
    m.add_function(wrap_pyfunction!(held_out::rgbd, m)?)?;
    m.add_function(wrap_pyfunction!(held_out::mono, m)?)?;
    m.add(
        "CLASS_NAMES",
        pyo3::types::PyTuple::new(m.py(), maps::CLASS_NAMES)?,
    )?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
