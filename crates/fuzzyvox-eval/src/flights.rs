//! Planned flights checked against the true scene: random start/goal pairs in truly free space,
//! a path planned in each map, and every path's segments swept by a ball of the vehicle's radius
//! against the scene's real geometry.
//!
//! The queries come from the truth alone (the gold-standard map and the scene), never from the
//! maps being compared, so every map answers the same queries whichever maps sit beside it, and
//! a map that knows less than the truth fails the queries it cannot answer, with the reason
//! counted ([`FailureCounts`]).

use nalgebra::Point3;
use rayon::prelude::*;
use rustc_hash::FxHashMap;
use serde::Serialize;

use crate::error::{Error, Result};
use crate::map::VoxelMap;
use crate::measures::VoxelClass;
use crate::plan::{Blocker, PlanError, PlannerConfig, plan_path};
use crate::sim::Scene;
use crate::sim::unit_hash;
use crate::storage::VoxelKey;

/// How flights are drawn and planned.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FlightConfig {
    /// Number of start/goal pairs.
    pub queries: usize,
    /// Seed of the draw.
    pub seed: u64,
    /// Planner settings (the vehicle radius is also the radius of the collision check).
    pub planner: PlannerConfig,
    /// Smallest and largest straight-line distance between start and goal, metres.
    pub distance: (f64, f64),
    /// Lowest and highest flight altitude of starts and goals, metres.
    pub altitude: (f64, f64),
    /// Extra distance, metres, beyond the vehicle radius that starts and goals keep from every
    /// true surface. Default: one voxel diagonal of the 0.2 m maps (0.35 m).
    pub surface_margin: f64,
}

impl Default for FlightConfig {
    fn default() -> Self {
        Self {
            queries: 100,
            seed: 1,
            planner: PlannerConfig::default(),
            distance: (6.0, 25.0),
            altitude: (1.0, 20.0),
            surface_margin: 0.2 * 3f64.sqrt(),
        }
    }
}

/// One start/goal pair.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct FlightQuery {
    /// Start (a voxel centre).
    pub from: Point3<f64>,
    /// Goal (a voxel centre).
    pub to: Point3<f64>,
}

/// What planning one query in one map gave.
#[derive(Clone, Debug, PartialEq)]
pub struct FlightOutcome {
    /// The path's waypoints, when the planner found one.
    pub waypoints: Option<Vec<Point3<f64>>>,
    /// Its length in metres.
    pub length: Option<f64>,
    /// Whether the path's swept ball meets the true geometry.
    pub collides: bool,
    /// Why the planner found no path; `None` when it found one.
    pub failure: Option<FlightFailure>,
    /// For an unsafe start or goal: what blocks it.
    pub blocked_by: Option<BlockingClass>,
}

/// What makes an unsafe start or goal unsafe: the class of its own voxel when that may not be
/// entered, otherwise (too little clearance) the class of the blocked voxel nearest to it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BlockingClass {
    /// The point lies outside the box of everything the map observed.
    OutsideExtent,
    /// Unknown space (forbidden).
    Unknown,
    /// Occupied space.
    Occupied,
    /// Ambiguous space (conflicting evidence).
    Ambiguous,
    /// Free space whose safety is below the planner's threshold.
    LowSafety,
}

impl BlockingClass {
    /// The class behind a planner's [`Blocker`]; `None` when the nearest blocked space is the
    /// edge of the planning region.
    pub fn of(blocker: &Blocker) -> Option<Self> {
        let of_class = |class: VoxelClass| match class {
            VoxelClass::Unknown => Self::Unknown,
            VoxelClass::Occupied => Self::Occupied,
            VoxelClass::Ambiguous => Self::Ambiguous,
            VoxelClass::Free => Self::LowSafety,
        };
        match blocker {
            Blocker::OutsideObservedExtent { .. } => Some(Self::OutsideExtent),
            Blocker::Unknown => Some(Self::Unknown),
            Blocker::Occupied { .. } => Some(Self::Occupied),
            Blocker::Ambiguous { .. } => Some(Self::Ambiguous),
            Blocker::LowSafety { .. } => Some(Self::LowSafety),
            Blocker::TooClose { nearest, .. } => nearest.map(|n| of_class(n.class)),
            _ => None,
        }
    }
}

