//! The simulated scenarios, their ground truth and the experiment runner, so that an operator
//! study runs from Python as `fuzzyvox eval` runs it.

use std::sync::Arc;

use fuzzyvox_core::Family;
use fuzzyvox_eval::{
    ExperimentConfig, GroundTruth as RustTruth, evaluate, gold_standard, run_experiment as run,
};
use fuzzyvox_sim::scenario::{self, Scenario as RustScenario};
use numpy::PyArray2;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::arrays;
use crate::errors::{OrRaise, invalid};
use crate::maps::{with_map, wrap};

/// A JSON value as Python objects (through the standard library's `json`).
pub(crate) fn json_to_py<'py>(
    py: Python<'py>,
    value: &impl serde::Serialize,
) -> PyResult<Bound<'py, PyAny>> {
    let text = serde_json::to_string(value).map_err(|e| invalid(e.to_string()))?;
    py.import("json")?.call_method1("loads", (text,))
}

/// A simulated world with a camera flight through it: ``Scenario.wall()`` (a wall seen by 6
/// strafing, then 6 receding stereo pairs) or ``Scenario.random(pairs=100, seed=1)`` (a random
/// flight over terrain with buildings and trees).
#[pyclass(module = "fuzzyvox", frozen)]
pub struct Scenario {
    inner: Arc<RustScenario>,
}

#[pymethods]
impl Scenario {
    /// The wall scenario.
    #[staticmethod]
    fn wall(py: Python<'_>) -> PyResult<Self> {
        let inner = py.detach(scenario::wall).or_raise()?;
        Ok(Self {
            inner: Arc::new(inner),
        })
    }

    /// The random-flight scenario with ``pairs`` stereo pairs and the flight of ``seed``.
    #[staticmethod]
    #[pyo3(signature = (pairs=100, seed=1))]
    fn random(py: Python<'_>, pairs: usize, seed: u64) -> PyResult<Self> {
        if pairs == 0 {
            return Err(invalid("pairs must be at least 1"));
        }
        let inner = py.detach(|| scenario::random(pairs, seed)).or_raise()?;
        Ok(Self {
            inner: Arc::new(inner),
        })
    }

    /// ``"wall"`` or ``"random"``.
    #[getter]
    fn name(&self) -> &'static str {
        self.inner.name
    }

    /// Number of stereo pairs.
    #[getter]
    fn pairs(&self) -> usize {
        self.inner.pairs.len()
    }

    /// Named phases of the flight as (name, first pair, end pair) tuples.
    #[getter]
    fn phases(&self) -> Vec<(&'static str, usize, usize)> {
        self.inner
            .phases
            .iter()
            .map(|(n, r)| (*n, r.start, r.end))
            .collect()
    }

    /// Farthest distance the cameras and maps consider, metres.
    #[getter]
    fn max_range(&self) -> f64 {
        self.inner.max_range
    }

    /// The ground truth at ``res`` metres: the voxels that meet the scene's geometry inside the
    /// region the cameras could observe (true depth integrated into a log-odds map).
    fn ground_truth(&self, py: Python<'_>, res: f64) -> PyResult<GroundTruth> {
        let scenario = self.inner.clone();
        let truth = py
            .detach(|| {
                let references: Vec<_> = scenario.pairs.iter().map(|p| p.0).collect();
                let gold = gold_standard(
                    &scenario.scene,
                    &scenario.intrinsics,
                    &references,
                    res,
                    scenario.max_range,
                )?;
                Ok::<_, fuzzyvox_core::Error>(RustTruth::from_scene(&scenario.scene, &gold))
            })
            .or_raise()?;
        Ok(GroundTruth {
            truth,
            scenario: self.inner.clone(),
        })
    }

    fn __repr__(&self) -> String {
        format!(
            "Scenario({:?}, pairs={})",
            self.inner.name,
            self.inner.pairs.len()
        )
    }
}

