//! Closed-loop flights as JSON ([`ClosedLoopReport`]), figures and a Markdown section (for
//! `fuzzyvox fly` and the demo's report).

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

use fuzzyvox_core::error::Result;
use fuzzyvox_core::map::VoxelMap;
use fuzzyvox_figure::palette::{PATH_COLLIDES, PATH_OK};
use fuzzyvox_figure::{Overlay, View, ViewColor, ViewSpec, save_png, view_figure};
use fuzzyvox_fly::{Ending, FlightLog, FlyConfig};
use image::RgbImage;
use nalgebra::Point3;
use serde::Serialize;

use super::summary::{ModelFlights, ModelSummary};
use crate::flights::{FlightQuery, QueryConfig};

/// The report of a run of closed-loop flights (`fuzzyvox fly --json`, the demo's
/// `closed_loop` in `metrics.json`).
#[derive(Clone, Debug, Serialize)]
pub struct ClosedLoopReport {
    /// Number of goals flown by every map.
    pub goals: usize,
    /// The goals.
    pub goal_list: Vec<GoalRecord>,
    /// The vehicle's settings and the goals' draw.
    pub config: ClosedLoopConfig,
    /// Per map (by name): its summary and its flights.
    pub maps: BTreeMap<String, ModelReport>,
    /// The scenario flown through (set by the command).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub scenario: Option<String>,
    /// The seed of the scene, the goals and the noise (set by the command).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub seed: Option<u64>,
    /// Wall-clock seconds of the whole run (set by the command).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub seconds: Option<f64>,
}

/// One goal: where the vehicle takes off, where it should go, and the length of the path the
/// true scene allows.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct GoalRecord {
    /// Take-off point.
    pub start: Point3<f64>,
    /// Goal.
    pub goal: Point3<f64>,
    /// Length of the path planned in the true scene, metres.
    pub truth_length: Option<f64>,
}

/// The vehicle's settings with the goals' altitude band, distance range and surface margin.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ClosedLoopConfig {
    /// The vehicle's settings.
    #[serde(flatten)]
    pub vehicle: FlyConfig,
    /// Lowest and highest altitude of starts and goals, metres.
    pub altitude: (f64, f64),
    /// Shortest and longest straight-line distance between start and goal, metres.
    pub distance: (f64, f64),
    /// Extra distance beyond the vehicle radius that starts and goals keep from every true
    /// surface, metres.
    pub surface_margin: f64,
}

/// One map's summary and flights.
#[derive(Clone, Debug, Serialize)]
pub struct ModelReport {
    /// The summary over every flight.
    #[serde(flatten)]
    pub summary: ModelSummary,
    /// Every flight, in goal order.
    pub flights: Vec<FlightRecord>,
}

/// One flight, as reported.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FlightRecord {
    /// How it ended.
    pub ending: Ending,
    /// Length flown, metres.
    pub length_m: f64,
    /// Flight time, seconds.
    pub seconds: f64,
    /// Camera frames taken.
    pub frames: usize,
    /// Depth images integrated.
    pub depth_images: usize,
    /// Pairs the depth stage refused.
    pub depth_refused: usize,
    /// Times the path was planned again.
    pub replans: usize,
    /// Times a blocked path was repaired instead of planned again.
    pub repairs: usize,
    /// The vehicle's positions, the start first.
    pub trajectory: Vec<[f64; 3]>,
}

impl From<&FlightLog> for FlightRecord {
    fn from(f: &FlightLog) -> Self {
        Self {
            ending: f.ending,
            length_m: f.length,
            seconds: f.seconds,
            frames: f.frames,
            depth_images: f.depth_images,
            depth_refused: f.depth_refused,
            replans: f.replans,
            repairs: f.repairs,
            trajectory: f.trajectory.iter().map(|p| [p.x, p.y, p.z]).collect(),
        }
    }
}

impl ClosedLoopReport {
    /// The report of `flights` to `goals` flown with `vehicle`, the goals drawn with `queries`.
    pub fn new(
        goals: &[FlightQuery],
        vehicle: &FlyConfig,
        queries: &QueryConfig,
        flights: &[ModelFlights],
    ) -> Self {
        Self {
            goals: goals.len(),
            goal_list: goals
                .iter()
                .map(|g| GoalRecord {
                    start: g.from,
                    goal: g.to,
                    truth_length: g.reference_length,
                })
                .collect(),
            config: ClosedLoopConfig {
                vehicle: *vehicle,
                altitude: queries.altitude,
                distance: queries.distance,
                surface_margin: queries.surface_margin,
            },
            maps: flights
                .iter()
                .map(|model| {
                    let report = ModelReport {
                        summary: model.summary(goals),
                        flights: model.flights.iter().map(FlightRecord::from).collect(),
                    };
                    (model.model.name().to_string(), report)
                })
                .collect(),
            scenario: None,
            seed: None,
            seconds: None,
        }
    }
}

