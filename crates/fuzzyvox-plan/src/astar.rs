use std::cmp::Reverse;
use std::collections::BinaryHeap;

use nalgebra::Point3;
use ordered_float::OrderedFloat;
use petgraph::visit::{EdgeRef, IntoEdges};
use serde::Serialize;

use super::blocker::{Blocker, ObservedExtent};
use super::config::PlannerConfig;
use super::cost_field::{CostField, PlanningRegion};
use super::graph::VoxelGraph;
use super::planner::Planner;
use crate::error::Error;
use crate::integrate::walk_ray;
use crate::map::VoxelMap;
use crate::storage::VoxelKey;

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

/// Why no path was found.
#[derive(Debug, thiserror::Error)]
pub enum PlanError {
    /// The start or goal lies outside the planning region.
    #[error("the {0} lies outside the planning region")]
    OutOfRegion(&'static str),
    /// The start voxel cannot be entered; the [`Blocker`] says why (outside the observed
    /// extent, unknown, occupied, ambiguous, low safety, or too close to a blocked voxel) and
    /// what would change it.
    #[error("the start is not safe: {0}")]
    StartUnsafe(Blocker),
    /// The goal voxel cannot be entered; the [`Blocker`] says why.
    #[error("the goal is not safe: {0}")]
    GoalUnsafe(Blocker),
    /// The goal is a voxel the caller asked the planner to avoid
    /// ([`plan_in_field_avoiding`]).
    #[error("the goal is one of the voxels the planner was asked to avoid")]
    GoalAvoided,
    /// Start and goal are not connected through traversable voxels.
    #[error(
        "the goal is not connected to the start through safe space ({expanded} voxels searched)"
    )]
    Disconnected {
        /// Nodes expanded before the search ran out.
        expanded: usize,
    },
    /// The map or the configuration rejected the request.
    #[error(transparent)]
    Map(#[from] Error),
}

/// Into the core's error, for callers that handle every fuzzyvox error as one type: a map or
/// configuration error becomes itself again, any other reason [`Error::Plan`] (which
/// `downcast_ref::<PlanError>()` reads back).
impl From<PlanError> for Error {
    fn from(error: PlanError) -> Self {
        match error {
            PlanError::Map(error) => error,
            other => Error::Plan(Box::new(other)),
        }
    }
}

impl PlanError {
    /// Why the start or goal was refused, for [`PlanError::StartUnsafe`] and
    /// [`PlanError::GoalUnsafe`].
    pub fn blocker(&self) -> Option<&Blocker> {
        match self {
            Self::StartUnsafe(why) | Self::GoalUnsafe(why) => Some(why),
            _ => None,
        }
    }
}

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

/// A* from `start` to `goal` over the field's 26-connected graph (through petgraph's
/// [`IntoEdges`]), with dense per-voxel arrays and the octile distance times the field's lowest
/// cost rate as a consistent heuristic, then line-of-sight shortcutting checked against the
/// same field and merging of collinear waypoints. Ties are broken by node index, so the result
/// is deterministic.
pub fn plan_in_field(
    field: &CostField,
    start: VoxelKey,
    goal: VoxelKey,
) -> Result<Path, PlanError> {
    search(field, start, goal, &|_| false)
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
    search(field, start, goal, avoid)
}

