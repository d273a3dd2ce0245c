//! What planning a query in a map gave ([`FlightOutcome`]), why it failed ([`FlightFailure`],
//! [`BlockingClass`]), and one map's figures over all queries ([`FlightSummary`]).

use fuzzyvox_core::measures::VoxelClass;
use fuzzyvox_plan::{Blocker, PlanError};
use nalgebra::Point3;
use serde::Serialize;

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
    /// For a path that meets the true world: where, and what the map said there.
    pub collision: Option<CollisionDetail>,
}

/// A planned path that meets the true world, explained: the query, the first point where the
/// vehicle's ball meets an obstacle, what the map said of that point's voxel, and how far the
/// point lies from the true surface (`plan_collision_details` in the JSON).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct CollisionDetail {
    /// The query's start.
    pub from: Point3<f64>,
    /// The query's goal.
    pub to: Point3<f64>,
    /// The first point of the path whose ball meets an obstacle.
    pub point: Point3<f64>,
    /// The map's class of that point's voxel (`occupied`, `free`, `ambiguous` or `unknown`).
    pub class: &'static str,
    /// The map's occupied membership there.
    pub occupied: f32,
    /// The map's free membership there.
    pub free: f32,
    /// The point's distance to the nearest true surface, metres.
    pub distance_to_surface: f64,
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
    /// The failures among `outcomes`, by reason and by what blocked them.
    pub fn count(outcomes: &[FlightOutcome]) -> Self {
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
#[derive(Clone, Debug, PartialEq, Serialize)]
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
    /// Every path that meets the true world, explained.
    pub plan_collision_details: Vec<CollisionDetail>,
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
        plan_collision_details: outcomes.iter().filter_map(|o| o.collision).collect(),
    }
}
