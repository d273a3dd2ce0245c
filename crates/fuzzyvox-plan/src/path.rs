//! A planned path ([`Path`]) and how one is planned through a cost field: A* over the
//! field's graph with a distance heuristic, then smoothing by line of sight
//! ([`plan_in_field`], [`plan_in_field_avoiding`]).

use fuzzyvox_core::storage::VoxelKey;
use nalgebra::Point3;
use serde::Serialize;

use crate::astar::{Unreached, astar};
use crate::cost_field::CostField;
use crate::error::PlanError;
use crate::heuristic::{GoalProfile, octile};
use crate::smooth::{merge_collinear, segment_voxels, shortcut};

/// A planned path.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Path {
    /// Waypoints in world coordinates (voxel centres), start first, after line-of-sight
    /// shortcutting; no interior waypoint lies on the segment between its neighbours.
    pub waypoints: Vec<Point3<f64>>,
    /// Length of the waypoint polyline in metres.
    pub length: f64,
    /// Cost of the A* path before shortcutting (metres weighted by the cost field).
    pub cost: f64,
    /// Lowest safety of any voxel the final path passes through.
    pub min_safety: f32,
    /// Lowest clearance (metres, voxel centre to the nearest blocked voxel centre) of any voxel
    /// the final path passes through.
    pub min_clearance: f32,
    /// Nodes A* expanded.
    pub expanded: usize,
}

/// A* from `start` to `goal` over the field's 26-connected graph (through petgraph's
/// [`IntoEdges`](petgraph::visit::IntoEdges)), with dense per-voxel arrays and the octile distance times the field's lowest
/// cost rate as a consistent heuristic, then line-of-sight shortcutting checked against the
/// same field and merging of collinear waypoints. Ties are broken by node index, so the result
/// is deterministic.
pub fn plan_in_field(
    field: &CostField,
    start: VoxelKey,
    goal: VoxelKey,
) -> Result<Path, PlanError> {
    unlimited(field, search(field, start, goal, &|_| false, None))
}

/// [`plan_in_field`] that also never enters a voxel (dense index) for which `avoid` is true,
/// the start excepted: a caller's restriction on top of the field, such as the closed loop's
/// guard that keeps the vehicle out of unseen space near it. Shortcuts obey it too.
///
/// A goal it must avoid is refused with [`PlanError::GoalAvoided`].
pub fn plan_in_field_avoiding(
    field: &CostField,
    start: VoxelKey,
    goal: VoxelKey,
    avoid: &dyn Fn(usize) -> bool,
) -> Result<Path, PlanError> {
    unlimited(field, search(field, start, goal, avoid, None))
}

/// A search without a limit always ends with a path or an error: it can expand every voxel.
/// (The `None` arm only keeps the types honest.)
fn unlimited(field: &CostField, found: Result<Option<Path>, PlanError>) -> Result<Path, PlanError> {
    found?.ok_or(PlanError::Disconnected {
        expanded: field.region().len(),
    })
}

/// [`plan_in_field_avoiding`] that gives up after expanding `max_expanded` voxels: `Ok(None)`
/// then. For a caller that already has a path and only looks for a better one (the closed
/// loop's periodic replan), so that the look costs a bounded time.
pub fn plan_in_field_within(
    field: &CostField,
    start: VoxelKey,
    goal: VoxelKey,
    avoid: &dyn Fn(usize) -> bool,
    max_expanded: usize,
) -> Result<Option<Path>, PlanError> {
    search(field, start, goal, avoid, Some(max_expanded))
}

/// The planning of [`plan_in_field_within`], generic over `avoid` so that [`plan_in_field`]
/// pays nothing for it. Without a limit the result is never `Ok(None)`.
fn search<A: Fn(usize) -> bool + ?Sized>(
    field: &CostField,
    start: VoxelKey,
    goal: VoxelKey,
    avoid: &A,
    limit: Option<usize>,
) -> Result<Option<Path>, PlanError> {
    let region = field.region();
    let start_index = region
        .index_of(start)
        .ok_or(PlanError::OutOfRegion("start"))?;
    let goal_index = region
        .index_of(goal)
        .ok_or(PlanError::OutOfRegion("goal"))?;
    if let Some(why) = field.blocker(start_index) {
        return Err(PlanError::StartUnsafe(why));
    }
    if let Some(why) = field.blocker(goal_index) {
        return Err(PlanError::GoalUnsafe(why));
    }
    if goal_index != start_index && avoid(goal_index) {
        return Err(PlanError::GoalAvoided);
    }
    // Exact within one and a half times the start's distance of the goal (plus a margin),
    // where the search stays unless it must go round much of the region.
    let heuristic = GoalProfile::new(field, goal, 1.5 * octile(start, goal) + 8.0);
    let route = astar(
        field,
        start_index,
        goal_index,
        |key| heuristic.cost_to_goal(key),
        avoid,
        limit.unwrap_or(usize::MAX),
    );
    let route = match route {
        Ok(route) => route,
        Err(Unreached::Limit) => return Ok(None),
        Err(Unreached::Disconnected { expanded }) => {
            return Err(PlanError::Disconnected { expanded });
        }
    };
    let voxels: Vec<VoxelKey> = route.nodes.iter().map(|&i| region.key_at(i)).collect();
    let enter =
        |index: usize| field.is_traversable(index) && (index == start_index || !avoid(index));
    let corners = merge_collinear(field, &enter, &shortcut(field, &enter, &voxels));
    let resolution = field.resolution();
    let waypoints: Vec<Point3<f64>> = corners.iter().map(|k| resolution.center(*k)).collect();
    let length = waypoints.windows(2).map(|w| (w[1] - w[0]).norm()).sum();
    let (mut min_safety, mut min_clearance) = (f32::INFINITY, f32::INFINITY);
    for pair in corners.windows(2) {
        segment_voxels(field, pair[0], pair[1], |index| {
            min_safety = min_safety.min(field.safety(index));
            min_clearance = min_clearance.min(field.clearance(index));
            true
        });
    }
    if corners.len() == 1 {
        min_safety = field.safety(start_index);
        min_clearance = field.clearance(start_index);
    }
    Ok(Some(Path {
        waypoints,
        length,
        cost: f64::from(route.cost),
        min_safety,
        min_clearance,
        expanded: route.expanded,
    }))
}

