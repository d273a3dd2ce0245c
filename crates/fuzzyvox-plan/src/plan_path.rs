//! The front door: [`plan_path`] plans once between two points of any map.

use fuzzyvox_core::map::VoxelMap;
use fuzzyvox_core::storage::VoxelKey;
use nalgebra::Point3;

use crate::blocker::{Blocker, ObservedExtent};
use crate::config::PlannerConfig;
use crate::error::PlanError;
use crate::path::Path;
use crate::planner::Planner;
use crate::region::PlanningRegion;

/// Plans from `from` to `to` in any map, once: a [`Planner`] over the box around both points
/// grown by a margin (the vehicle radius plus the preferred clearance plus 2 m). To plan again
/// and again while a map grows, keep a [`Planner`] and update it instead.
///
/// A start or goal in unknown space that also lies outside the map's [`ObservedExtent`] is
/// reported as [`Blocker::OutsideObservedExtent`] rather than [`Blocker::Unknown`]: a point
/// off the map is usually a mistyped coordinate or a map of the wrong place.
pub fn plan_path(
    map: &dyn VoxelMap,
    from: &Point3<f64>,
    to: &Point3<f64>,
    config: &PlannerConfig,
) -> Result<Path, PlanError> {
    let config = config.validate()?;
    let resolution = map.resolution();
    let start = resolution.key_of(from)?;
    let goal = resolution.key_of(to)?;
    let margin = config.vehicle_radius + config.preferred_clearance + 2.0;
    let region = PlanningRegion::around(&resolution, from, to, margin)?;
    let planner = Planner::new(map, region, config)?;
    // The extent costs a pass over the map, so it is only computed for an unknown end point.
    let off_map = |point: &Point3<f64>, key: VoxelKey| {
        ObservedExtent::of(map)
            .filter(|extent| !extent.contains(key))
            .map_or(Blocker::Unknown, |extent| Blocker::OutsideObservedExtent {
                point: *point,
                extent,
            })
    };
    match planner.plan(start, goal) {
        Err(PlanError::StartUnsafe(Blocker::Unknown)) => {
            Err(PlanError::StartUnsafe(off_map(from, start)))
        }
        Err(PlanError::GoalUnsafe(Blocker::Unknown)) => {
            Err(PlanError::GoalUnsafe(off_map(to, goal)))
        }
        result => result,
    }
}
