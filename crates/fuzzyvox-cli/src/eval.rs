use std::path::PathBuf;
use std::time::Instant;

use anyhow::Context;
use clap::{Args, ValueEnum};
use fuzzyvox::Family;
use fuzzyvox::eval::{
    ExperimentConfig, QueryConfig, run_experiment_with_progress, write_experiment,
};
use fuzzyvox::plan::{PlannerConfig, UnknownPolicy};
use fuzzyvox::sim::scenario::{self, Scenario};

use super::maps::Evidence;
use super::plan::Unknown;

/// Run one of the paper's scenarios: render every stereo pair, run the depth stage, feed the
/// same depth to the log-odds, alpha-cut and fuzzy maps, and measure each against the truth;
/// optionally plan flights in every map and check them against the true scene.
#[derive(Args)]
#[command(after_help = "Examples:\n  \
    fuzzyvox eval --scenario wall --json\n  \
    fuzzyvox eval --scenario wall --out eval-wall        # report.md with figures\n  \
    fuzzyvox eval --scenario random --pairs 300 --plan 100 --out eval-random\n  \
    fuzzyvox eval --scenario random --pairs 100 --seed 7 --ops max,dombi:2 --json")]
pub struct EvalArgs {
    /// Which scenario.
    #[arg(long, value_enum)]
    scenario: ScenarioName,
    /// Stereo pairs of the random flight (the wall scenario always has 12).
    #[arg(long, default_value_t = 100)]
    pairs: usize,
    /// Seed of the random flight, the sensor noise and the flight queries.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Extra fuzzy maps, one per t-conorm (comma-separated NAME[:PARAM]), each reported as
    /// `fuzzy:` and the t-conorm's name (`max` gives `fuzzy:maximum`).
    #[arg(long, value_delimiter = ',')]
    ops: Vec<String>,
    /// Voxel size in metres.
    #[arg(long, default_value_t = 0.2)]
    res: f64,
    /// Camera views behind each depth image: 2 matches every stereo pair on its own (the
    /// paper's depth stage); N > 2 adds the N - 2 most recent earlier camera positions of the
    /// same phase and matches them at once (multiple-baseline plane sweep).
    #[arg(long, default_value_t = 2, value_parser = clap::value_parser!(u32).range(2..=17))]
    views: u32,
    /// With `--views` above 2: give each depth image full weight instead of `2 / views` (by
    /// default images that share views count as one pair's worth of evidence each).
    #[arg(long)]
    unweighted_views: bool,
    /// Evidence model of the fuzzy maps: `dual` (free space weighted by how likely each match
    /// is right, reaching into the depth interval) or `paper` (free space weighted by the
    /// confidence, only in front of the interval), for comparison.
    #[arg(long, value_enum, default_value_t = Evidence::Dual)]
    evidence: Evidence,
    /// Plan this many random flights in every map and check them against the true scene.
    #[arg(long, default_value_t = 0)]
    plan: usize,
    /// Unknown space for the planned flights: forbidden (only known-safe space is flown), or
    /// allowed at a cost (optimistic exploration).
    #[arg(long, value_enum, default_value_t = Unknown::Forbid)]
    unknown: Unknown,
    /// Extra cost per metre through unknown space; only with `--unknown cost` [default: 5].
    #[arg(long, value_name = "C", allow_negative_numbers = true)]
    unknown_cost: Option<f32>,
    /// Write metrics.json, report.md, every map (.fvx) and the figures (PNG) here.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Print the report as one JSON object.
    #[arg(long)]
    json: bool,
}

#[derive(Clone, Copy, ValueEnum)]
pub enum ScenarioName {
    /// A wall seen by 6 strafing, then 6 receding stereo pairs.
    Wall,
    /// A random flight over terrain with buildings and trees.
    Random,
}

impl ScenarioName {
    /// Builds the scenario.
    pub fn build(self, pairs: usize, seed: u64) -> fuzzyvox::Result<Scenario> {
        match self {
            Self::Wall => scenario::wall(),
            Self::Random => scenario::random(pairs, seed),
        }
    }
}

/// The experiment settings of the CLI: the pairs whose depth images go in the report are the
/// first pair of each phase and, for longer flights, one in the middle.
pub fn experiment_config(
    scenario: &Scenario,
    resolution: f64,
    operators: Vec<Family>,
    seed: u64,
    plan: usize,
    unknown: UnknownPolicy,
) -> ExperimentConfig {
    let mut sample_pairs: Vec<usize> = scenario.phases.iter().map(|(_, r)| r.start).collect();
    if scenario.phases.len() == 1 && scenario.pairs.len() > 2 {
        sample_pairs.push(scenario.pairs.len() / 2);
    }
    ExperimentConfig {
        resolution,
        operators,
        seed,
        flights: (plan > 0).then(|| QueryConfig {
            queries: plan,
            seed,
            altitude: scenario.flight_altitude,
            distance: scenario.flight_distance,
            planner: PlannerConfig {
                unknown,
                ..PlannerConfig::default()
            },
            ..QueryConfig::default()
        }),
        sample_pairs,
        ..ExperimentConfig::default()
    }
}

