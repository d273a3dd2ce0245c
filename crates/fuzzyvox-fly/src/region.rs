//! The box a flight plans in.

use fuzzyvox_core::error::Result;
use fuzzyvox_core::storage::Resolution;
use fuzzyvox_plan::PlanningRegion;
use nalgebra::Point3;

use crate::config::FlyConfig;

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
