//! Closed-loop flights: a simulated vehicle with one camera flies to a goal through a scene it
//! has not seen, mapping as it goes. Every cycle it plans through what its map knows, advances
//! a little, takes a picture, estimates depth from its own motion (poor when it flies towards
//! what it looks at), updates the map and replans. Each map flies its own flight from the same
//! start to the same goal through the same scene, and the true scene checks every step.
//!
//! - [`config`]: the loop's parameters ([`FlyConfig`]);
//! - [`goals`]: starts and goals in truly free space, and the true scene's path between them;
//! - [`guard`]: no unseen space near the vehicle ([`UnknownGuard`]);
//! - [`flight`]: one flight ([`fly_goal`]) and the prior map around the start;
//! - [`report`]: the flights as JSON, figures and Markdown;
//! - this module: every goal with every map ([`fly_all`]) and the summary per map.

use fuzzyvox_core::{error, integrate, map, measures, storage};
use fuzzyvox_depth as depth;
use fuzzyvox_figure as figure;
use fuzzyvox_plan as plan;
use fuzzyvox_sim as sim;

pub mod config;
pub mod flight;
pub mod goals;
pub mod guard;
pub mod report;

use serde::Serialize;

pub use config::FlyConfig;
pub use flight::{CycleTimes, Ending, Flight, FlightLog, LOOK_FRAMES, fly_goal, integrate_prior};
pub use goals::{Goal, draw_goals, planning_region, truth_map};
pub use guard::UnknownGuard;
pub use report::{flight_figure, flights_json, flights_markdown, write_flight_figures};

use crate::error::{Error, Result};
use crate::map::{
    AlphaConfig, AlphaCutMap, AnyMap, FuzzyConfig, FuzzyMap, LogOddsConfig, LogOddsMap,
};
use crate::sim::scenario::Scenario;

/// The maps a vehicle can fly with.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum FlyModel {
    /// The dual-set fuzzy map (default evidence model).
    Fuzzy,
    /// The standard log-odds map.
    LogOdds,
    /// The alpha-cut map.
    Alpha,
}

impl FlyModel {
    /// Every model, in report order.
    pub const ALL: [FlyModel; 3] = [FlyModel::Fuzzy, FlyModel::LogOdds, FlyModel::Alpha];

    /// `fuzzy`, `logodds` or `alpha`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Fuzzy => "fuzzy",
            Self::LogOdds => "logodds",
            Self::Alpha => "alpha",
        }
    }

    /// An empty map of this model at `resolution` metres.
    pub fn new_map(self, resolution: f64) -> Result<AnyMap> {
        Ok(match self {
            Self::Fuzzy => AnyMap::Fuzzy(FuzzyMap::new(FuzzyConfig::new(resolution)?)?),
            Self::LogOdds => AnyMap::LogOdds(LogOddsMap::new(LogOddsConfig::new(resolution)?)?),
            Self::Alpha => AnyMap::Alpha(AlphaCutMap::new(AlphaConfig::new(resolution)?)?),
        })
    }
}

/// One model's flights.
#[derive(Clone, Debug, Serialize)]
pub struct ModelFlights {
    /// The model.
    pub model: FlyModel,
    /// One log per goal, in goal order.
    pub flights: Vec<FlightLog>,
    /// Each flight's final map, in goal order (kept only when asked for).
    #[serde(skip)]
    pub maps: Vec<AnyMap>,
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
    /// Flights that came no nearer to their goal for [`FlyConfig::patience`] seconds.
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
    /// A full rebuild of the cost field over the planning region, timed on every tenth cycle,
    /// milliseconds.
    pub full_rebuild_ms: f64,
    /// See `full_rebuild_ms`.
    pub full_rebuild_ms_p95: f64,
}

impl ModelFlights {
    /// The summary over every flight; `goals` are the flights' goals, in the same order.
    pub fn summary(&self, goals: &[Goal]) -> ModelSummary {
        let reached: Vec<(&FlightLog, &Goal)> = self
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
        let rebuild = times(|c| c.full_rebuild_ms);
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
                    .map(|(f, g)| f.length / g.truth_length.max(1e-9))
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

/// Flies every goal with every model: each flight starts from an empty map of its model with
/// the prior around its start. `keep_maps` keeps each flight's final map (for figures).
/// `progress(done, total)` is called after each flight. Deterministic for `seed`.
pub fn fly_all(
    scenario: &Scenario,
    goals: &[Goal],
    models: &[FlyModel],
    config: &FlyConfig,
    seed: u64,
    keep_maps: bool,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<Vec<ModelFlights>> {
    let config = config.validate()?;
    if models.is_empty() {
        return Err(Error::Empty("models to fly"));
    }
    let total = goals.len() * models.len();
    let mut done = 0;
    let mut out = Vec::new();
    for &model in models {
        let mut flights = Vec::new();
        let mut maps = Vec::new();
        for (i, goal) in goals.iter().enumerate() {
            let mut map = model.new_map(config.resolution)?;
            integrate_prior(scenario, &mut map, &goal.start, &config)?;
            let flight_seed = seed.wrapping_mul(7919).wrapping_add(i as u64);
            flights.push(fly_goal(scenario, goal, &mut map, &config, flight_seed)?);
            if keep_maps {
                maps.push(map);
            }
            done += 1;
            progress(done, total);
        }
        out.push(ModelFlights {
            model,
            flights,
            maps,
        });
    }
    Ok(out)
}