/// The A* of [`plan_in_field_avoiding`], generic over `avoid` so that [`plan_in_field`] pays
/// nothing for it.
fn search<A: Fn(usize) -> bool + ?Sized>(
    field: &CostField,
    start: VoxelKey,
    goal: VoxelKey,
    avoid: &A,
) -> Result<Path, PlanError> {
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
    // Metres of the shortest 26-connected route times the lowest rate: never more than the
    // true remaining cost, and consistent because every step costs at least its length times
    // that rate.
    let size = field.resolution().size() as f32 * field.min_rate();
    let heuristic = |key: VoxelKey| {
        let mut d = [
            (key.x - goal.x).unsigned_abs() as f32,
            (key.y - goal.y).unsigned_abs() as f32,
            (key.z - goal.z).unsigned_abs() as f32,
        ];
        d.sort_unstable_by(|a, b| b.total_cmp(a));
        let sqrt3 = 1.732_050_8_f32;
        size * ((d[0] - d[1]) + std::f32::consts::SQRT_2 * (d[1] - d[2]) + sqrt3 * d[2])
    };
    let graph = VoxelGraph::new(field);
    let n = region.len();
    let mut best = vec![f32::INFINITY; n];
    let mut parent = vec![u32::MAX; n];
    let mut closed = vec![false; n];
    let mut open = BinaryHeap::new();
    best[start_index] = 0.0;
    open.push(Reverse((
        OrderedFloat(heuristic(start)),
        start_index as u32,
    )));
    let mut expanded = 0;
    while let Some(Reverse((_, node))) = open.pop() {
        let node_index = node as usize;
        if closed[node_index] {
            continue;
        }
        closed[node_index] = true;
        expanded += 1;
        if node_index == goal_index {
            break;
        }
        let g = best[node_index];
        for edge in graph.edges(node) {
            let target = edge.target() as usize;
            if closed[target] || avoid(target) {
                continue;
            }
            let candidate = g + *edge.weight();
            if candidate < best[target] {
                best[target] = candidate;
                parent[target] = node;
                let f = candidate + heuristic(region.key_at(target));
                open.push(Reverse((OrderedFloat(f), target as u32)));
            }
        }
    }
    if !closed[goal_index] {
        return Err(PlanError::Disconnected { expanded });
    }
    let mut voxels = vec![goal];
    let mut node = goal_index;
    while node != start_index {
        node = parent[node] as usize;
        voxels.push(region.key_at(node));
    }
    voxels.reverse();
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
    Ok(Path {
        waypoints,
        length,
        cost: f64::from(best[goal_index]),
        min_safety,
        min_clearance,
        expanded,
    })
}

/// Calls `visit` with the dense index of every voxel the straight segment between two voxel
/// centres passes through (both ends included), stopping early when `visit` returns false;
/// returns false when stopped or when the segment leaves the region.
pub(super) fn segment_voxels(
    field: &CostField,
    from: VoxelKey,
    to: VoxelKey,
    mut visit: impl FnMut(usize) -> bool,
) -> bool {
    let resolution = field.resolution();
    let region = field.region();
    let mut ok = true;
    walk_ray(
        &resolution,
        &resolution.center(from),
        &resolution.center(to),
        from,
        to,
        |key| {
            if ok {
                ok = region.index_of(key).is_some_and(&mut visit);
            }
        },
    );
    ok && region.index_of(to).is_some_and(visit)
}

/// Greedy line-of-sight shortcutting: from each kept waypoint, jump to the farthest later
/// voxel of the path whose straight segment crosses only traversable voxels.
fn shortcut(
    field: &CostField,
    enter: &dyn Fn(usize) -> bool,
    voxels: &[VoxelKey],
) -> Vec<VoxelKey> {
    let mut kept = vec![voxels[0]];
    let mut anchor = 0;
    while anchor + 1 < voxels.len() {
        let mut next = anchor + 1;
        for candidate in (anchor + 2..voxels.len()).rev() {
            if segment_voxels(field, voxels[anchor], voxels[candidate], enter) {
                next = candidate;
                break;
            }
        }
        kept.push(voxels[next]);
        anchor = next;
    }
    kept
}