/// Why a map gave no path for a query.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FlightFailure {
    /// The start voxel is not safe in the map (blocked, unknown, or too close to either).
    StartUnsafe,
    /// The goal voxel is not safe in the map.
    GoalUnsafe,
    /// Start and goal are safe but no safe path joins them.
    Disconnected,
    /// The start or goal lies outside the region the planner could build.
    OutOfRegion,
    /// The planner refused the request for another reason (a map or configuration error).
    Error,
}

impl FlightFailure {
    /// The failure behind a planner error.
    pub fn of(error: &PlanError) -> Self {
        match error {
            PlanError::StartUnsafe { .. } => Self::StartUnsafe,
            PlanError::GoalUnsafe { .. } | PlanError::GoalAvoided => Self::GoalUnsafe,
            PlanError::Disconnected { .. } => Self::Disconnected,
            PlanError::OutOfRegion { .. } => Self::OutOfRegion,
            _ => Self::Error,
        }
    }
}

/// How many queries failed, by reason (`plan_failures` in `metrics.json`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct FailureCounts {
    /// The start was not safe in the map.
    pub start_unsafe: usize,
    /// The goal was not safe in the map (and the start was).
    pub goal_unsafe: usize,
    /// Both were safe but not connected through safe space.
    pub disconnected: usize,
    /// The start or goal lay outside the planning region.
    pub out_of_region: usize,
    /// The planner refused the request (a map or configuration error; 0 in a sound run).
    pub error: usize,
    /// The unsafe starts and goals by what blocks them.
    pub blocked_by: BlockedByCounts,
}

/// Unsafe starts and goals by what blocks them ([`BlockingClass`]; `blocked_by` in
/// `metrics.json`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct BlockedByCounts {
    /// Outside the map's observed extent.
    pub outside_extent: usize,
    /// Unknown space in or near the point.
    pub unknown: usize,
    /// Occupied space in or near it.
    pub occupied: usize,
    /// Ambiguous space in or near it.
    pub ambiguous: usize,
    /// Free space of low safety in or near it.
    pub low_safety: usize,
}

impl FailureCounts {
    fn count(outcomes: &[FlightOutcome]) -> Self {
        let mut counts = Self::default();
        for failure in outcomes.iter().filter_map(|o| o.failure) {
            *match failure {
                FlightFailure::StartUnsafe => &mut counts.start_unsafe,
                FlightFailure::GoalUnsafe => &mut counts.goal_unsafe,
                FlightFailure::Disconnected => &mut counts.disconnected,
                FlightFailure::OutOfRegion => &mut counts.out_of_region,
                FlightFailure::Error => &mut counts.error,
            } += 1;
        }
        for class in outcomes.iter().filter_map(|o| o.blocked_by) {
            let b = &mut counts.blocked_by;
            *match class {
                BlockingClass::OutsideExtent => &mut b.outside_extent,
                BlockingClass::Unknown => &mut b.unknown,
                BlockingClass::Occupied => &mut b.occupied,
                BlockingClass::Ambiguous => &mut b.ambiguous,
                BlockingClass::LowSafety => &mut b.low_safety,
            } += 1;
        }
        counts
    }
}

/// Flight figures of one map, as reported in `metrics.json`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct FlightSummary {
    /// Start/goal pairs tried.
    pub plan_queries: usize,
    /// Fraction of them for which the map gave a path.
    pub plan_success: f64,
    /// Paths that meet the true geometry.
    pub plan_collisions: usize,
    /// Mean of this map's path length over the ground-truth map's, over the queries both
    /// solved; `None` when there are none.
    pub path_length_ratio: Option<f64>,
    /// The failed queries by reason.
    pub plan_failures: FailureCounts,
}

