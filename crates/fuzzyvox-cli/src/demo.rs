use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::Instant;

use anyhow::Context;
use clap::Args;
use fuzzyvox::eval::QueryConfig;
use fuzzyvox::eval::closed_loop::{
    ClosedLoopReport, draw_goals, flights_markdown, fly_all, write_flight_figures,
};
use fuzzyvox::eval::{file_stem, report_html, write_experiment};
use fuzzyvox::fly::FlyConfig;
use fuzzyvox::io::octomap::write_bt_max_likelihood;
use fuzzyvox::io::ply::{PlyEncoding, write_ply};
use fuzzyvox::ops::Family;
use fuzzyvox::plan::UnknownPolicy;
use fuzzyvox::sim::scenario;
use fuzzyvox::{MapKind, VoxelClass};

use super::eval::{experiment_config, run_with_bar};
use super::maps::Evidence;

/// The simulated flight demo: a drone's camera maps the paper's two scenes (a wall, then a
/// random flight over buildings and trees) with the standard log-odds map, the alpha-cut map
/// and the fuzzy map, from the same depth-stage output; flights are planned in every map and
/// checked against the true scene, and the report compares everything side by side.
#[derive(Args)]
#[command(
    after_help = "Examples:\n  fuzzyvox demo\n  fuzzyvox demo --out my-demo --full\n  fuzzyvox demo --json > metrics.json"
)]
pub struct DemoArgs {
    /// Where to write the report, metrics, maps and figures.
    #[arg(long, default_value = "demo-out")]
    out: PathBuf,
    /// Fly the paper-scale random flight (700 pairs, 100 planned flights) instead of the short
    /// one (60 pairs, 30 flights).
    #[arg(long)]
    full: bool,
    /// Print the metrics (what `metrics.json` holds, plus `out` and `seconds`) as one line of
    /// JSON instead of the summary, without progress.
    #[arg(long)]
    json: bool,
    /// Evidence model of the fuzzy map: `dual` (the default) or `paper`, for comparison.
    #[arg(long, value_enum, default_value_t = Evidence::Dual)]
    evidence: Evidence,
}

pub fn run(args: DemoArgs) -> anyhow::Result<()> {
    let started = Instant::now();
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("creating {}", args.out.display()))?;
    let (pairs, flights) = if args.full { (700, 100) } else { (60, 30) };
    let mut report = String::from("# fuzzyvox demo\n\n");
    let _ = writeln!(
        report,
        "A simulated camera flies through two scenes. Every stereo pair goes through the depth \
         stage once, and the same interval depth feeds three maps: the standard log-odds map \
         (OctoMap's method), the alpha-cut map (confidence cuts) and the dual-set fuzzy map. \
         Each map is then compared with the true scene, and flights planned in each map are \
         checked against the true geometry.\n"
    );
    let mut all = serde_json::Map::new();
    for scenario in [scenario::wall()?, scenario::random(pairs, 1)?] {
        if !args.json {
            eprintln!(
                "[{:>5.1} s] {} scenario: {} stereo pairs ...",
                started.elapsed().as_secs_f64(),
                scenario.name,
                scenario.pairs.len()
            );
        }
        // The wall also compares aggregation operators: the maximum (idempotent, what a
        // possibilistic map would use) and the bounded sum beside the default probabilistic sum.
        let operators = if scenario.name == "wall" {
            vec![Family::Minimum, Family::Lukasiewicz]
        } else {
            Vec::new()
        };
        let mut config =
            experiment_config(&scenario, 0.2, operators, 1, flights, UnknownPolicy::Forbid);
        config.evidence = args.evidence.model();
        let output = run_with_bar(&scenario, &config, args.json)?;
        let (section, _) = write_experiment(&args.out, &scenario, &output)?;
        report.push_str(&section);
        for (name, map) in &output.maps {
            let stem = format!("{}-{}", scenario.name, file_stem(name));
            write_bt_max_likelihood(&args.out.join(format!("{stem}.bt")), map.as_map())?;
            // Occupied and ambiguous voxels with their measures, for any point-cloud viewer.
            write_ply(
                map.as_map(),
                &[VoxelClass::Occupied, VoxelClass::Ambiguous],
                PlyEncoding::BinaryLittleEndian,
                &args.out.join(format!("{stem}.ply")),
            )?;
        }
        let mut metrics = serde_json::to_value(&output.report)?;
        // A short closed-loop flight: each map flies to one goal through the scene, mapping
        // with depth from the vehicle's own motion.
        let fly_config = FlyConfig::default();
        let queries = QueryConfig {
            distance: (6.0, 10.0),
            ..QueryConfig::closed_loop(1, 1, fly_config.planner)
        };
        let goals = draw_goals(&scenario, &fly_config, &queries)?;
        let flights = fly_all(
            &scenario,
            &goals,
            &MapKind::ALL,
            &fly_config,
            1,
            true,
            &mut |_, _| {},
        )?;
        let figure_name =
            |model: &str, i: usize| format!("{}-fly-{model}-{}.png", scenario.name, i + 1);
        write_flight_figures(&args.out, scenario.name, &goals, &flights, &figure_name)?;
        report.push_str(&flights_markdown(
            scenario.name,
            &goals,
            &flights,
            Some(&figure_name),
        ));
        metrics["closed_loop"] = serde_json::to_value(ClosedLoopReport::new(
            &goals,
            &fly_config,
            &queries,
            &flights,
        ))?;
        all.insert(scenario.name.to_string(), metrics);
    }
    let _ = writeln!(
        report,
        "Each map is also saved as `.fvx` (open with `fuzzyvox info`, plan with `fuzzyvox \
         plan`, view with `fuzzyvox view`), `.html` (its 3D viewer page, with the camera's \
         trajectory and the planned flights), `.bt` (OctoMap's tools and octovis) and `.ply` \
         (occupied and ambiguous voxel centres with their measures, for point-cloud \
         viewers).\n\nTotal time {:.1} s.",
        started.elapsed().as_secs_f64()
    );
    fuzzyvox::io::write_atomic(&args.out.join("report.md"), report.as_bytes())?;
    fuzzyvox::io::write_atomic(
        &args.out.join("report.html"),
        report_html("fuzzyvox demo", &report).as_bytes(),
    )?;
    fuzzyvox::io::write_atomic(
        &args.out.join("metrics.json"),
        serde_json::to_string_pretty(&all)?.as_bytes(),
    )?;
    let seconds = started.elapsed().as_secs_f64();
    if args.json {
        all.insert("out".into(), args.out.display().to_string().into());
        all.insert("seconds".into(), seconds.into());
        return super::print_json(&serde_json::Value::Object(all));
    }
    println!(
        "wrote {} (report.html and report.md, metrics.json, maps, figures, charts and 3D viewer \
         pages) in {seconds:.1} s",
        args.out.display(),
    );
    Ok(())
}
