//! One model's flights and their summary.

use fuzzyvox_core::map::{AnyMap, MapKind};
use fuzzyvox_fly::{CycleTimes, Ending, FlightLog};
use serde::Serialize;

use crate::flights::FlightQuery;

/// One model's flights.
#[derive(Clone, Debug, Serialize)]
pub struct ModelFlights {
    /// The model.
    pub model: MapKind,
    /// One log per goal, in goal order.
    pub flights: Vec<FlightLog>,
    /// Each flight's final map, in goal order (kept only when asked for).
    #[serde(skip)]
    pub maps: Vec<AnyMap>,
    /// Full rebuilds of the cost field, milliseconds: one every
    /// [`REBUILD_EVERY`](super::REBUILD_EVERY)th cycle of every flight.
    #[serde(skip)]
    pub rebuild_ms: Vec<f64>,
}

/// A summary of one model's flights.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ModelSummary {
    /// Goals flown.
    pub goals: usize,
    /// Fraction of the goals reached.
    pub reached: f64,
    /// Flights stopped by a collision with the true scene.
    pub collisions: usize,
    /// Flights that ran out of time.
    pub time_limit: usize,
    /// Flights that gave up without a path.
    pub no_path: usize,
    /// Flights that came no nearer to their goal for
    /// [`FlyConfig::patience`](fuzzyvox_fly::FlyConfig::patience) seconds.
    pub stuck: usize,
    /// Mean, over reached goals, of the length flown over the length of the true scene's path.
    pub length_ratio: Option<f64>,
    /// Mean time to goal over reached goals, seconds.
    pub time_to_goal_s: Option<f64>,
    /// Camera frames over all flights.
    pub frames: usize,
    /// Depth images integrated.
    pub depth_images: usize,
    /// Pairs the depth stage refused.
    pub depth_refused: usize,
    /// The depth stage per cycle, milliseconds: median and 95th percentile.
    pub depth_ms: f64,
    /// See `depth_ms`.
    pub depth_ms_p95: f64,
    /// Integration into the map per cycle, milliseconds.
    pub integrate_ms: f64,
    /// See `integrate_ms`.
    pub integrate_ms_p95: f64,
    /// Keeping or replanning the path per cycle (the path check, and when needed the cost
    /// field and A*), milliseconds.
    pub update_replan_ms: f64,
    /// See `update_replan_ms`.
    pub update_replan_ms_p95: f64,
    /// Updating the unseen-surface guard per cycle, milliseconds.
    pub guard_ms: f64,
    /// See `guard_ms`.
    pub guard_ms_p95: f64,
    /// A full rebuild of the cost field over the planning region, timed on every
    /// [`REBUILD_EVERY`](super::REBUILD_EVERY)th cycle, milliseconds.
    pub full_rebuild_ms: f64,
    /// See `full_rebuild_ms`.
    pub full_rebuild_ms_p95: f64,
}

impl ModelFlights {
    /// The summary over every flight; `goals` are the flights' goals, in the same order.
    pub fn summary(&self, goals: &[FlightQuery]) -> ModelSummary {
        let reached: Vec<(&FlightLog, &FlightQuery)> = self
            .flights
            .iter()
            .zip(goals)
            .filter(|(f, _)| f.ending == Ending::Reached)
            .collect();
        let count = |ending| self.flights.iter().filter(|f| f.ending == ending).count();
        let mean = |values: Vec<f64>| {
            (!values.is_empty()).then(|| values.iter().sum::<f64>() / values.len() as f64)
        };
        let cycles: Vec<&CycleTimes> = self.flights.iter().flat_map(|f| &f.cycles).collect();
        let times = |part: fn(&CycleTimes) -> Option<f64>| {
            percentiles(cycles.iter().filter_map(|c| part(c)).collect())
        };
        let depth = times(|c| (c.depth_ms > 0.0).then_some(c.depth_ms));
        let integrate = times(|c| (c.integrate_ms > 0.0).then_some(c.integrate_ms));
        let replan = times(|c| Some(c.update_replan_ms));
        let guard = times(|c| Some(c.guard_ms));
        let rebuild = percentiles(self.rebuild_ms.clone());
        ModelSummary {
            goals: self.flights.len(),
            reached: reached.len() as f64 / self.flights.len().max(1) as f64,
            collisions: count(Ending::Collided),
            time_limit: count(Ending::TimeLimit),
            no_path: count(Ending::NoPath),
            stuck: count(Ending::Stuck),
            length_ratio: mean(
                reached
                    .iter()
                    .map(|(f, g)| f.length / g.reference_length.unwrap_or(0.0).max(1e-9))
                    .collect(),
            ),
            time_to_goal_s: mean(reached.iter().map(|(f, _)| f.seconds).collect()),
            frames: self.flights.iter().map(|f| f.frames).sum(),
            depth_images: self.flights.iter().map(|f| f.depth_images).sum(),
            depth_refused: self.flights.iter().map(|f| f.depth_refused).sum(),
            depth_ms: depth[0],
            depth_ms_p95: depth[1],
            integrate_ms: integrate[0],
            integrate_ms_p95: integrate[1],
            update_replan_ms: replan[0],
            update_replan_ms_p95: replan[1],
            guard_ms: guard[0],
            guard_ms_p95: guard[1],
            full_rebuild_ms: rebuild[0],
            full_rebuild_ms_p95: rebuild[1],
        }
    }
}

/// The median and 95th percentile of `values` (zeros when empty).
fn percentiles(mut values: Vec<f64>) -> [f64; 2] {
    if values.is_empty() {
        return [0.0; 2];
    }
    values.sort_by(f64::total_cmp);
    let at = |q: f64| values[((values.len() - 1) as f64 * q).round() as usize];
    [at(0.5), at(0.95)]
}
