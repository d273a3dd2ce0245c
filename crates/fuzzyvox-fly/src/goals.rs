//! Where flights go: starts and goals in truly free space, the planning region around them,
//! and the path the true scene allows (the yardstick of a flight's length).

use nalgebra::Point3;
use serde::Serialize;

use super::config::FlyConfig;
use crate::error::Result;
use crate::map::FunctionMap;
use crate::measures::Memberships;
use crate::plan::{CostField, PlanningRegion, plan_in_field};
use crate::sim::scenario::Scenario;
use crate::sim::unit_hash;
use crate::storage::{Resolution, VoxelKey};

/// One flight to fly: from a start to a goal, both in truly free space.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Goal {
    /// Where the vehicle takes off.
    pub start: Point3<f64>,
    /// Where it should go.
    pub goal: Point3<f64>,
    /// Length of the path planned in the true scene, metres.
    pub truth_length: f64,
}

/// The box flights between `start` and `goal` plan in: the two points grown by the region
/// margin horizontally, from half a metre above the ground to 4 m above the higher point.
pub fn planning_region(
    resolution: &Resolution,
    start: &Point3<f64>,
    goal: &Point3<f64>,
    config: &FlyConfig,
) -> Result<PlanningRegion> {
    let margin = config.region_margin;
    let lo = Point3::new(
        start.x.min(goal.x) - margin,
        start.y.min(goal.y) - margin,
        0.5,
    );
    let hi = Point3::new(
        start.x.max(goal.x) + margin,
        start.y.max(goal.y) + margin,
        start.z.max(goal.z) + 4.0,
    );
    PlanningRegion::new(resolution.key_of(&lo)?, resolution.key_of(&hi)?)
}

/// The true scene as a map: a voxel that meets any surface is occupied, every other voxel free.
pub fn truth_map(
    scenario: &Scenario,
    resolution: Resolution,
) -> FunctionMap<impl Fn(VoxelKey) -> Memberships + Send + Sync + '_> {
    FunctionMap::new(resolution, move |key: VoxelKey| {
        let half = nalgebra::Vector3::repeat(resolution.size() / 2.0);
        let center = resolution.center(key);
        let (min, max) = (center - half, center + half);
        if scenario.scene.intersects_box(&min, &max) {
            Memberships {
                occupied: 1.0,
                free: 0.0,
            }
        } else {
            Memberships {
                occupied: 0.0,
                free: 1.0,
            }
        }
    })
}

/// Draws `count` flights in `scenario` for `seed`: starts and goals uniformly in the scenario's
/// extent at the configured altitudes, at least the vehicle radius plus the surface margin from
/// every true surface, the configured distance apart, and connected in the true scene (the
/// path planned there gives [`Goal::truth_length`]). Deterministic for a seed; fewer come back
/// when too few candidates exist.
pub fn draw_goals(
    scenario: &Scenario,
    config: &FlyConfig,
    count: usize,
    seed: u64,
) -> Result<Vec<Goal>> {
    let config = config.validate()?;
    let resolution = Resolution::new(config.resolution)?;
    let truth = truth_map(scenario, resolution);
    let [[x0, y0], [x1, y1]] = scenario.extent;
    let (z0, z1) = config.altitude;
    let clearance = config.planner.vehicle_radius + config.surface_margin;
    // Voxel centres, so that every map answers about the same voxel.
    let point = |draw: i64, salt: i64| {
        let uniform = |lo: f64, hi: f64, axis: i64| {
            lo + (hi - lo) * f64::from(unit_hash(draw, salt + axis, 131, seed))
        };
        let p = Point3::new(uniform(x0, x1, 0), uniform(y0, y1, 1), uniform(z0, z1, 2));
        resolution.key_of(&p).map(|key| resolution.center(key))
    };
    let mut goals = Vec::new();
    let attempts = 500 * count as i64 + 100;
    let mut draw = 0i64;
    while goals.len() < count && draw < attempts {
        draw += 1;
        let start = point(draw, 1)?;
        let goal = point(draw, 4)?;
        let distance = (goal - start).norm();
        if distance < config.distance.0
            || distance > config.distance.1
            || scenario.scene.distance_to_surface(&start) < clearance
            || scenario.scene.distance_to_surface(&goal) < clearance
        {
            continue;
        }
        let region = planning_region(&resolution, &start, &goal, &config)?;
        let mut planner = config.planner;
        planner.unknown = crate::plan::UnknownPolicy::Forbid;
        let field = CostField::build(&truth, region, planner)?;
        let (a, b) = (resolution.key_of(&start)?, resolution.key_of(&goal)?);
        if let Ok(path) = plan_in_field(&field, a, b) {
            goals.push(Goal {
                start,
                goal,
                truth_length: path.length,
            });
        }
    }
    Ok(goals)
}
