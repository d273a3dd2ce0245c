//! Closed-loop flights as JSON, figures and a Markdown section (for `fuzzyvox fly` and the
//! demo's report).

use std::fmt::Write as _;
use std::path::Path;

use image::RgbImage;
use serde_json::{Value, json};

use super::flight::{Ending, FlightLog};
use super::goals::Goal;
use super::{FlyConfig, ModelFlights};
use crate::error::Result;
use crate::figure::palette::{PATH_COLLIDES, PATH_OK};
use crate::figure::{Overlay, View, ViewColor, ViewSpec, save_png, view_figure};
use crate::map::VoxelMap;

/// The report of a run: `goals`, `goal_list`, `config` and `maps.<model>` (the model's
/// [`ModelSummary`](super::ModelSummary) and its `flights`).
pub fn flights_json(goals: &[Goal], config: &FlyConfig, flights: &[ModelFlights]) -> Value {
    let mut maps = serde_json::Map::new();
    for model in flights {
        let mut entry = serde_json::to_value(model.summary(goals)).unwrap_or(Value::Null);
        entry["flights"] = model
            .flights
            .iter()
            .map(|f| {
                json!({
                    "ending": f.ending,
                    "length_m": f.length,
                    "seconds": f.seconds,
                    "frames": f.frames,
                    "depth_images": f.depth_images,
                    "depth_refused": f.depth_refused,
                    "replans": f.replans,
                    "trajectory": f.trajectory.iter().map(|p| [p.x, p.y, p.z]).collect::<Vec<_>>(),
                })
            })
            .collect();
        maps.insert(model.model.name().to_string(), entry);
    }
    json!({
        "goals": goals.len(),
        "goal_list": goals,
        "config": config,
        "maps": maps,
    })
}

/// A top-down figure of one flight over its final map: occupied voxels by height (the ground
/// left out), the flight in blue (red when it collided) from its start dot, the goal as a red
/// dot, 4 m around start and goal.
pub fn flight_figure(
    map: &dyn VoxelMap,
    goal: &Goal,
    log: &FlightLog,
    title: &str,
) -> Result<RgbImage> {
    let margin = 4.0;
    let mut spec = ViewSpec::new(View::Top, ViewColor::Height);
    spec.window = Some([
        [
            goal.start.x.min(goal.goal.x) - margin,
            goal.start.x.max(goal.goal.x) + margin,
        ],
        [
            goal.start.y.min(goal.goal.y) - margin,
            goal.start.y.max(goal.goal.y) + margin,
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
            points: vec![[goal.goal.x, goal.goal.y]],
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
    goals: &[Goal],
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
    goals: &[Goal],
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
