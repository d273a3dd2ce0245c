//! An experiment's outputs on disk: every map in the native format, the paper-style figures,
//! and a Markdown section with the tables that links them.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use super::charts::{depth_confidence_chart, maps_chart, operators_chart};
use super::experiment::{ExperimentOutput, ExperimentReport};
use super::figures::{TopDownView, depth_panels_png, flights_png, top_down_png};
use super::metrics::MapMetrics;
use fuzzyvox_core::error::Result;
use fuzzyvox_sim::scenario::Scenario;
use fuzzyvox_view::{PagePath, PathKind, ViewerOptions, write_viewer_page};

/// Free (and unknown) voxels written to each map's viewer page at most.
const PAGE_MAX_FREE: usize = 150_000;

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
        let title = |what: &str| format!("{name} scenario, {map_name} map: {what}");
        top_down_png(
            map.as_map(),
            &view,
            false,
            &title("occupied voxels by height"),
            &occupied,
        )?;
        files.push(occupied);
        let free = dir.join(format!("{stem}-free.png"));
        top_down_png(
            map.as_map(),
            &view,
            true,
            &title("occupied by height, free space"),
            &free,
        )?;
        files.push(free);
        if let Some((_, outcomes)) = output.flights.iter().find(|(n, _)| n == map_name) {
            let paths: Vec<_> = outcomes
                .iter()
                .filter_map(|o| Some((o.waypoints.as_deref()?, o.collides)))
                .collect();
            let flights = dir.join(format!("{stem}-flights.png"));
            flights_png(
                map.as_map(),
                &view,
                &paths,
                &title("planned flights (red: collides)"),
                &flights,
            )?;
            files.push(flights);
        }
    }
    let trajectory = PagePath {
        name: "camera".into(),
        kind: PathKind::Trajectory,
        ok: true,
        points: scenario
            .pairs
            .iter()
            .map(|(pose, _)| {
                let t = pose.translation.vector;
                [t.x, t.y, t.z]
            })
            .collect(),
    };
    for (map_name, map) in &output.maps {
        let stem = format!("{name}-{}", file_stem(map_name));
        let mut paths = vec![trajectory.clone()];
        if let Some((_, outcomes)) = output.flights.iter().find(|(n, _)| n == map_name) {
            paths.extend(outcomes.iter().enumerate().filter_map(|(i, o)| {
                Some(PagePath {
                    name: format!("flight {}", i + 1),
                    kind: PathKind::Flight,
                    ok: !o.collides,
                    points: o
                        .waypoints
                        .as_ref()?
                        .iter()
                        .map(|p| [p.x, p.y, p.z])
                        .collect(),
                })
            }));
        }
        let json = dir.join(format!("{stem}-paths.json"));
        let text = serde_json::to_string(&serde_json::json!({ "paths": paths })).map_err(|e| {
            fuzzyvox_core::error::Error::Io {
                path: json.clone(),
                source: std::io::Error::other(e),
            }
        })?;
        fuzzyvox_io::write_atomic(&json, text.as_bytes())?;
        files.push(json);
        let mut options = ViewerOptions::new(
            format!("{name} scenario, {map_name} map"),
            map.kind().name(),
        );
        options.max_free = PAGE_MAX_FREE;
        options.paths = paths;
        let page = dir.join(format!("{stem}.html"));
        write_viewer_page(map.as_map(), &options, &page)?;
        files.push(page);
    }
    let charts = [
        ("maps", Some(maps_chart(&output.report))),
        ("operators", operators_chart(&output.report)),
        (
            "depth-confidence",
            depth_confidence_chart(name, &output.samples),
        ),
    ];
    let mut written = Vec::new();
    for (what, chart) in charts {
        if let Some(chart) = chart {
            files.extend(chart.save(&dir.join(format!("{name}-{what}")))?);
            written.push(what);
        }
    }
    for sample in &output.samples {
        let panels = dir.join(format!("{name}-pair{}.png", sample.pair));
        let title = format!("{name} scenario, pair {}: the depth stage", sample.pair);
        depth_panels_png(sample, &title, &panels)?;
        files.push(panels);
    }
    Ok((markdown(scenario, output, &written), files))
}