#[cfg(test)]
pub(crate) mod tests {
    use fuzzyvox_core::map::FunctionMap;
    use fuzzyvox_core::measures::Memberships;
    use fuzzyvox_core::storage::Resolution;

    use super::*;
    use crate::config::PlannerConfig;
    use crate::region::PlanningRegion;
    use crate::smooth::segment_voxels;

    /// The field of a 4 × 4 × 2 m box of confident free space at 0.1 m, with a 1 m pillar in
    /// the middle when `pillar`.
    pub(crate) fn open_field(pillar: bool) -> CostField {
        let resolution = Resolution::new(0.1).unwrap();
        let map = FunctionMap::new(resolution, move |key| {
            let inside_pillar = (18..22).contains(&key.x) && (15..25).contains(&key.y);
            if pillar && inside_pillar {
                Memberships {
                    occupied: 0.9,
                    free: 0.0,
                }
            } else {
                Memberships {
                    occupied: 0.0,
                    free: 0.95,
                }
            }
        });
        let region =
            PlanningRegion::new(VoxelKey::new(0, 0, 0), VoxelKey::new(40, 40, 20)).unwrap();
        let config = PlannerConfig {
            vehicle_radius: 0.1,
            ..PlannerConfig::default()
        };
        CostField::build(&map, region, config).unwrap()
    }

    /// A search within a budget gives the unlimited search's path when the budget covers it,
    /// and `None` (not an error) when it does not; refusals come first either way.
    #[test]
    fn a_budget_stops_the_search_without_failing_it() {
        let field = open_field(true);
        let (start, goal) = (VoxelKey::new(5, 20, 10), VoxelKey::new(35, 20, 10));
        let full = plan_in_field(&field, start, goal).unwrap();
        let never = |_: usize| false;
        let within = plan_in_field_within(&field, start, goal, &never, full.expanded).unwrap();
        assert_eq!(within, Some(full.clone()));
        let short = plan_in_field_within(&field, start, goal, &never, full.expanded - 1).unwrap();
        assert_eq!(short, None);
        let pillar = VoxelKey::new(20, 20, 10);
        assert!(matches!(
            plan_in_field_within(&field, start, pillar, &never, 1),
            Err(PlanError::GoalUnsafe(_))
        ));
    }

    /// A wall of avoided voxels across the straight line bends the path around it; no
    /// waypoint and no segment of the path enters an avoided voxel; an avoided goal is refused
    /// as such; avoiding nothing gives `plan_in_field`'s path.
    #[test]
    fn avoided_voxels_bend_the_path_and_an_avoided_goal_is_refused() {
        let field = open_field(false);
        let region = *field.region();
        let (start, goal) = (VoxelKey::new(5, 20, 10), VoxelKey::new(35, 20, 10));
        let direct = plan_in_field(&field, start, goal).unwrap();
        assert_eq!(direct.waypoints.len(), 2, "open space: one straight leg");
        assert_eq!(
            plan_in_field_avoiding(&field, start, goal, &|_| false)
                .unwrap()
                .waypoints,
            direct.waypoints
        );
        // A 1.4 m wide plate at x = 2 m across the line, every z.
        let wall = |index: usize| {
            let [x, y, _] = region.coordinates_at(index);
            x == 20 && (13..=27).contains(&y)
        };
        let path = plan_in_field_avoiding(&field, start, goal, &wall).unwrap();
        assert!(
            path.length > direct.length + 0.1,
            "{} vs {}",
            path.length,
            direct.length
        );
        let resolution = field.resolution();
        let corners: Vec<VoxelKey> = path
            .waypoints
            .iter()
            .map(|p| resolution.key_of(p).unwrap())
            .collect();
        for leg in corners.windows(2) {
            assert!(segment_voxels(&field, leg[0], leg[1], |i| !wall(i)));
        }
        let on_wall = VoxelKey::new(20, 20, 10);
        assert!(matches!(
            plan_in_field_avoiding(&field, start, on_wall, &wall),
            Err(PlanError::GoalAvoided)
        ));
        // The start may be avoided: the vehicle is there already.
        assert!(plan_in_field_avoiding(&field, on_wall, goal, &wall).is_ok());
    }
}
