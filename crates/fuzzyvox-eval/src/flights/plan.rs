//! Every query planned in a map, and every path checked against the true world.

use fuzzyvox_core::map::VoxelMap;
use fuzzyvox_core::measures::{Memberships, VoxelClass};
use fuzzyvox_plan::{PlannerConfig, plan_path};
use nalgebra::Point3;
use rayon::prelude::*;

use super::outcome::{BlockingClass, CollisionDetail, FlightFailure, FlightOutcome};
use super::queries::FlightQuery;
use super::world::{Obstacles, path_contact};

/// Plans every query in `map` with `planner` and checks each path against `world` with a
/// ball of the vehicle's radius; a path that meets it is explained
/// ([`FlightOutcome::collision`]).
pub fn plan_queries(
    map: &dyn VoxelMap,
    world: &dyn Obstacles,
    queries: &[FlightQuery],
    planner: &PlannerConfig,
) -> Vec<FlightOutcome> {
    queries
        .par_iter()
        .map(|q| match plan_path(map, &q.from, &q.to, planner) {
            Ok(path) => {
                let contact = path_contact(world, &path.waypoints, planner.vehicle_radius);
                FlightOutcome {
                    collides: contact.is_some(),
                    collision: contact.map(|point| explain(map, world, q, point)),
                    length: Some(path.length),
                    waypoints: Some(path.waypoints),
                    failure: None,
                    blocked_by: None,
                }
            }
            Err(error) => FlightOutcome {
                waypoints: None,
                length: None,
                collides: false,
                failure: Some(FlightFailure::of(&error)),
                blocked_by: error.blocker().and_then(BlockingClass::of),
                collision: None,
            },
        })
        .collect()
}

/// What `map` said at `point`, where the path of `query` met `world`.
fn explain(
    map: &dyn VoxelMap,
    world: &dyn Obstacles,
    query: &FlightQuery,
    point: Point3<f64>,
) -> CollisionDetail {
    let (class, memberships) = match map.resolution().key_of(&point) {
        Ok(key) => (map.class_at(key), map.memberships_at(key)),
        Err(_) => (VoxelClass::Unknown, Memberships::default()),
    };
    CollisionDetail {
        from: query.from,
        to: query.to,
        point,
        class: class.name(),
        occupied: memberships.occupied,
        free: memberships.free,
        distance_to_surface: world.distance_to_surface(&point),
    }
}
