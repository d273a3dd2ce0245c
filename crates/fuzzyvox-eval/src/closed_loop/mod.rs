//! Closed-loop flights as an experiment: where the vehicle goes (start/goal pairs drawn by the
//! one drawer, [`draw_goals`]), every goal flown with every map ([`fly_all`]), the summary per
//! map ([`ModelSummary`]) and the reports ([`ClosedLoopReport`], figures, Markdown). The
//! vehicle itself (camera, steering, the loop) is `fuzzyvox_fly`'s.
//!
//! Each map flies its own flight from the same start to the same goal through the same scene,
//! from an empty map of its kind with the prior around the start.

mod report;
mod summary;
mod truth;

use std::time::Instant;

use fuzzyvox_core::error::{Error, Result};
use fuzzyvox_core::map::{AnyMap, MapKind};
use fuzzyvox_core::storage::Resolution;
use fuzzyvox_fly::{Flight, FlyConfig, integrate_prior, planning_region};
use fuzzyvox_plan::{CostField, UnknownPolicy, plan_in_field};
use fuzzyvox_sim::scenario::Scenario;
use nalgebra::Point3;

use crate::flights::{Candidates, FlightQuery, QueryConfig, draw_queries};
pub use report::{
    ClosedLoopConfig, ClosedLoopReport, FigureName, FlightRecord, GoalRecord, ModelReport,
    flight_figure, flights_markdown, write_flight_figures,
};
pub use summary::{ModelFlights, ModelSummary};
pub use truth::truth_map;

/// Cycles between two timed full rebuilds of a flight's cost field (the yardstick of the
/// incremental update).
pub const REBUILD_EVERY: usize = 10;

/// Draws the goals of closed-loop flights in `scenario`: voxel centres drawn uniformly in the
/// scenario's extent within `queries`' altitude band and distance range, clear of every true
/// surface, and connected in the true scene through the planning region the vehicle would use
/// (the path planned there gives [`FlightQuery::reference_length`]). Deterministic for the
/// seed; fewer come back when too few candidates exist.
pub fn draw_goals(
    scenario: &Scenario,
    vehicle: &FlyConfig,
    queries: &QueryConfig,
) -> Result<Vec<FlightQuery>> {
    let vehicle = vehicle.validate()?;
    let resolution = Resolution::new(vehicle.resolution)?;
    let truth = truth_map(scenario, resolution);
    let mut planner = queries.planner;
    planner.unknown = UnknownPolicy::Forbid;
    let connect = |start: &Point3<f64>, goal: &Point3<f64>| -> Result<Option<f64>> {
        let region = planning_region(&resolution, start, goal, &vehicle)?;
        let field = CostField::build(&truth, region, planner)?;
        let (a, b) = (resolution.key_of(start)?, resolution.key_of(goal)?);
        Ok(plan_in_field(&field, a, b).ok().map(|path| path.length))
    };
    draw_queries(
        &scenario.scene,
        Candidates::Uniform {
            extent: scenario.extent,
            resolution,
            connect: &connect,
        },
        queries,
    )
}

/// Flies every goal with every model: each flight starts from an empty map of its model with
/// the prior around its start. `keep_maps` keeps each flight's final map (for figures). Every
/// [`REBUILD_EVERY`]th cycle of every flight also times a full rebuild of the cost field over
/// the flight's planning region (outside the vehicle's loop). `progress(done, total)` is called
/// after each flight. Deterministic for `seed`.
pub fn fly_all(
    scenario: &Scenario,
    goals: &[FlightQuery],
    models: &[MapKind],
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
        let mut rebuild_ms = Vec::new();
        for (i, goal) in goals.iter().enumerate() {
            let mut map = model.new_map(config.resolution)?;
            integrate_prior(scenario, &mut map, &goal.from, &config)?;
            let flight_seed = seed.wrapping_mul(7919).wrapping_add(i as u64);
            let mut flight =
                Flight::new(scenario, &goal.from, &goal.to, &map, &config, flight_seed)?;
            while flight.ending().is_none() {
                let frames = flight.log().frames;
                flight.cycle(&mut map)?;
                let seen = flight.log().frames > frames;
                if seen && frames.is_multiple_of(REBUILD_EVERY) {
                    rebuild_ms.push(time_rebuild(&flight, &map, &config)?);
                }
            }
            flights.push(flight.into_log());
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
            rebuild_ms,
        });
    }
    Ok(out)
}

/// Milliseconds a full build of the flight's cost field from `map` takes.
fn time_rebuild(flight: &Flight, map: &AnyMap, config: &FlyConfig) -> Result<f64> {
    let t = Instant::now();
    CostField::build(
        map.as_map(),
        *flight.planner().field().region(),
        config.planner,
    )?;
    Ok(t.elapsed().as_secs_f64() * 1e3)
}