/// The Markdown section of one experiment: what was flown, the metrics (and after each phase),
/// the flights, the figures and viewer pages written by [`write_experiment`], and the charts
/// named in `charts` (`maps`, `operators`, `depth-confidence`).
pub fn markdown(scenario: &Scenario, output: &ExperimentOutput, charts: &[&str]) -> String {
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
             failures are counted by reason, and the unsafe starts and goals by what blocks \
             them (the class of the point's voxel, or of the blocked voxel nearest to it; a point \
             outside everything the map observed counts as unknown). \
             Length ratio: mean path length over the length of the path planned in the \
             ground-truth (gold-standard) map.\n\n\
             | map | queries | success | collisions | length ratio | start not safe | goal not \
             safe | disconnected | outside the region | blocked by: unknown / occupied / \
             ambiguous / low safety |\n|---|---|---|---|---|---|---|---|---|---|"
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
                "| {map_name} | {} | {:.2} | {} | {} | {} | {} | {} | {} | {} / {} / {} / {} |",
                f.plan_queries,
                f.plan_success,
                f.plan_collisions,
                f.path_length_ratio
                    .map_or("–".to_string(), |r| format!("{r:.3}")),
                failed.start_unsafe,
                failed.goal_unsafe,
                failed.disconnected,
                failed.out_of_region + failed.error,
                failed.blocked_by.unknown + failed.blocked_by.outside_extent,
                failed.blocked_by.occupied,
                failed.blocked_by.ambiguous,
                failed.blocked_by.low_safety
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
    for chart in charts {
        let _ = writeln!(md, "![{name} {chart} chart]({name}-{chart}.svg)\n");
    }
    let _ = writeln!(
        md,
        "3D views (open in a browser; drag to orbit, wheel to zoom, hover to read a voxel): {}\n",
        names
            .iter()
            .map(|n| format!("[{n}]({name}-{}.html)", file_stem(n)))
            .collect::<Vec<_>>()
            .join(" · ")
    );
    let _ = writeln!(
        md,
        "Top-down views: occupied voxel columns coloured by the height of their highest occupied \
         voxel (viridis: purple low, yellow high); unknown space light grey.\n"
    );
    header(&mut md);
    row(&mut md, "");
    let _ = writeln!(md, "The same with free space in green:\n");
    header(&mut md);
    row(&mut md, "-free");
    if !output.flights.is_empty() {
        let _ = writeln!(
            md,
            "Planned flights over each map (blue: clear of the true geometry, red: collides):\n"
        );
        header(&mut md);
        row(&mut md, "-flights");
    }
    if !output.samples.is_empty() {
        let _ = writeln!(
            md,
            "Depth stage, per kept pair: top row the image, the true depth, the error |P0 - \
             truth| (0 to 2 m) and the confidence (0 to 1); bottom row P-, P0, P+ and the \
             interval width (0 to 10 m), each with its colour bar. Black: no value.\n"
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

/// The report as one HTML page (`report.html` beside `report.md`): the same Markdown rendered,
/// with its tables, figures, charts and links to the viewer pages, styled to read well. The
/// page needs nothing but the files beside it.
pub fn report_html(title: &str, markdown: &str) -> String {
    use pulldown_cmark::{Options, Parser, html};
    let mut body = String::new();
    html::push_html(&mut body, Parser::new_ext(markdown, Options::ENABLE_TABLES));
    format!(
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n\
         <title>{}</title>\n<style>{REPORT_CSS}</style>\n</head>\n<body>\n<main>\n{body}</main>\n\
         </body>\n</html>\n",
        fuzzyvox_view::escape_html(title)
    )
}

const REPORT_CSS: &str = "\
body { margin: 0; background: #fafaf7; color: #222; \
  font: 15px/1.5 system-ui, -apple-system, 'Segoe UI', sans-serif; }
main { max-width: 1200px; margin: 0 auto; padding: 24px; }
h1, h2 { font-weight: 600; } h2 { margin-top: 2.2em; border-bottom: 1px solid #ddd; }
table { border-collapse: collapse; margin: 1em 0; font-variant-numeric: tabular-nums; }
th, td { border: 1px solid #ddd; padding: 4px 8px; text-align: right; vertical-align: top; }
th:first-child, td:first-child { text-align: left; }
td img { max-width: 380px; }
img { max-width: 100%; height: auto; }
code { background: #eee; padding: 0 3px; border-radius: 3px; }
a { color: #0a58ca; }
";
