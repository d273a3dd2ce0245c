//! Repairing a path that stopped being clear ([`repair_in_field`]): a detour from the start to
//! the first voxel past the path's last blocked voxel, searched within a budget, and the rest
//! of the path as it was.
//!
//! A closed loop's path is usually blocked over a short stretch (a surface seen closer than
//! before, unknown space the guard now forbids), so the search for a way round that stretch is
//! short, while a search for a whole new path from the vehicle to the goal can cross much of
//! the region. The rest of the old path was planned through the same field and is still clear,
//! so the detour reuses it instead of searching it again.

use fuzzyvox_core::storage::VoxelKey;
use nalgebra::Point3;

use crate::cost_field::CostField;
use crate::path::plan_in_field_within;
use crate::smooth::interior_voxels;

/// Repairs `waypoints` (a path planned earlier through this field; the first point is where
/// the vehicle is) for the field as it is now: A* from `start` (the voxel to plan from, usually
/// the first waypoint's) to the voxel the path crosses `rejoin_after` voxels (at least one,
/// at most to the path's end) after the last one it crosses that is not traversable or that
/// `avoid` names (the first waypoint's voxel excepted), expanding at most `max_expanded`
/// voxels, then the old path from that voxel on. Rejoining some way past the blocked stretch
/// leaves the detour room to go round it smoothly instead of hugging it back onto the old
/// line. A leg crosses the voxels it passes through over a stretch of positive length, as in
/// [`Planner::is_path_clear_avoiding`](crate::Planner::is_path_clear_avoiding).
///
/// Returns the repaired waypoints (the detour's first point is `start`'s centre, as
/// [`plan_in_field_within`] gives it), each straight leg crossing only traversable voxels that
/// `avoid` allows, the start excepted. `None` when there is nothing to repair (the path is
/// clear, or shorter than two points, or leaves the region) or the path cannot be repaired
/// within the budget: its last point is blocked, or the detour was not found. A caller then
/// plans in full.
pub fn repair_in_field(
    field: &CostField,
    start: VoxelKey,
    waypoints: &[Point3<f64>],
    avoid: &dyn Fn(usize) -> bool,
    rejoin_after: usize,
    max_expanded: usize,
) -> Option<Vec<Point3<f64>>> {
    let resolution = field.resolution();
    let region = field.region();
    let keys: Vec<VoxelKey> = waypoints
        .iter()
        .map(|p| resolution.key_of(p).ok())
        .collect::<Option<_>>()?;
    if keys.len() < 2 {
        return None;
    }
    let first = region.index_of(keys[0])?;
    let enter = |i: usize| field.is_traversable(i) && (i == first || !avoid(i));
    // The voxels the legs cross, in order, each with its leg.
    let mut crossed: Vec<(usize, usize)> = Vec::new();
    for (leg, pair) in keys.windows(2).enumerate() {
        let inside = interior_voxels(field, pair[0], pair[1], |index| {
            crossed.push((leg, index));
            true
        });
        if !inside {
            return None;
        }
    }
    let last_blocked = crossed.iter().rposition(|&(_, index)| !enter(index))?;
    let at = (last_blocked + rejoin_after.max(1)).min(crossed.len() - 1);
    if at <= last_blocked {
        return None;
    }
    let (leg, rejoin) = crossed[at];
    let rejoin_key = region.key_at(rejoin);
    let detour = plan_in_field_within(field, start, rejoin_key, avoid, max_expanded)
        .ok()
        .flatten()?;
    // The rest of the rejoining leg starts at the rejoin voxel's centre: check its voxels, then
    // the old path's later legs, which were all clear.
    let leg_end = keys[leg + 1];
    if leg_end != rejoin_key && !interior_voxels(field, rejoin_key, leg_end, enter) {
        return None;
    }
    let mut repaired = detour.waypoints;
    let rest = if leg_end == rejoin_key {
        leg + 2
    } else {
        leg + 1
    };
    repaired.extend_from_slice(&waypoints[rest.min(waypoints.len())..]);
    Some(repaired)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::path::tests::open_field;
    use crate::smooth::{LegVoxels, legs_clear};

    fn centre(field: &CostField, key: VoxelKey) -> Point3<f64> {
        field.resolution().center(key)
    }

    /// Whether every leg of `waypoints` crosses only voxels the field lets in and `avoid`
    /// allows, the first waypoint's voxel excepted (the planner's test of a path it gave).
    fn clear(field: &CostField, waypoints: &[Point3<f64>], avoid: &dyn Fn(usize) -> bool) -> bool {
        legs_clear(field, waypoints, avoid, LegVoxels::Interior)
    }

    /// A straight path through where a pillar now stands is repaired round the pillar, joins
    /// the old path after it and keeps the old path's later corners; a budget too small for any
    /// detour repairs nothing.
    #[test]
    fn a_blocked_stretch_is_repaired_round_and_the_rest_is_kept() {
        let field = open_field(true);
        let start = VoxelKey::new(5, 20, 10);
        let old = vec![
            centre(&field, start),
            centre(&field, VoxelKey::new(35, 20, 10)),
            centre(&field, VoxelKey::new(35, 35, 10)),
        ];
        let none = |_: usize| false;
        assert!(!clear(&field, &old, &none));
        let repaired = repair_in_field(&field, start, &old, &none, 1, 30_000).expect("a detour");
        assert!(clear(&field, &repaired, &none));
        assert_eq!(repaired.first(), old.first());
        assert_eq!(repaired.last(), old.last());
        assert!(
            repaired.contains(&old[1]),
            "the old corner after the pillar is kept: {repaired:?}"
        );
        assert!(repair_in_field(&field, start, &old, &none, 1, 3).is_none());
        // Rejoining further on leaves out more of the old leg, and never passes the old end.
        let later = repair_in_field(&field, start, &old, &none, 6, 30_000).expect("a detour");
        assert!(clear(&field, &later, &none));
        assert_eq!(later.last(), old.last());
        let beyond =
            repair_in_field(&field, start, &old, &none, 1_000, 30_000).expect("to the end");
        assert!(clear(&field, &beyond, &none));
        assert_eq!(beyond.last(), old.last());
        assert!(
            !beyond.contains(&old[1]),
            "rejoined at the old end, past the corner"
        );
    }

    /// Voxels the caller avoids block a path as the field's blocked voxels do; a clear path and
    /// a path whose end is blocked are not repaired.
    #[test]
    fn avoided_voxels_block_and_clear_or_dead_end_paths_are_left_alone() {
        let field = open_field(false);
        let start = VoxelKey::new(5, 20, 10);
        let old = vec![
            centre(&field, start),
            centre(&field, VoxelKey::new(35, 20, 10)),
        ];
        assert!(repair_in_field(&field, start, &old, &|_| false, 1, 5_000).is_none());
        let wall = |index: usize| {
            let key = field.region().key_at(index);
            key.x == 15 && (16..=24).contains(&key.y) && (6..=14).contains(&key.z)
        };
        let repaired =
            repair_in_field(&field, start, &old, &wall, 1, 5_000).expect("round the wall");
        assert!(clear(&field, &repaired, &wall));
        assert!(repaired.len() > 2);
        assert_eq!(repaired.last(), old.last());
        let end = |index: usize| field.region().key_at(index) == VoxelKey::new(35, 20, 10);
        assert!(repair_in_field(&field, start, &old, &end, 1, 5_000).is_none());
    }
}