/// Draws start/goal pairs from the truth alone, among the voxels that are truly free and seen:
/// voxels within the altitude band from which the gold-standard map (true depth inserted with
/// the standard method, so only space the cameras saw) can take off, that is, every voxel within
/// the planner's required clearance (vehicle radius plus a voxel diagonal, see
/// [`CostField`](crate::plan::CostField)) is free and safe in it; and at least the vehicle
/// radius plus [`FlightConfig::surface_margin`] from every true surface. The maps being
/// compared play no part, so every map answers the same queries. Deterministic for a seed;
/// fewer pairs come back when too few candidates exist.
pub fn flight_queries(
    scene: &Scene,
    gold: &dyn VoxelMap,
    config: &FlightConfig,
) -> Result<Vec<FlightQuery>> {
    let planner = config.planner.validate()?;
    let (near, far) = config.distance;
    if !(near.is_finite() && far.is_finite() && near >= 0.0 && far > near) {
        return Err(Error::InvalidParameter {
            name: "flight distance range",
            value: near,
            expected: "0 <= near < far, finite",
        });
    }
    if !(config.surface_margin.is_finite() && config.surface_margin >= 0.0) {
        return Err(Error::InvalidParameter {
            name: "surface margin",
            value: config.surface_margin,
            expected: "a finite distance >= 0 m",
        });
    }
    let resolution = gold.resolution();
    let surface_clearance = planner.vehicle_radius + config.surface_margin;
    let measures = gold.measure_config();
    let mut candidates: Vec<VoxelKey> = gold
        .cells()
        .filter(|&(key, m)| {
            let z = resolution.center(key).z;
            z >= config.altitude.0
                && z <= config.altitude.1
                && measures.classify(m) == VoxelClass::Free
        })
        .map(|(key, _)| key)
        .collect();
    candidates.sort_unstable();
    let mut queries = Vec::new();
    if candidates.len() < 2 {
        return Ok(queries);
    }
    // Every voxel whose centre lies closer than the planner's required clearance.
    let required = planner.vehicle_radius + 3f64.sqrt() * resolution.size();
    let reach = (required / resolution.size()).ceil() as i32;
    let mut ball = Vec::new();
    for dz in -reach..=reach {
        for dy in -reach..=reach {
            for dx in -reach..=reach {
                let d2 = f64::from(dx * dx + dy * dy + dz * dz) * resolution.size().powi(2);
                if d2 < required * required {
                    ball.push((dx, dy, dz));
                }
            }
        }
    }
    let safe_in_gold = |key: VoxelKey| {
        let m = gold.measures_at(key);
        m.class == VoxelClass::Free && m.safety >= planner.safety_threshold
    };
    let mut usable: FxHashMap<VoxelKey, bool> = FxHashMap::default();
    let mut is_usable = |key: VoxelKey| {
        *usable.entry(key).or_insert_with(|| {
            ball.iter().all(|&(dx, dy, dz)| {
                safe_in_gold(VoxelKey::new(key.x + dx, key.y + dy, key.z + dz))
            }) && scene.distance_to_surface(&resolution.center(key)) >= surface_clearance
        })
    };
    let pick = |n: i64, salt: i64| {
        let u = unit_hash(n, salt, 97, config.seed);
        ((u as f64 * candidates.len() as f64) as usize).min(candidates.len() - 1)
    };
    let mut draw = 0i64;
    let attempts = 200 * config.queries as i64 + 1000;
    while queries.len() < config.queries && draw < attempts {
        draw += 1;
        let (a, b) = (candidates[pick(draw, 1)], candidates[pick(draw, 2)]);
        let (from, to) = (resolution.center(a), resolution.center(b));
        let d = (to - from).norm();
        if d >= near && d <= far && is_usable(a) && is_usable(b) {
            queries.push(FlightQuery { from, to });
        }
    }
    Ok(queries)
}