/// A top-down figure of one flight over its final map: occupied voxels by height (the ground
/// left out), the flight in blue (red when it collided) from its start dot, the goal as a red
/// dot, 4 m around start and goal.
pub fn flight_figure(
    map: &dyn VoxelMap,
    goal: &FlightQuery,
    log: &FlightLog,
    title: &str,
) -> Result<RgbImage> {
    let margin = 4.0;
    let mut spec = ViewSpec::new(View::Top, ViewColor::Height);
    spec.window = Some([
        [
            goal.from.x.min(goal.to.x) - margin,
            goal.from.x.max(goal.to.x) + margin,
        ],
        [
            goal.from.y.min(goal.to.y) - margin,
            goal.from.y.max(goal.to.y) + margin,
        ],
    ]);
    spec.floor = Some(0.3);
    let overlays = vec![
        Overlay {
            points: log.trajectory.iter().map(|p| [p.x, p.y]).collect(),
            color: if log.ending == Ending::Collided {
                PATH_COLLIDES
            } else {
                PATH_OK
            },
            mark_start: true,
        },
        Overlay {
            points: vec![[goal.to.x, goal.to.y]],
            color: PATH_COLLIDES,
            mark_start: true,
        },
    ];
    view_figure(map, &spec, title, overlays, 1)
}

/// Names the figure of a model's flight (model name, goal index).
pub type FigureName<'a> = &'a dyn Fn(&str, usize) -> String;

/// Writes [`flight_figure`] of every flight whose final map was kept into `dir`, named by
/// `name`, titled with `scenario`, the map and how the flight ended.
pub fn write_flight_figures(
    dir: &Path,
    scenario: &str,
    goals: &[FlightQuery],
    flights: &[ModelFlights],
    name: FigureName,
) -> Result<()> {
    for model in flights {
        for (i, (flight, map)) in model.flights.iter().zip(&model.maps).enumerate() {
            let title = format!(
                "{scenario} scenario, {} map, flight {}: {:?}, {:.1} m",
                model.model.name(),
                i + 1,
                flight.ending,
                flight.length
            );
            save_png(
                &flight_figure(map.as_map(), &goals[i], flight, &title)?,
                &dir.join(name(model.model.name(), i)),
            )?;
        }
    }
    Ok(())
}

/// A Markdown section on the flights of a scenario: a table per map and the figures named by
/// `figure(model, goal index)` when given.
pub fn flights_markdown(
    scenario: &str,
    goals: &[FlightQuery],
    flights: &[ModelFlights],
    figure: Option<FigureName>,
) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "### Closed-loop flights\n\n{} flight(s) through the {scenario} scene it has not seen: \
         the vehicle renders its camera every 0.5 m, estimates depth from its own motion, \
         updates its map and replans; each map flies its own flight from the same start to \
         the same goal, and the true scene checks every step (see docs/flight.md).\n",
        goals.len()
    );
    let _ = writeln!(
        out,
        "| map | goals reached | collisions | no path | stuck | out of time | length / true path | \
         depth ms | integration ms | update and replan ms | full rebuild ms |\n\
         |---|---|---|---|---|---|---|---|---|---|---|"
    );
    for model in flights {
        let s = model.summary(goals);
        let _ = writeln!(
            out,
            "| {} | {:.2} | {} | {} | {} | {} | {} | {:.0} | {:.0} | {:.1} | {:.0} |",
            model.model.name(),
            s.reached,
            s.collisions,
            s.no_path,
            s.stuck,
            s.time_limit,
            s.length_ratio.map_or("n/a".into(), |r| format!("{r:.2}")),
            s.depth_ms,
            s.integrate_ms,
            s.update_replan_ms,
            s.full_rebuild_ms,
        );
    }
    if let Some(figure) = figure {
        out.push('\n');
        for model in flights {
            for i in 0..model.flights.len() {
                let name = figure(model.model.name(), i);
                let _ = writeln!(out, "![{} flight {}]({name})", model.model.name(), i + 1);
            }
        }
    }
    out.push('\n');
    out
}
