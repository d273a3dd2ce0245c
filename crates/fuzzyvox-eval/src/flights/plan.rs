//! Every query planned in a map, and every path checked against the true world.

use fuzzyvox_core::map::VoxelMap;
use fuzzyvox_plan::{PlannerConfig, plan_path};
use rayon::prelude::*;

use super::outcome::{BlockingClass, FlightFailure, FlightOutcome};
use super::queries::FlightQuery;
use super::world::{Obstacles, path_collides};

/// Plans every query in `map` with `planner` and checks each path against `world` with a
/// ball of the vehicle's radius.
pub fn plan_queries(
    map: &dyn VoxelMap,
    world: &dyn Obstacles,
    queries: &[FlightQuery],
    planner: &PlannerConfig,
) -> Vec<FlightOutcome> {
    queries
        .par_iter()
        .map(|q| match plan_path(map, &q.from, &q.to, planner) {
            Ok(path) => FlightOutcome {
                collides: path_collides(world, &path.waypoints, planner.vehicle_radius),
                length: Some(path.length),
                waypoints: Some(path.waypoints),
                failure: None,
                blocked_by: None,
            },
            Err(error) => FlightOutcome {
                waypoints: None,
                length: None,
                collides: false,
                failure: Some(FlightFailure::of(&error)),
                blocked_by: error.blocker().and_then(BlockingClass::of),
            },
        })
        .collect()
}
