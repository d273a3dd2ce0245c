//! Planning from where the vehicle is: A* through the cost field, or towards the reachable
//! voxel nearest the goal when the goal cannot be reached yet; within a budget of expanded
//! voxels when the vehicle only looks for a better path; and the repair of a blocked path
//! round what blocks it.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use fuzzyvox_core::storage::VoxelKey;
use fuzzyvox_plan::{CostField, PlanError, plan_in_field_within, repair_in_field};
use nalgebra::Point3;

/// What a replan depends on besides the flight's goal: the cost field (through the planner's
/// [generation](fuzzyvox_plan::Planner::generation)), the voxels the guard forbids, where the
/// vehicle is, and the search's limit. Equal inputs give an equal plan.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct ReplanInputs {
    pub(super) generation: u64,
    pub(super) forbidden: Vec<usize>,
    pub(super) position: Point3<f64>,
    pub(super) limit: usize,
}

/// What a replan gave.
#[derive(Clone, Debug)]
pub(super) enum Replanned {
    /// A path from the vehicle.
    Path(Vec<Point3<f64>>),
    /// The search reached its limit: keep the current path.
    Kept,
    /// No path.
    Failed,
}

/// The last replan's inputs and what it gave.
#[derive(Clone, Debug, Default)]
pub(super) struct LastReplan(Option<(ReplanInputs, Replanned)>);

impl LastReplan {
    /// What a replan with `inputs` gives: the last outcome when the inputs are the same (a
    /// vehicle waiting in place for a picture with some baseline, in a field and guard that
    /// have not changed, would search again for the same plan), otherwise `plan()`'s.
    pub(super) fn outcome(
        &mut self,
        inputs: ReplanInputs,
        plan: impl FnOnce() -> Replanned,
    ) -> Replanned {
        match &self.0 {
            Some((seen, outcome)) if *seen == inputs => outcome.clone(),
            _ => {
                let outcome = plan();
                self.0 = Some((inputs, outcome.clone()));
                outcome
            }
        }
    }
}

/// [`plan_from`] as a [`Replanned`].
pub(super) fn replan(
    field: &CostField,
    position: Point3<f64>,
    goal: VoxelKey,
    avoid: &dyn Fn(usize) -> bool,
    limit: usize,
) -> Replanned {
    match plan_from(field, position, goal, avoid, limit) {
        Ok(Some(path)) => Replanned::Path(path),
        Ok(None) => Replanned::Kept,
        Err(_) => Replanned::Failed,
    }
}

/// Plans through `field` from `position` to the goal, from the voxel [`start_voxel`] gives.
/// Never enters a voxel `avoid` names (the start excepted). Each search expands at most
/// `limit` voxels; `Ok(None)` when one ran out.
fn plan_from(
    field: &CostField,
    position: Point3<f64>,
    goal: VoxelKey,
    avoid: &dyn Fn(usize) -> bool,
    limit: usize,
) -> std::result::Result<Option<Vec<Point3<f64>>>, PlanError> {
    let resolution = field.resolution();
    let start = start_voxel(field, position, avoid)?;
    let found = match plan_in_field_within(field, start, goal, avoid, limit) {
        // The goal cannot be entered or reached yet: fly to the reachable voxel nearest to
        // it (the known-safe frontier towards the goal), see more, and plan again there.
        Err(PlanError::GoalUnsafe(_) | PlanError::GoalAvoided | PlanError::Disconnected { .. }) => {
            let target = nearest_reachable(field, start, goal, avoid, NEAREST_SEARCH)
                .ok_or(PlanError::Disconnected { expanded: 0 })?;
            if resolution.center(target) == resolution.center(start) {
                return Err(PlanError::Disconnected { expanded: 0 });
            }
            plan_in_field_within(field, start, target, avoid, limit)?
        }
        other => other?,
    };
    let Some(mut path) = found else {
        return Ok(None);
    };
    // The path starts where the vehicle is, not at its voxel's centre.
    if let Some(first) = path.waypoints.first_mut() {
        *first = position;
    }
    Ok(Some(path.waypoints))
}

