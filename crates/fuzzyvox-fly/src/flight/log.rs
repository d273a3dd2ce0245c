//! What a flight did: how it ended, what each cycle cost, and its log.

use nalgebra::Point3;
use serde::Serialize;

/// How a flight ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Ending {
    /// Within [`REACHED_VOXELS`](crate::flight::REACHED_VOXELS) voxel edges of the goal.
    Reached,
    /// The vehicle's swept ball met the true scene; the flight stopped there.
    Collided,
    /// The time limit passed.
    TimeLimit,
    /// The map offered no path (not even towards the goal) for [`STALL_FRAMES`](crate::flight::STALL_FRAMES) frames in a
    /// row.
    NoPath,
    /// The vehicle came no nearer to the goal for [`FlyConfig::patience`](crate::FlyConfig::patience) seconds.
    Stuck,
}

/// Milliseconds each part of one cycle took.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct CycleTimes {
    /// The depth stage on the latest views.
    pub depth_ms: f64,
    /// Integrating the depth image into the map.
    pub integrate_ms: f64,
    /// Updating the cost field from the blocks the integration changed, checking the current
    /// path against it and, when the path is no longer clear (or every
    /// [`FlyConfig::replan_every`](crate::FlyConfig::replan_every) frames), planning again.
    pub update_replan_ms: f64,
    /// Updating the [`UnknownGuard`](crate::UnknownGuard) (not part of `update_replan_ms`).
    pub guard_ms: f64,
}

/// What one flight did.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FlightLog {
    /// How it ended.
    pub ending: Ending,
    /// Positions of the vehicle, the start first, one per frame it moved.
    pub trajectory: Vec<Point3<f64>>,
    /// Length flown, metres.
    pub length: f64,
    /// Flight time, seconds (frames × frame interval).
    pub seconds: f64,
    /// Camera frames taken.
    pub frames: usize,
    /// Depth images integrated.
    pub depth_images: usize,
    /// Pairs the depth stage refused (too short a baseline, no overlap, ...).
    pub depth_refused: usize,
    /// Times the cost field was built and a path planned.
    pub replans: usize,
    /// Times a blocked path was repaired round what blocks it instead of planned again.
    pub repairs: usize,
    /// Per-cycle times.
    pub cycles: Vec<CycleTimes>,
}
