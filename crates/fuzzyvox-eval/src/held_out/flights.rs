//! Flights through real maps: start/goal pairs drawn in the free space of a reference map built
//! from the folder's own sensor depth (all frames, the standard log-odds method, as `eval`'s
//! gold standard), near where the camera went; planned in every camera-only map and in the
//! reference with unknown space forbidden; every path checked against the reference's occupied
//! voxels.

use fuzzyvox_core::error::{Error, Result};
use fuzzyvox_core::integrate::IntegrationOptions;
use fuzzyvox_core::map::{LogOddsConfig, LogOddsMap, VoxelMap, VoxelMapMut};
use fuzzyvox_io::posed::PosedFrames;
use fuzzyvox_plan::{PlannerConfig, UnknownPolicy};
use nalgebra::Point3;
use serde::Serialize;

use crate::flights::{
    Candidates, FlightSummary, OccupiedVoxels, QueryConfig, draw_queries, plan_queries, summarize,
};

/// How flights through real maps are drawn and flown (`fuzzyvox mono --plan N`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RealFlightConfig {
    /// Start/goal pairs to draw.
    pub queries: usize,
    /// Seed of the draw.
    pub seed: u64,
    /// The vehicle's radius, metres: starts and goals keep it from the reference's occupied
    /// voxels, and a path collides where a point of it comes nearer to one. Default 0.2.
    pub vehicle_radius: f64,
    /// Shortest and longest straight-line distance between start and goal, metres. Default 1
    /// to 4 (a room).
    pub distance: (f64, f64),
    /// Starts and goals lie within this distance of a camera position, metres. Default 1.
    pub reach: f64,
}

impl RealFlightConfig {
    /// `queries` pairs with the defaults.
    pub fn new(queries: usize) -> Self {
        Self {
            queries,
            seed: 1,
            vehicle_radius: 0.2,
            distance: (1.0, 4.0),
            reach: 1.0,
        }
    }

    /// Checks every value.
    pub fn validate(&self) -> Result<()> {
        if self.queries == 0 {
            return Err(Error::InvalidParameter {
                name: "flights to plan",
                value: 0.0,
                expected: "at least 1",
            });
        }
        if !(self.reach.is_finite() && self.reach > 0.0) {
            return Err(Error::InvalidParameter {
                name: "reach from the camera path",
                value: self.reach,
                expected: "a finite distance > 0 m",
            });
        }
        self.query_config().validate().map(|_| ())
    }

    /// The drawer's settings: the planner with the vehicle's radius and unknown space
    /// forbidden; no altitude band (the candidates come from near the camera path).
    pub fn query_config(&self) -> QueryConfig {
        QueryConfig {
            queries: self.queries,
            seed: self.seed,
            planner: PlannerConfig {
                vehicle_radius: self.vehicle_radius,
                unknown: UnknownPolicy::Forbid,
                ..PlannerConfig::default()
            },
            distance: self.distance,
            altitude: (0.0, f64::MAX),
            surface_margin: 0.0,
        }
    }
}

/// One camera-only map's flights: the open-loop figures of `eval --plan`, and what the
/// reference map solved of the same queries.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RealFlights {
    /// The map's paths: queries, success, collisions with the reference's occupied voxels,
    /// failures by reason and every collision explained.
    #[serde(flatten)]
    pub summary: FlightSummary,
    /// The fraction of the queries the reference map solved.
    pub reference_plan_success: f64,
}

/// The reference map of `folder`: the sensor depth of every frame that has it, inserted into a
/// log-odds map at `resolution` metres. `None` when no frame has sensor depth.
pub(super) fn reference_map(
    folder: &dyn PosedFrames,
    resolution: f64,
) -> Result<Option<LogOddsMap>> {
    let mut reference = LogOddsMap::new(LogOddsConfig::new(resolution)?)?;
    let mut any = false;
    for position in 0..folder.len() {
        if let Some(sensor) = folder.read_sensor_depth(position)? {
            reference.integrate_depth(&sensor, &IntegrationOptions::default())?;
            any = true;
        }
    }
    Ok(any.then_some(reference))
}

/// Draws the queries near the camera path `cameras` in `reference`'s free space, plans them in
/// every map of `maps` and in the reference, and checks every path against the reference's
/// occupied voxels; one [`RealFlights`] per map, in order.
pub(super) fn fly_real(
    maps: &[&dyn VoxelMap],
    reference: &dyn VoxelMap,
    cameras: &[Point3<f64>],
    config: &RealFlightConfig,
) -> Result<Vec<RealFlights>> {
    config.validate()?;
    let queries_config = config.query_config();
    // Distances are searched a metre beyond the radius: enough for the clearance of starts and
    // goals, and for the distance of a collision's point to the nearest surface.
    let obstacles = OccupiedVoxels::new(reference, config.vehicle_radius + 1.0);
    let candidates = Candidates::NearPath {
        reference,
        path: cameras,
        reach: config.reach,
    };
    let queries = draw_queries(&obstacles, candidates, &queries_config)?;
    let planner = queries_config.planner;
    let reference_outcomes = plan_queries(reference, &obstacles, &queries, &planner);
    let reference_success = summarize(&reference_outcomes, &reference_outcomes).plan_success;
    Ok(maps
        .iter()
        .map(|map| RealFlights {
            summary: summarize(
                &plan_queries(*map, &obstacles, &queries, &planner),
                &reference_outcomes,
            ),
            reference_plan_success: reference_success,
        })
        .collect())
}