/// The voxel to plan from at `position`: the one the vehicle is in, or, when that one cannot
/// be entered (the map learnt that something is near), the nearest traversable voxel within
/// half a metre that `avoid` allows (the vehicle's own when there is none).
fn start_voxel(
    field: &CostField,
    position: Point3<f64>,
    avoid: &dyn Fn(usize) -> bool,
) -> std::result::Result<VoxelKey, PlanError> {
    let resolution = field.resolution();
    let region = *field.region();
    let here = resolution.key_of(&position)?;
    Ok(match region.index_of(here) {
        Some(index) if !field.is_traversable(index) => {
            let reach = (0.5 / resolution.size()).ceil() as i32;
            let mut best: Option<(i32, VoxelKey)> = None;
            for dz in -reach..=reach {
                for dy in -reach..=reach {
                    for dx in -reach..=reach {
                        let key = VoxelKey::new(here.x + dx, here.y + dy, here.z + dz);
                        let d2 = dx * dx + dy * dy + dz * dz;
                        if best.is_none_or(|(b, _)| d2 < b)
                            && region
                                .index_of(key)
                                .is_some_and(|i| field.is_traversable(i) && !avoid(i))
                        {
                            best = Some((d2, key));
                        }
                    }
                }
            }
            best.map_or(here, |(_, key)| key)
        }
        _ => here,
    })
}

/// Repairs `path` (blocked in `field`; its first point is where the vehicle is) round what
/// blocks it, from the voxel [`plan_from`] would start at, rejoining it `rejoin` metres (in
/// voxels crossed, so at least that far along the path) past what blocks it and expanding at
/// most `limit` voxels ([`repair_in_field`]); `None` when it cannot, or when the repair would
/// leave fewer than two waypoints (the loop then plans in full).
pub(super) fn repair(
    field: &CostField,
    position: Point3<f64>,
    path: &[Point3<f64>],
    avoid: &dyn Fn(usize) -> bool,
    rejoin: f64,
    limit: usize,
) -> Option<Vec<Point3<f64>>> {
    let start = start_voxel(field, position, avoid).ok()?;
    let rejoin_after = (rejoin / field.resolution().size()).ceil() as usize;
    let mut repaired = repair_in_field(field, start, path, avoid, rejoin_after, limit)?;
    if let Some(first) = repaired.first_mut() {
        *first = position;
    }
    Some(repaired).filter(|p| p.len() >= 2)
}

/// The most voxels [`nearest_reachable`] takes from its queue: the search for where to fly
/// when the goal cannot be reached yet costs a bounded time, as a periodic replan does, however
/// large the region the vehicle can reach.
const NEAREST_SEARCH: usize = 5_000;

/// The traversable voxel connected to `start` (through the field's 26-neighbourhood, never
/// entering a voxel `avoid` names) nearest to `goal`, ties to the lowest index, among the
/// first `limit` voxels a best-first search takes: nearest to the goal first, so the search
/// heads for the goal and spreads along what stops it there. Exact when the voxels connected
/// to `start` are at most `limit`. `None` when `start` is not traversable.
fn nearest_reachable(
    field: &CostField,
    start: VoxelKey,
    goal: VoxelKey,
    avoid: &dyn Fn(usize) -> bool,
    limit: usize,
) -> Option<VoxelKey> {
    let region = field.region();
    let first = region
        .index_of(start)
        .filter(|&i| field.is_traversable(i))?;
    let distance = |key: VoxelKey| {
        let d = [key.x - goal.x, key.y - goal.y, key.z - goal.z].map(i64::from);
        d[0] * d[0] + d[1] * d[1] + d[2] * d[2]
    };
    // Zeroed pages from the system: only those the search touches are written.
    let mut seen = vec![false; region.len()];
    seen[first] = true;
    let mut queue = BinaryHeap::from([Reverse((distance(start), first))]);
    let mut best = (distance(start), first);
    let mut taken = 0;
    while let Some(Reverse((d, index))) = queue.pop() {
        if taken == limit {
            break;
        }
        taken += 1;
        best = best.min((d, index));
        let key = region.key_at(index);
        for dz in -1..=1 {
            for dy in -1..=1 {
                for dx in -1..=1 {
                    let next = VoxelKey::new(key.x + dx, key.y + dy, key.z + dz);
                    if let Some(n) = region.index_of(next)
                        && !seen[n]
                        && field.is_traversable(n)
                        && !avoid(n)
                    {
                        seen[n] = true;
                        queue.push(Reverse((distance(next), n)));
                    }
                }
            }
        }
    }
    Some(region.key_at(best.1))
}

