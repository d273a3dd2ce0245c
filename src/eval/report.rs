//! An experiment's outputs on disk: every map in the native format, the paper-style figures,
//! and a Markdown section with the tables that links them.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use super::experiment::{ExperimentOutput, ExperimentReport};
use super::figures::{TopDownView, depth_panels_png, flights_png, top_down_png};
use super::metrics::MapMetrics;
use crate::error::Result;
use crate::sim::scenario::Scenario;

/// File-name form of a map name (`fuzzy:dombi:2` → `fuzzy_dombi_2`).
pub fn file_stem(name: &str) -> String {
    name.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' || c == '.' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// Writes each map as `SCENARIO-MAP.fvx`, the figures as PNG (`SCENARIO-MAP.png`: top-down
/// occupied voxels; `SCENARIO-MAP-free.png`: the same with free space in green;
/// `SCENARIO-MAP-flights.png` when flights were planned; `SCENARIO-pairN.png`: the depth
/// stage's images of each kept pair) into `dir`, and returns the Markdown section that shows
/// them with the metrics tables, and the files written.
pub fn write_experiment(
    dir: &Path,
    scenario: &Scenario,
    output: &ExperimentOutput,
) -> Result<(String, Vec<PathBuf>)> {
    let view = TopDownView {
        min: scenario.extent[0],
        max: scenario.extent[1],
        heights: scenario.heights,
    };
    let name = scenario.name;
    let mut files = Vec::new();
    for (map_name, map) in &output.maps {
        let stem = format!("{name}-{}", file_stem(map_name));
        let native = dir.join(format!("{stem}.fvx"));
        map.save(&native)?;
        files.push(native);
        let occupied = dir.join(format!("{stem}.png"));
        top_down_png(map.as_map(), &view, false, &occupied)?;
        files.push(occupied);
        let free = dir.join(format!("{stem}-free.png"));
        top_down_png(map.as_map(), &view, true, &free)?;
        files.push(free);
        if let Some((_, outcomes)) = output.flights.iter().find(|(n, _)| n == map_name) {
            let paths: Vec<_> = outcomes
                .iter()
                .filter_map(|o| Some((o.waypoints.as_deref()?, o.collides)))
                .collect();
            let flights = dir.join(format!("{stem}-flights.png"));
            flights_png(map.as_map(), &view, &paths, &flights)?;
            files.push(flights);
        }
    }
    for sample in &output.samples {
        let panels = dir.join(format!("{name}-pair{}.png", sample.pair));
        depth_panels_png(sample, &panels)?;
        files.push(panels);
    }
    Ok((markdown(scenario, output), files))
}

/// The Markdown section of one experiment: what was flown, the metrics (and after each phase),
/// the flights, and the figures written by [`write_experiment`].
pub fn markdown(scenario: &Scenario, output: &ExperimentOutput) -> String {
    let report = &output.report;
    let name = scenario.name;
    let mut md = String::new();
    let matching = match report.views_summary() {
        Some(views) => format!("{views}, {} matched by plane sweep", report.swept_pairs),
        None => format!(
            "{} matched by plane sweep because the camera moved along its view",
            report.swept_pairs
        ),
    };
    let _ = writeln!(
        md,
        "## {name} scenario\n\n{} stereo pairs ({matching}, {} refused by the depth stage); {} \
         truly occupied voxels in the region the cameras saw.\n",
        report.pairs, report.rejected_pairs, report.truth_occupied
    );
    table(&mut md, report, None);
    let phases: Vec<String> = report
        .maps
        .values()
        .next()
        .map(|m| m.after.keys().cloned().collect())
        .unwrap_or_default();
    for phase in &phases {
        let _ = writeln!(md, "{}:\n", phase.replace('_', " "));
        table(&mut md, report, Some(phase));
    }
    if report.maps.values().any(|m| m.flights.is_some()) {
        let _ = writeln!(
            md,
            "Planned flights: the same random start/goal pairs, drawn from the truth alone \
             (truly free space that the cameras saw, clear of every surface), planned in each \
             map and checked against the true geometry with the vehicle's radius swept along \
             every segment. A map in which the start or goal is not safe fails that query; the \
             failures are counted by reason. Length ratio: mean path length over the length of \
             the path planned in the ground-truth (gold-standard) map.\n\n\
             | map | queries | success | collisions | length ratio | start not safe | goal not \
             safe | disconnected | outside the region |\n|---|---|---|---|---|---|---|---|---|"
        );
        let rows = report
            .truth_flights
            .iter()
            .map(|f| ("ground truth".to_string(), f))
            .chain(
                report
                    .maps
                    .iter()
                    .filter_map(|(n, m)| Some((n.clone(), m.flights.as_ref()?))),
            );
        for (map_name, f) in rows {
            let failed = &f.plan_failures;
            let _ = writeln!(
                md,
                "| {map_name} | {} | {:.2} | {} | {} | {} | {} | {} | {} |",
                f.plan_queries,
                f.plan_success,
                f.plan_collisions,
                f.path_length_ratio
                    .map_or("–".to_string(), |r| format!("{r:.3}")),
                failed.start_unsafe,
                failed.goal_unsafe,
                failed.disconnected,
                failed.out_of_region + failed.error
            );
        }
        let _ = writeln!(md);
    }
    let names: Vec<&String> = output.maps.iter().map(|(n, _)| n).collect();
    let header = |md: &mut String| {
        let _ = writeln!(
            md,
            "| {} |\n|{}",
            names
                .iter()
                .map(|n| n.as_str())
                .collect::<Vec<_>>()
                .join(" | "),
            "---|".repeat(names.len())
        );
    };
    let row = |md: &mut String, suffix: &str| {
        let _ = writeln!(
            md,
            "| {} |\n",
            names
                .iter()
                .map(|n| format!("![{n}]({name}-{}{suffix}.png)", file_stem(n)))
                .collect::<Vec<_>>()
                .join(" | ")
        );
    };
    let _ = writeln!(
        md,
        "Top-down views: occupied voxel columns coloured by the height of their highest occupied \
         voxel (blue low, yellow high).\n"
    );
    header(&mut md);
    row(&mut md, "");
    let _ = writeln!(md, "The same with free space in green:\n");
    header(&mut md);
    row(&mut md, "-free");
    if !output.flights.is_empty() {
        let _ = writeln!(
            md,
            "Planned flights over each map (black: clear of the true geometry, red: collides):\n"
        );
        header(&mut md);
        row(&mut md, "-flights");
    }
    if !output.samples.is_empty() {
        let _ = writeln!(
            md,
            "Depth stage, per kept pair: top row the image, the true depth, the error |P0 - \
             truth| (0 to 2 m) and the confidence (black 0, white 1); bottom row P-, P0, P+ and \
             the interval width (0 to 10 m). Black: no value.\n"
        );
        for sample in &output.samples {
            let _ = writeln!(
                md,
                "Pair {}:\n\n![pair {}]({name}-pair{}.png)\n",
                sample.pair, sample.pair, sample.pair
            );
        }
    }
    md
}

fn table(md: &mut String, report: &ExperimentReport, phase: Option<&str>) {
    let _ = writeln!(
        md,
        "| map | occupied | precision | recall | F1 | holes | spurious (unknown region) | \
         Chamfer (m) |\n|---|---|---|---|---|---|---|---|"
    );
    for (map_name, map) in &report.maps {
        let m: &MapMetrics = match phase {
            Some(p) => match map.after.get(p) {
                Some(m) => m,
                None => continue,
            },
            None => &map.metrics,
        };
        let _ = writeln!(
            md,
            "| {map_name} | {} | {:.3} | {:.3} | {:.3} | {} | {} | {:.3} |",
            m.occupied,
            m.occupied_precision,
            m.occupied_recall,
            m.occupied_f1,
            m.holes,
            m.spurious_unknown,
            m.chamfer_m
        );
    }
    let _ = writeln!(md);
}
