use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::Instant;

use anyhow::Context;
use clap::Args;
use fuzzyvox::eval::{ExperimentConfig, ExperimentReport, run_experiment, top_down_png};
use fuzzyvox::io::octomap::write_bt_max_likelihood;
use fuzzyvox::sim::scenario::{self, Scenario};

/// The simulated flight demo: a drone's camera maps the paper's two scenes (a wall, then a
/// random flight over buildings and trees) with the standard log-odds map, the alpha-cut map
/// and the fuzzy map, from the same depth-stage output, and the report compares them against
/// the true scene.
#[derive(Args)]
#[command(after_help = "Examples:\n  fuzzyvox demo\n  fuzzyvox demo --out my-demo --full")]
pub struct DemoArgs {
    /// Where to write the report, metrics, maps and figures.
    #[arg(long, default_value = "demo-out")]
    out: PathBuf,
    /// Fly the paper-scale random flight (700 pairs) instead of the short one (60 pairs).
    #[arg(long)]
    full: bool,
}

pub fn run(args: DemoArgs) -> anyhow::Result<()> {
    let started = Instant::now();
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("creating {}", args.out.display()))?;
    let pairs = if args.full { 700 } else { 60 };
    let mut report = String::from("# fuzzyvox demo\n\n");
    let _ = writeln!(
        report,
        "A simulated camera flies through two scenes. Every stereo pair goes through the depth \
         stage once, and the same interval depth feeds three maps: the standard log-odds map \
         (OctoMap's method), the alpha-cut map (confidence cuts) and the dual-set fuzzy map. \
         Each map is then compared with the true scene.\n"
    );
    let mut all = serde_json::Map::new();
    for (scenario, extent) in [
        (scenario::wall()?, ([-8.0, -16.0], [14.0, 16.0])),
        (scenario::random(pairs, 1)?, ([-65.0, -65.0], [65.0, 65.0])),
    ] {
        eprintln!(
            "[{:>5.1} s] {} scenario: {} stereo pairs ...",
            started.elapsed().as_secs_f64(),
            scenario.name,
            scenario.pairs.len()
        );
        let (result, maps) = run_experiment(&scenario, &ExperimentConfig::default())?;
        section(&mut report, &scenario, &result);
        for (name, map) in &maps {
            let stem = format!("{}-{}", scenario.name, name.replace(':', "_"));
            map.save(args.out.join(format!("{stem}.fvx")))?;
            write_bt_max_likelihood(&args.out.join(format!("{stem}.bt")), map.as_map())?;
            top_down_png(
                map.as_map(),
                extent.0,
                extent.1,
                [0.0, 8.0],
                &args.out.join(format!("{stem}.png")),
            )?;
        }
        let _ = writeln!(
            report,
            "| {} |",
            maps.iter()
                .map(|(n, _)| n.as_str())
                .collect::<Vec<_>>()
                .join(" | ")
        );
        let _ = writeln!(report, "|{}", "---|".repeat(maps.len()));
        let _ = writeln!(
            report,
            "| {} |\n",
            maps.iter()
                .map(|(n, _)| format!("![{n}]({}-{}.png)", scenario.name, n.replace(':', "_")))
                .collect::<Vec<_>>()
                .join(" | ")
        );
        all.insert(scenario.name.to_string(), serde_json::to_value(&result)?);
    }
    let _ = writeln!(
        report,
        "Top-down views: occupied voxel columns coloured by height (blue low, yellow high), free \
         space light green, unknown white. Each map is also saved as `.fvx` (open with \
         `fuzzyvox info`, plan with `fuzzyvox plan`) and `.bt` (OctoMap's tools and octovis).\n\n\
         Total time {:.1} s.",
        started.elapsed().as_secs_f64()
    );
    fuzzyvox::io::write_atomic(&args.out.join("report.md"), report.as_bytes())?;
    fuzzyvox::io::write_atomic(
        &args.out.join("metrics.json"),
        serde_json::to_string_pretty(&all)?.as_bytes(),
    )?;
    println!(
        "wrote {} (report.md, metrics.json, maps and figures) in {:.1} s",
        args.out.display(),
        started.elapsed().as_secs_f64()
    );
    Ok(())
}

/// The report's section for one scenario: what was flown and the metrics table.
fn section(report: &mut String, scenario: &Scenario, result: &ExperimentReport) {
    let _ = writeln!(
        report,
        "## {} scenario\n\n{} stereo pairs ({} could not be rectified and were skipped), {} truly \
         occupied voxels in the region the cameras saw.\n",
        scenario.name, result.pairs, result.rejected_pairs, result.truth_occupied
    );
    let _ = writeln!(
        report,
        "| map | occupied precision | recall | F1 | holes | spurious (unknown region) | Chamfer (m) |\n|---|---|---|---|---|---|---|"
    );
    for (name, map) in &result.maps {
        let m = &map.metrics;
        let _ = writeln!(
            report,
            "| {name} | {:.3} | {:.3} | {:.3} | {} | {} | {:.3} |",
            m.occupied_precision,
            m.occupied_recall,
            m.occupied_f1,
            m.holes,
            m.spurious_unknown,
            m.chamfer_m
        );
    }
    let _ = writeln!(report);
}