/// Plans every query in `map` and checks each path against the scene.
pub fn fly(
    map: &dyn VoxelMap,
    scene: &Scene,
    queries: &[FlightQuery],
    planner: &PlannerConfig,
) -> Vec<FlightOutcome> {
    queries
        .par_iter()
        .map(|q| match plan_path(map, &q.from, &q.to, planner) {
            Ok(path) => {
                let collides = path
                    .waypoints
                    .windows(2)
                    .any(|w| scene.intersects_swept_ball(&w[0], &w[1], planner.vehicle_radius))
                    || path.waypoints.len() == 1
                        && scene.intersects_swept_ball(
                            &path.waypoints[0],
                            &path.waypoints[0],
                            planner.vehicle_radius,
                        );
                FlightOutcome {
                    length: Some(path.length),
                    waypoints: Some(path.waypoints),
                    collides,
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
            },
        })
        .collect()
}

/// The figures of one map's outcomes, with lengths compared to the reference (ground-truth
/// map) outcomes of the same queries.
pub fn summarize(outcomes: &[FlightOutcome], reference: &[FlightOutcome]) -> FlightSummary {
    let solved = outcomes.iter().filter(|o| o.length.is_some()).count();
    let ratios: Vec<f64> = outcomes
        .iter()
        .zip(reference)
        .filter_map(|(o, r)| Some(o.length? / r.length.filter(|l| *l > 0.0)?))
        .collect();
    FlightSummary {
        plan_queries: outcomes.len(),
        plan_success: if outcomes.is_empty() {
            0.0
        } else {
            solved as f64 / outcomes.len() as f64
        },
        plan_collisions: outcomes.iter().filter(|o| o.collides).count(),
        path_length_ratio: (!ratios.is_empty())
            .then(|| ratios.iter().sum::<f64>() / ratios.len() as f64),
        plan_failures: FailureCounts::count(outcomes),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::map::VoxelMapMut;
    use crate::map::{FuzzyConfig, FuzzyMap};
    use crate::plan::NearestBlocked;
    use crate::sim::SurfaceKind;
    use fuzzyvox_core::PointCloud;
    use nalgebra::Vector3;

    /// A wall at x = 5 across the corridor, mapped from a sensor at the origin, so that the
    /// map knows the free space in front of the wall.
    fn wall_world() -> (Scene, FuzzyMap) {
        let mut scene = Scene::new();
        scene.add_box(
            Point3::new(5.3, 0.0, 3.0),
            Vector3::new(0.3, 6.0, 3.0),
            0.0,
            SurfaceKind::Wall,
        );
        let mut points = Vec::new();
        for i in -40..=40 {
            for j in 0..=40 {
                points.push(Point3::new(
                    5.0,
                    f64::from(i) * 0.1,
                    f64::from(j) * 0.1 + 1.0,
                ));
            }
        }
        let cloud = PointCloud::new(Point3::new(0.0, 0.0, 3.0), points).unwrap();
        let mut map = FuzzyMap::new(FuzzyConfig::new(0.2).unwrap()).unwrap();
        for _ in 0..3 {
            map.integrate_cloud(&cloud, &Default::default()).unwrap();
        }
        (scene, map)
    }

    #[test]
    fn queries_lie_in_true_free_space_and_repeat_for_a_seed() {
        let (scene, map) = wall_world();
        let config = FlightConfig {
            queries: 10,
            distance: (1.0, 3.0),
            altitude: (1.5, 4.0),
            ..FlightConfig::default()
        };
        let a = flight_queries(&scene, &map, &config).unwrap();
        assert_eq!(a.len(), 10);
        assert_eq!(a, flight_queries(&scene, &map, &config).unwrap());
        for q in &a {
            let d = (q.to - q.from).norm();
            assert!((1.0..=3.0).contains(&d));
            for p in [q.from, q.to] {
                assert!(scene.distance_to_surface(&p) >= 0.3);
                assert!(p.z >= 1.5 && p.z <= 4.0);
            }
        }
        let other = FlightConfig { seed: 2, ..config };
        assert_ne!(a, flight_queries(&scene, &map, &other).unwrap());
        // A truth that saw nothing leaves no candidates.
        let empty = FuzzyMap::new(FuzzyConfig::new(0.2).unwrap()).unwrap();
        assert!(flight_queries(&scene, &empty, &config).unwrap().is_empty());
        // A map that knows nothing answers the same queries, and fails each at its start.
        let outcomes = fly(&empty, &scene, &a, &config.planner);
        let summary = summarize(&outcomes, &fly(&map, &scene, &a, &config.planner));
        assert_eq!(summary.plan_success, 0.0);
        assert_eq!(summary.plan_failures.start_unsafe, a.len());
        assert_eq!(summary.plan_failures.goal_unsafe, 0);
    }

    #[test]
    fn a_point_short_of_clearance_is_blocked_by_the_class_of_its_nearest_blocked_voxel() {
        let too_close = |nearest: Option<NearestBlocked>| Blocker::TooClose {
            clearance: 0.2,
            required: 0.47,
            vehicle_radius: 0.3,
            largest_radius: 0.03,
            nearest,
        };
        let near = |class| NearestBlocked {
            center: Point3::origin(),
            class,
            safety: 0.1,
            distance: 0.2,
        };
        for (class, expected) in [
            (VoxelClass::Unknown, BlockingClass::Unknown),
            (VoxelClass::Occupied, BlockingClass::Occupied),
            (VoxelClass::Ambiguous, BlockingClass::Ambiguous),
            (VoxelClass::Free, BlockingClass::LowSafety),
        ] {
            assert_eq!(
                BlockingClass::of(&too_close(Some(near(class)))),
                Some(expected)
            );
        }
        // The planning region's edge is no class.
        assert_eq!(BlockingClass::of(&too_close(None)), None);
        assert_eq!(
            BlockingClass::of(&Blocker::Unknown),
            Some(BlockingClass::Unknown)
        );
    }

    #[test]
    fn paths_are_checked_against_the_geometry() {
        let (scene, map) = wall_world();
        let planner = PlannerConfig::default();
        let safe = FlightQuery {
            from: Point3::new(2.5, -0.8, 3.0),
            to: Point3::new(4.0, 0.8, 3.0),
        };
        let outcomes = fly(&map, &scene, &[safe], &planner);
        assert!(outcomes[0].length.is_some());
        assert!(!outcomes[0].collides);
        // The same path judged against a scene with a pillar in its way collides.
        let mut blocked = scene.clone();
        blocked.add_box(
            Point3::new(3.25, 0.0, 3.0),
            Vector3::new(0.3, 0.3, 3.0),
            0.0,
            SurfaceKind::Building,
        );
        let judged = fly(&map, &blocked, &[safe], &planner);
        assert!(judged[0].collides);
        let summary = summarize(&judged, &outcomes);
        assert_eq!(summary.plan_queries, 1);
        assert_eq!(summary.plan_collisions, 1);
        assert!((summary.plan_success - 1.0).abs() < 1e-12);
        assert!((summary.path_length_ratio.unwrap() - 1.0).abs() < 1e-12);
        // A goal inside the wall has no path.
        let into = FlightQuery {
            from: safe.from,
            to: Point3::new(5.3, 0.0, 3.0),
        };
        let failed = fly(&map, &scene, &[into], &planner);
        assert!(failed[0].length.is_none() && !failed[0].collides);
        assert_eq!(failed[0].failure, Some(FlightFailure::GoalUnsafe));
        assert_eq!(summarize(&failed, &failed).plan_failures.goal_unsafe, 1);
        assert_eq!(summarize(&failed, &failed).path_length_ratio, None);
        // A goal on the wall's face is blocked by the occupied voxels the sensor saw there.
        let onto = FlightQuery {
            from: safe.from,
            to: Point3::new(5.0, 0.0, 3.0),
        };
        let failed = fly(&map, &scene, &[onto], &planner);
        assert_eq!(failed[0].failure, Some(FlightFailure::GoalUnsafe));
        assert_eq!(failed[0].blocked_by, Some(BlockingClass::Occupied));
        let counts = summarize(&failed, &failed).plan_failures.blocked_by;
        assert_eq!(
            counts,
            BlockedByCounts {
                occupied: 1,
                ..BlockedByCounts::default()
            }
        );
    }
}