/// A scenario's ground truth at one resolution; ``evaluate(map)`` measures a map against it.
#[pyclass(module = "fuzzyvox", frozen)]
pub struct GroundTruth {
    truth: RustTruth,
    scenario: Arc<RustScenario>,
}

#[pymethods]
impl GroundTruth {
    /// Voxel size, metres.
    #[getter]
    fn resolution(&self) -> f64 {
        self.truth.resolution().size()
    }

    /// Number of truly occupied voxels.
    #[getter]
    fn occupied_count(&self) -> usize {
        self.truth.occupied_count()
    }

    /// Number of voxels the cameras could observe.
    #[getter]
    fn observed_count(&self) -> usize {
        self.truth.observed_count()
    }

    /// Centres of the truly occupied voxels: an (M, 3) float64 array.
    fn occupied_centres<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let r = self.truth.resolution();
        let points: Vec<_> = self.truth.occupied().map(|k| r.center(k)).collect();
        arrays::points_out(py, &points)
    }

    /// The map's metrics against this truth, as a dict: ``occupied_precision``,
    /// ``occupied_recall``, ``occupied_f1``, ``holes`` (truly occupied voxels the map calls
    /// free), ``spurious_unknown`` (occupied voxels where the truth is unobservable),
    /// ``chamfer_m``, ``occupied``, ``free``. The map must have the truth's resolution.
    fn evaluate<'py>(
        &self,
        py: Python<'py>,
        map: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let metrics = with_map(map, |m| {
            let m = m.as_map();
            if m.resolution() != self.truth.resolution() {
                return Err(invalid(format!(
                    "the map's resolution ({} m) is not the truth's ({} m)",
                    m.resolution().size(),
                    self.truth.resolution().size()
                )));
            }
            Ok(py.detach(|| evaluate(m, &self.truth, &self.scenario.scene)))
        })??;
        json_to_py(py, &metrics)
    }
}

/// An experiment's results: ``report`` (the same dict ``fuzzyvox eval --json`` prints, with
/// ``maps[name]["metrics"]`` holding each map's holes, spurious voxels and F1) and ``maps``
/// (the maps themselves, by name).
#[pyclass(module = "fuzzyvox", frozen)]
pub struct Experiment {
    #[pyo3(get)]
    report: Py<PyAny>,
    #[pyo3(get)]
    maps: Py<PyDict>,
}

/// Runs ``scenario`` as ``fuzzyvox eval`` does: renders every stereo pair, runs the depth stage
/// once per pair, feeds the same depth to the log-odds, alpha-cut and fuzzy maps plus one fuzzy
/// map per extra t-conorm in ``operators`` (named ``fuzzy:NAME``), and measures each against
/// the ground truth. The GIL is released while it runs.
#[pyfunction]
#[pyo3(signature = (scenario, res=0.2, operators=None, seed=1))]
pub fn run_experiment(
    py: Python<'_>,
    scenario: &Scenario,
    res: f64,
    operators: Option<Vec<String>>,
    seed: u64,
) -> PyResult<Experiment> {
    let operators = operators
        .unwrap_or_default()
        .iter()
        .map(|op| {
            op.parse::<Family>()
                .map_err(|e| invalid(format!("operator {op:?}: {e}")))
        })
        .collect::<PyResult<Vec<_>>>()?;
    let sc = scenario.inner.clone();
    let config = ExperimentConfig {
        resolution: res,
        operators,
        seed,
        // No depth images are kept for figures.
        sample_pairs: Vec::new(),
        ..ExperimentConfig::default()
    };
    let output = py.detach(|| run(&sc, &config)).or_raise()?;
    let report = json_to_py(py, &output.report)?.unbind();
    let maps = PyDict::new(py);
    for (name, map) in output.maps {
        maps.set_item(name, wrap(py, map)?)?;
    }
    Ok(Experiment {
        report,
        maps: maps.unbind(),
    })
}