/// Runs an experiment with a progress bar over its pairs (hidden for JSON or without a
/// terminal), logging the phase timings with `-v`.
pub fn run_with_bar(
    scenario: &Scenario,
    config: &ExperimentConfig,
    json: bool,
) -> anyhow::Result<fuzzyvox::eval::ExperimentOutput> {
    let label = format!("{} scenario", scenario.name);
    let bar = super::progress::bar(scenario.pairs.len() as u64, &label, json);
    let output = run_experiment_with_progress(scenario, config, &mut |done, _| {
        bar.set_position(done as u64);
    })?;
    bar.finish_and_clear();
    for (stage, seconds) in &output.report.seconds {
        tracing::info!("{}: {stage} {seconds:.1} s", scenario.name);
    }
    Ok(output)
}

pub fn run(args: EvalArgs) -> anyhow::Result<()> {
    let unknown = args
        .unknown
        .policy(args.unknown_cost)
        .unwrap_or_else(|e| e.exit());
    if args.pairs == 0 {
        anyhow::bail!("--pairs must be at least 1");
    }
    let operators = args
        .ops
        .iter()
        .map(|op| op.parse::<Family>().with_context(|| format!("--ops {op}")))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let scenario = args.scenario.build(args.pairs, args.seed)?;
    let mut config = experiment_config(
        &scenario, args.res, operators, args.seed, args.plan, unknown,
    );
    config.views = args.views as usize;
    config.weigh_reused_views = !args.unweighted_views;
    config.evidence = args.evidence.model();
    let started = Instant::now();
    let output = run_with_bar(&scenario, &config, args.json)?;
    let seconds = started.elapsed().as_secs_f64();
    let report = &output.report;
    if let Some(dir) = &args.out {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
        let json = serde_json::to_string_pretty(report)?;
        fuzzyvox::io::write_atomic(&dir.join("metrics.json"), json.as_bytes())?;
        let (section, _) = write_experiment(dir, &scenario, &output)?;
        let page = format!(
            "# fuzzyvox eval: {} scenario\n\nCommand: `fuzzyvox {}`; {seconds:.1} s.\n\n{section}",
            scenario.name,
            std::env::args().skip(1).collect::<Vec<_>>().join(" ")
        );
        fuzzyvox::io::write_atomic(&dir.join("report.md"), page.as_bytes())?;
    }
    if args.json {
        return super::print_json(&serde_json::to_value(report)?);
    }
    let views = report
        .views_summary()
        .map_or(String::new(), |summary| format!(", {summary}"));
    println!(
        "{} scenario: {} pairs ({} by plane sweep, {} rejected{views}) in {seconds:.1} s; {} truly occupied voxels",
        report.scenario,
        report.pairs,
        report.swept_pairs,
        report.rejected_pairs,
        report.truth_occupied
    );
    if let Some(stage) = &report.depth_stage {
        println!(
            "depth stage on {} sampled depth images against the true depth: median relative \
             error {:.3} (90th percentile {:.3}), true depth inside [P-, P+] {:.2}",
            stage.images,
            stage.median_rel_error,
            stage.rel_error_quantiles.p90,
            stage.interval_coverage
        );
    }
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
    if report.maps.values().any(|m| m.flights.is_some()) {
        println!(
            "{:<16} {:>9} {:>9} {:>10} {:>12}",
            "flights", "queries", "success", "collisions", "length ratio"
        );
        let truth = report.truth_flights.iter().map(|f| ("ground truth", f));
        let maps = report
            .maps
            .iter()
            .filter_map(|(n, m)| Some((n.as_str(), m.flights.as_ref()?)));
        for (name, f) in truth.chain(maps) {
            println!(
                "{name:<16} {:>9} {:>9.2} {:>10} {:>12}",
                f.plan_queries,
                f.plan_success,
                f.plan_collisions,
                f.path_length_ratio
                    .map_or("-".to_string(), |r| format!("{r:.3}"))
            );
        }
    }
    if let Some(dir) = &args.out {
        println!("wrote {}", dir.join("report.md").display());
    }
    Ok(())
}