#[cfg(test)]
mod tests {
    use fuzzyvox_core::map::FunctionMap;
    use fuzzyvox_core::measures::Memberships;
    use fuzzyvox_core::storage::Resolution;
    use fuzzyvox_plan::{PlannerConfig, PlanningRegion};

    use super::*;

    /// A 6 × 2 × 1 m box of seen free space at 0.1 m, cut across by an occupied wall at x 4 m:
    /// a goal behind the wall cannot be reached.
    fn walled() -> CostField {
        let map = FunctionMap::new(Resolution::new(0.1).unwrap(), |key| {
            if key.x == 40 {
                Memberships {
                    occupied: 0.95,
                    free: 0.0,
                }
            } else {
                Memberships {
                    occupied: 0.0,
                    free: 0.95,
                }
            }
        });
        let region = PlanningRegion::new(VoxelKey::new(0, 0, 0), VoxelKey::new(59, 19, 9)).unwrap();
        let config = PlannerConfig {
            vehicle_radius: 0.1,
            ..PlannerConfig::default()
        };
        CostField::build(&map, region, config).unwrap()
    }

    /// Searching every reachable voxel gives the one nearest the goal in front of the wall; a
    /// search of a few hundred voxels heads for the goal and finds the same one, and one of a
    /// single voxel gives the start.
    #[test]
    fn the_nearest_reachable_voxel_is_found_heading_for_the_goal() {
        let field = walled();
        let (start, goal) = (VoxelKey::new(3, 10, 5), VoxelKey::new(50, 12, 5));
        let none = |_: usize| false;
        let exact = nearest_reachable(&field, start, goal, &none, usize::MAX).unwrap();
        assert!(field.is_traversable(field.region().index_of(exact).unwrap()));
        assert_eq!((exact.y, exact.z), (12, 5));
        assert!((36..40).contains(&exact.x), "{exact:?}");
        assert_eq!(
            nearest_reachable(&field, start, goal, &none, 600),
            Some(exact)
        );
        assert_eq!(
            nearest_reachable(&field, start, goal, &none, 1),
            Some(start)
        );
        // What `avoid` names is never entered.
        let fence = |index: usize| field.region().key_at(index).x >= 20;
        let fenced = nearest_reachable(&field, start, goal, &fence, usize::MAX).unwrap();
        assert_eq!(fenced.x, 19);
    }

    /// The last outcome comes back while the inputs are equal; any changed input plans again.
    #[test]
    fn equal_inputs_reuse_the_last_replan() {
        let inputs = ReplanInputs {
            generation: 3,
            forbidden: vec![7, 9],
            position: Point3::new(1.0, 2.0, 3.0),
            limit: 10,
        };
        let mut last = LastReplan::default();
        let mut plans = 0u32;
        let mut plan = |last: &mut LastReplan, inputs: &ReplanInputs| {
            last.outcome(inputs.clone(), || {
                plans += 1;
                Replanned::Path(vec![Point3::new(f64::from(plans), 0.0, 0.0)])
            })
        };
        let first = plan(&mut last, &inputs);
        let again = plan(&mut last, &inputs);
        assert!(matches!((&first, &again), (Replanned::Path(a), Replanned::Path(b)) if a == b));
        let changes = [
            ReplanInputs {
                generation: 4,
                ..inputs.clone()
            },
            ReplanInputs {
                forbidden: vec![7],
                ..inputs.clone()
            },
            ReplanInputs {
                position: Point3::new(1.0, 2.0, 3.5),
                ..inputs.clone()
            },
            ReplanInputs {
                limit: usize::MAX,
                ..inputs.clone()
            },
        ];
        for changed in &changes {
            plan(&mut last, changed);
        }
        assert_eq!(plans as usize, 1 + changes.len());
    }
}
