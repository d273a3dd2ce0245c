use std::path::PathBuf;
use std::time::Instant;

use anyhow::Context;
use clap::{Args, ValueEnum};
use fuzzyvox::Family;
use fuzzyvox::eval::{ExperimentConfig, run_experiment};
use fuzzyvox::sim::scenario;

/// Run one of the paper's scenarios: render every stereo pair, run the depth stage, feed the
/// same depth to the log-odds, alpha-cut and fuzzy maps, and measure each against the truth.
#[derive(Args)]
#[command(after_help = "Examples:\n  \
    fuzzyvox eval --scenario wall --json\n  \
    fuzzyvox eval --scenario random --pairs 300 --seed 7 --ops max,dombi:2 --out eval-random")]
pub struct EvalArgs {
    /// Which scenario.
    #[arg(long, value_enum)]
    scenario: Scenario,
    /// Stereo pairs of the random flight.
    #[arg(long, default_value_t = 100)]
    pairs: usize,
    /// Seed of the random flight and of the sensor noise.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Extra fuzzy maps, one per t-conorm (comma-separated NAME[:PARAM]).
    #[arg(long, value_delimiter = ',')]
    ops: Vec<String>,
    /// Voxel size in metres.
    #[arg(long, default_value_t = 0.2)]
    res: f64,
    /// Write `metrics.json` and each map (native format) here.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Print the report as one JSON object.
    #[arg(long)]
    json: bool,
}

#[derive(Clone, Copy, ValueEnum)]
enum Scenario {
    /// A wall seen by 6 strafing, then 6 receding stereo pairs.
    Wall,
    /// A random flight over terrain with buildings and trees.
    Random,
}

pub fn run(args: EvalArgs) -> anyhow::Result<()> {
    let operators = args
        .ops
        .iter()
        .map(|op| op.parse::<Family>().with_context(|| format!("--ops {op}")))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let scenario = match args.scenario {
        Scenario::Wall => scenario::wall()?,
        Scenario::Random => scenario::random(args.pairs, args.seed)?,
    };
    let config = ExperimentConfig {
        resolution: args.res,
        operators,
        seed: args.seed,
        ..ExperimentConfig::default()
    };
    let started = Instant::now();
    let (report, maps) = run_experiment(&scenario, &config)?;
    let seconds = started.elapsed().as_secs_f64();
    if let Some(dir) = &args.out {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
        let json = serde_json::to_string_pretty(&report)?;
        fuzzyvox::io::write_atomic(&dir.join("metrics.json"), json.as_bytes())?;
        for (name, map) in &maps {
            map.save(dir.join(format!("{}.fvx", name.replace(':', "_"))))?;
        }
    }
    if args.json {
        return super::print_json(&serde_json::to_value(&report)?);
    }
    println!(
        "{} scenario: {} pairs ({} rejected by the depth stage) in {seconds:.1} s; {} truly occupied voxels",
        report.scenario, report.pairs, report.rejected_pairs, report.truth_occupied
    );
    println!(
        "{:<16} {:>9} {:>9} {:>9} {:>8} {:>9} {:>9}",
        "map", "precision", "recall", "F1", "holes", "spurious", "chamfer"
    );
    for (name, map) in &report.maps {
        let m = &map.metrics;
        println!(
            "{name:<16} {:>9.3} {:>9.3} {:>9.3} {:>8} {:>9} {:>8.3}m",
            m.occupied_precision,
            m.occupied_recall,
            m.occupied_f1,
            m.holes,
            m.spurious_unknown,
            m.chamfer_m
        );
    }
    Ok(())
}
