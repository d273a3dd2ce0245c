//! Planning: A* through any map, with the plan's figures.

use fuzzyvox_plan::{PlannerConfig, UnknownPolicy, plan_path};
use nalgebra::Point3;
use numpy::PyArray2;
use pyo3::prelude::*;

use crate::arrays;
use crate::errors::{invalid, plan_error};
use crate::maps::with_map;

/// A planned path: waypoints and the figures that say how good it is.
#[pyclass(module = "fuzzyvox", frozen)]
pub struct Plan {
    waypoints: Vec<Point3<f64>>,
    /// Length of the waypoint polyline, metres.
    #[pyo3(get)]
    length: f64,
    /// Cost of the A* path before shortcutting (metres weighted by the cost field).
    #[pyo3(get)]
    cost: f64,
    /// Lowest safety of any voxel the path passes through.
    #[pyo3(get)]
    min_safety: f32,
    /// Lowest clearance (metres, voxel centre to the nearest blocked voxel centre) along the
    /// path.
    #[pyo3(get)]
    min_clearance: f32,
    /// Nodes A* expanded.
    #[pyo3(get)]
    expanded: usize,
}

#[pymethods]
impl Plan {
    /// A plan from its parts (as pickling rebuilds one); ``plan()`` makes plans.
    #[new]
    #[pyo3(signature = (waypoints, length, cost, min_safety, min_clearance, expanded))]
    fn new(
        waypoints: &Bound<'_, PyAny>,
        length: f64,
        cost: f64,
        min_safety: f32,
        min_clearance: f32,
        expanded: usize,
    ) -> PyResult<Self> {
        Ok(Self {
            waypoints: arrays::points(waypoints, "waypoints")?,
            length,
            cost,
            min_safety,
            min_clearance,
            expanded,
        })
    }

    /// Pickles through its parts.
    #[allow(clippy::type_complexity)]
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> PyResult<(
        Bound<'py, pyo3::types::PyType>,
        (Bound<'py, PyArray2<f64>>, f64, f64, f32, f32, usize),
    )> {
        let py = slf.py();
        let p = slf.get();
        Ok((
            slf.get_type(),
            (
                arrays::points_out(py, &p.waypoints),
                p.length,
                p.cost,
                p.min_safety,
                p.min_clearance,
                p.expanded,
            ),
        ))
    }

    /// The waypoints (voxel centres, start first): a (K, 3) float64 array.
    #[getter]
    fn waypoints<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        arrays::points_out(py, &self.waypoints)
    }

    fn __len__(&self) -> usize {
        self.waypoints.len()
    }

    fn __repr__(&self) -> String {
        format!(
            "Plan(waypoints={}, length={:.3}, cost={:.3}, min_safety={:.3}, min_clearance={:.3})",
            self.waypoints.len(),
            self.length,
            self.cost,
            self.min_safety,
            self.min_clearance
        )
    }
}

/// Plans a path from ``start`` to ``goal`` through ``map`` (any of the three maps) for a
/// vehicle of ``radius`` metres, through voxels whose safety is at least ``safety``.
///
/// ``unknown="forbid"`` flies only known-safe space; ``unknown="cost"`` allows unknown space at
/// an extra cost per metre (``unknown_cost``, 5 by default). A refused start or goal, or no path,
/// raises ``fuzzyvox.PlanError`` (its ``failure`` attribute names why; the message says what
/// blocks and which setting would change it). The GIL is released while planning.
#[pyfunction]
#[pyo3(signature = (map, start, goal, radius=0.3, unknown="forbid", unknown_cost=None, safety=0.2))]
#[allow(clippy::too_many_arguments)]
pub fn plan(
    py: Python<'_>,
    map: &Bound<'_, PyAny>,
    start: &Bound<'_, PyAny>,
    goal: &Bound<'_, PyAny>,
    radius: f64,
    unknown: &str,
    unknown_cost: Option<f32>,
    safety: f32,
) -> PyResult<Plan> {
    let start = arrays::point(start, "start")?;
    let goal = arrays::point(goal, "goal")?;
    let unknown = match (unknown, unknown_cost) {
        ("forbid", None) => UnknownPolicy::Forbid,
        ("forbid", Some(_)) => {
            return Err(invalid(
                "unknown_cost only applies with unknown=\"cost\" (unknown space is forbidden by default)",
            ));
        }
        ("cost", cost) => UnknownPolicy::Cost(cost.unwrap_or(5.0)),
        (other, _) => {
            return Err(invalid(format!(
                "unknown={other:?}: expected \"forbid\" or \"cost\""
            )));
        }
    };
    let config = PlannerConfig {
        vehicle_radius: radius,
        safety_threshold: safety,
        unknown,
        ..PlannerConfig::default()
    };
    let path = with_map(map, |map| {
        py.detach(|| plan_path(map.as_map(), &start, &goal, &config))
    })?
    .map_err(plan_error)?;
    Ok(Plan {
        waypoints: path.waypoints,
        length: path.length,
        cost: path.cost,
        min_safety: path.min_safety,
        min_clearance: path.min_clearance,
        expanded: path.expanded,
    })
}