/// Drops every interior waypoint that lies on the segment between its neighbours, so that a
/// path has no redundant corners. Shortcutting leaves such points when the voxel walk of the
/// longer segment breaks a tie at a voxel edge differently from the two shorter ones.
///
/// A waypoint exactly on the segment is always dropped: the path is the same curve, so it keeps
/// the field's clearance guarantee. One within a thousandth of a voxel of it (possible only on
/// segments over a thousand voxels long) is dropped when the merged segment crosses
/// traversable voxels alone.
fn merge_collinear(
    field: &CostField,
    enter: &dyn Fn(usize) -> bool,
    corners: &[VoxelKey],
) -> Vec<VoxelKey> {
    let mut kept: Vec<VoxelKey> = Vec::with_capacity(corners.len());
    for (i, &key) in corners.iter().enumerate() {
        let redundant = match (kept.last(), corners.get(i + 1)) {
            (Some(&before), Some(&after)) => match offset_from_segment(before, key, after) {
                Some(0.0) => true,
                Some(offset) if offset <= 1e-3 => segment_voxels(field, before, after, enter),
                _ => false,
            },
            _ => false,
        };
        if !redundant {
            kept.push(key);
        }
    }
    kept
}

/// Distance in voxels from `middle` to the line through `a` and `b`, or `None` when `middle`
/// does not lie between the two ends (a reversal, whose removal would cut a corner) or the
/// ends coincide. Exact (0.0) for a point on the segment: the cross product of integer keys
/// is computed in integers.
fn offset_from_segment(a: VoxelKey, middle: VoxelKey, b: VoxelKey) -> Option<f64> {
    let vector = |from: VoxelKey, to: VoxelKey| {
        [
            i128::from(to.x) - i128::from(from.x),
            i128::from(to.y) - i128::from(from.y),
            i128::from(to.z) - i128::from(from.z),
        ]
    };
    let (u, v) = (vector(a, b), vector(a, middle));
    let dot = |p: [i128; 3], q: [i128; 3]| p[0] * q[0] + p[1] * q[1] + p[2] * q[2];
    let cross = [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ];
    let (length2, along) = (dot(u, u), dot(u, v));
    if length2 == 0 || along < 0 || along > length2 {
        return None;
    }
    // Squared in floating point: the cross product's components fit i128, their squares may
    // not, and a zero product stays exactly zero.
    let off = cross.map(|c| c as f64);
    Some(((off[0] * off[0] + off[1] * off[1] + off[2] * off[2]) / (length2 as f64)).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::map::FunctionMap;
    use crate::measures::Memberships;
    use crate::storage::Resolution;

    /// The field of a 4 × 4 × 2 m box of confident free space at 0.1 m, with a 1 m pillar in
    /// the middle when `pillar`.
    fn open_field(pillar: bool) -> CostField {
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

    fn traversable(field: &CostField) -> impl Fn(usize) -> bool + '_ {
        |index| field.is_traversable(index)
    }

    fn keys(points: &[[i32; 3]]) -> Vec<VoxelKey> {
        points
            .iter()
            .map(|&[x, y, z]| VoxelKey::new(x, y, z))
            .collect()
    }

    #[test]
    fn plan_errors_convert_into_the_core_error() {
        let disconnected: Error = PlanError::Disconnected { expanded: 7 }.into();
        let Error::Plan(inner) = &disconnected else {
            panic!("{disconnected:?}");
        };
        assert!(matches!(
            inner.downcast_ref::<PlanError>(),
            Some(PlanError::Disconnected { expanded: 7 })
        ));
        assert_eq!(
            disconnected.to_string(),
            PlanError::Disconnected { expanded: 7 }.to_string()
        );
        let map: Error = PlanError::Map(Error::Empty("cloud")).into();
        assert!(matches!(map, Error::Empty("cloud")), "{map:?}");
    }

    #[test]
    fn collinear_waypoints_are_merged() {
        let field = open_field(false);
        // Two points on the first leg, one on the second, then a turn into z.
        let corners = keys(&[
            [5, 5, 5],
            [7, 7, 5],
            [10, 10, 5],
            [10, 20, 5],
            [10, 30, 5],
            [10, 30, 10],
        ]);
        assert_eq!(
            merge_collinear(&field, &traversable(&field), &corners),
            keys(&[[5, 5, 5], [10, 10, 5], [10, 30, 5], [10, 30, 10]])
        );
        // A repeated point is redundant too.
        assert_eq!(
            merge_collinear(
                &field,
                &traversable(&field),
                &keys(&[[5, 5, 5], [5, 5, 5], [9, 5, 5]])
            ),
            keys(&[[5, 5, 5], [9, 5, 5]])
        );
    }

    #[test]
    fn corners_and_reversals_are_kept() {
        let field = open_field(false);
        // Off the line by one voxel: a real corner.
        let corner = keys(&[[5, 5, 5], [10, 6, 5], [15, 5, 5]]);
        assert_eq!(
            merge_collinear(&field, &traversable(&field), &corner),
            corner
        );
        // On the line but beyond its end: dropping it would cut the path short.
        let reversal = keys(&[[5, 5, 5], [15, 5, 5], [10, 5, 5]]);
        assert_eq!(
            merge_collinear(&field, &traversable(&field), &reversal),
            reversal
        );
        // Ends alone, and a single point, are left as they are.
        let two = keys(&[[5, 5, 5], [15, 5, 5]]);
        assert_eq!(merge_collinear(&field, &traversable(&field), &two), two);
        assert_eq!(
            merge_collinear(&field, &traversable(&field), &two[..1]),
            two[..1]
        );
    }

    #[test]
    fn offsets_from_a_segment_are_exact_on_it_and_none_beyond_its_ends() {
        let key = VoxelKey::new;
        let (a, b) = (key(0, 0, 0), key(10_000, 1, 0));
        assert_eq!(
            offset_from_segment(a, key(20_000, 2, 0), key(40_000, 4, 0)),
            Some(0.0)
        );
        // (5, 0, 0) is 0.0005 voxel off the line from a to b; (5000, 0, 0) is 0.5 off.
        let near = offset_from_segment(a, key(5, 0, 0), b).unwrap();
        assert!((near - 5e-4).abs() < 1e-9, "{near}");
        let far = offset_from_segment(a, key(5000, 0, 0), b).unwrap();
        assert!((far - 0.5).abs() < 1e-6, "{far}");
        assert_eq!(offset_from_segment(a, key(-1, 0, 0), b), None);
        assert_eq!(offset_from_segment(a, key(10_001, 1, 0), b), None);
        assert_eq!(offset_from_segment(a, a, a), None);
        // Keys at the ends of the key range do not overflow.
        let (lo, hi) = (key(i32::MIN, i32::MIN, 0), key(i32::MAX, i32::MAX, 0));
        assert_eq!(
            offset_from_segment(lo, key(0, 0, 0), hi).map(|d| d < 1.0),
            Some(true)
        );
    }

    #[test]
    fn planned_paths_have_no_collinear_interior_waypoints() {
        let field = open_field(true);
        let region = *field.region();
        let resolution = field.resolution();
        for (start, goal) in [
            ([5, 20, 10], [35, 20, 10]),
            ([5, 5, 5], [35, 35, 15]),
            ([20, 5, 10], [20, 35, 10]),
            ([8, 19, 4], [33, 21, 16]),
        ] {
            let (start, goal) = (
                VoxelKey::new(start[0], start[1], start[2]),
                VoxelKey::new(goal[0], goal[1], goal[2]),
            );
            let path = plan_in_field(&field, start, goal).unwrap();
            assert_eq!(resolution.key_of(&path.waypoints[0]).unwrap(), start);
            for w in path.waypoints.windows(3) {
                let k: Vec<VoxelKey> = w.iter().map(|p| resolution.key_of(p).unwrap()).collect();
                assert_ne!(
                    offset_from_segment(k[0], k[1], k[2]),
                    Some(0.0),
                    "redundant waypoint in {:?}",
                    path.waypoints
                );
                assert!(k.iter().all(|key| region.index_of(*key).is_some()));
            }
        }
    }
}
