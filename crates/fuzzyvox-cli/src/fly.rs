use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, bail};
use clap::Args;
use fuzzyvox::MapKind;
use fuzzyvox::eval::QueryConfig;
use fuzzyvox::eval::closed_loop::{ClosedLoopReport, draw_goals, fly_all, write_flight_figures};
use fuzzyvox::fly::FlyConfig;
use fuzzyvox::plan::UnknownPolicy;

use super::eval::ScenarioName;
use super::maps::ModelArg;
use super::plan::Unknown;

/// Fly closed-loop flights: a simulated vehicle with one camera flies from a start to a goal
/// through a scenario it has not seen. Every frame it renders its camera, estimates depth from
/// its own motion (plane sweep when it flies towards what it looks at), updates its map, keeps
/// or replans its path, and advances; the true scene checks every step with the vehicle's
/// swept ball. Each map flies its own flight from the same start to the same goal.
///
/// See docs/flight.md for the loop, its parameters and results.
#[derive(Args)]
#[command(after_help = "Examples:\n  \
    fuzzyvox fly --scenario random --seed 3 --goals 5\n  \
    fuzzyvox fly --scenario wall --goals 3 --model fuzzy,logodds --json\n  \
    fuzzyvox fly --scenario random --goals 20 --out fly-random   # fly.json and a figure per flight")]
pub struct FlyArgs {
    /// Which scenario's scene to fly through.
    #[arg(long, value_enum)]
    scenario: ScenarioName,
    /// Seed of the scene (random scenario), the goals and the sensor noise.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Number of flights (start/goal pairs) per map.
    #[arg(long, default_value_t = 5)]
    goals: usize,
    /// Maps to fly with: `all`, or a comma-separated list of fuzzy, logodds, alpha.
    #[arg(long, value_delimiter = ',', default_value = "all", value_parser = ModelArg::parser())]
    model: Vec<ModelArg>,
    /// Camera views per depth image: 2 matches each frame against the previous one; N > 2
    /// adds earlier frames (multiple-baseline plane sweep).
    #[arg(long, default_value_t = 2, value_parser = clap::value_parser!(u32).range(2..=17))]
    views: u32,
    /// Unknown space: allowed at a cost (default: goals lie in space not seen yet), or
    /// forbidden (the vehicle flies to the known-safe voxel nearest the goal and looks again).
    #[arg(long, value_enum, default_value_t = Unknown::Cost)]
    unknown: Unknown,
    /// Extra cost per metre through unknown space; only with `--unknown cost` [default: 2].
    #[arg(long, value_name = "C")]
    unknown_cost: Option<f32>,
    /// Weave: each step leaves the path's direction by this angle, degrees, to alternating
    /// sides, so that what lies ahead is never at the epipole of the camera's motion [default:
    /// 0, straight].
    #[arg(long, value_name = "DEG")]
    weave: Option<f64>,
    /// The vehicle steps sideways to look ahead with a sideways baseline at take-off and after
    /// every turn of the camera by more than this angle, degrees [default: 45; 0 turns it off].
    #[arg(long, value_name = "DEG")]
    look_turn: Option<f64>,
    /// The camera pitches towards the point ahead by at most this angle, degrees [default: 30;
    /// 0 keeps it level].
    #[arg(long, value_name = "DEG")]
    pitch: Option<f64>,
    /// The camera turns at most this fast, degrees per second [default: 720, no limit at the
    /// default frame rate].
    #[arg(long, value_name = "DEG_PER_S")]
    yaw_rate: Option<f64>,
    /// The unseen-surface guard's reach, metres: unknown voxels next to seen surfaces within
    /// this distance of the vehicle are never entered [default: 0, off].
    #[arg(long, value_name = "M")]
    guard: Option<f64>,
    /// Unknown voxels within the look-ahead whose occupied membership reaches this (and exceeds
    /// their free membership) are never entered: surfaces seen, though not confidently
    /// [default: 0.2; above 1 turns it off].
    #[arg(long, value_name = "MEMBERSHIP")]
    leaning: Option<f64>,
    /// Let steps into unknown space leave the camera's last picture (by default the vehicle
    /// enters unknown space only where its camera has just looked).
    #[arg(long)]
    blind_steps: bool,
    /// A flight that comes no nearer to its goal for this many seconds ends as stuck
    /// [default: 15].
    #[arg(long, value_name = "S")]
    patience: Option<f64>,
    /// Write fly.json and a top-down figure of each flight over its final map here.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Print one JSON object instead of text.
    #[arg(long)]
    json: bool,
}

pub fn run(args: FlyArgs) -> anyhow::Result<()> {
    let started = Instant::now();
    let models: Vec<MapKind> = MapKind::ALL
        .into_iter()
        .filter(|kind| args.model.iter().any(|m| m.includes(*kind)))
        .collect();
    if args.goals == 0 {
        bail!("--goals must be at least 1");
    }
    let defaults = FlyConfig::default();
    let mut config = FlyConfig {
        views: args.views as usize,
        weave_angle: args.weave.unwrap_or(defaults.weave_angle),
        max_pitch: args.pitch.unwrap_or(defaults.max_pitch),
        look_turn: args.look_turn.unwrap_or(defaults.look_turn),
        max_yaw_rate: args.yaw_rate.unwrap_or(defaults.max_yaw_rate),
        unknown_guard: args.guard.unwrap_or(defaults.unknown_guard),
        leaning_occupied: args.leaning.unwrap_or(defaults.leaning_occupied),
        blind_steps: args.blind_steps,
        patience: args.patience.unwrap_or(defaults.patience),
        ..defaults
    };
    config.planner.unknown = match (args.unknown, args.unknown_cost) {
        (Unknown::Cost, cost) => UnknownPolicy::Cost(cost.unwrap_or(2.0)),
        (Unknown::Forbid, None) => UnknownPolicy::Forbid,
        (Unknown::Forbid, Some(_)) => bail!("--unknown-cost applies only with --unknown cost"),
    };
    let config = config.validate()?;
    if let Some(out) = &args.out
        && out.exists()
        && !out.is_dir()
    {
        bail!("--out {} exists and is not a folder", out.display());
    }
    let scenario = args.scenario.build(2, args.seed)?;
    let queries = QueryConfig::closed_loop(args.goals, args.seed, config.planner);
    let goals = draw_goals(&scenario, &config, &queries)?;
    if goals.is_empty() {
        bail!(
            "no start and goal could be drawn in the {} scenario",
            scenario.name
        );
    }
    let label = format!("{} scenario", scenario.name);
    let bar = super::progress::bar((goals.len() * models.len()) as u64, &label, args.json);
    let flights = fly_all(
        &scenario,
        &goals,
        &models,
        &config,
        args.seed,
        args.out.is_some(),
        &mut |done, _| bar.set_position(done as u64),
    )?;
    bar.finish_and_clear();

    let mut report = ClosedLoopReport::new(&goals, &config, &queries, &flights);
    report.scenario = Some(scenario.name.to_string());
    report.seed = Some(args.seed);
    report.seconds = Some(started.elapsed().as_secs_f64());
    if let Some(out) = &args.out {
        std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
        let file = out.join("fly.json");
        fuzzyvox::io::write_atomic(&file, serde_json::to_string_pretty(&report)?.as_bytes())?;
        write_flight_figures(out, scenario.name, &goals, &flights, &|model, i| {
            format!("fly-{model}-{}.png", i + 1)
        })?;
    }
    if args.json {
        return super::print_json(&serde_json::to_value(&report)?);
    }
    println!(
        "{} scenario, seed {}: {} flights per map ({:.0} s)",
        scenario.name,
        args.seed,
        goals.len(),
        started.elapsed().as_secs_f64()
    );
    for model in &flights {
        let s = model.summary(&goals);
        println!(
            "  {:8} reached {:>3.0} %, collisions {}, no path {}, stuck {}, out of time {}; length / true path {}; \
             per cycle: depth {:.0} ms, integration {:.0} ms, update and replan {:.1} ms (full rebuild {:.0} ms)",
            model.model.name(),
            s.reached * 100.0,
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
    if let Some(out) = &args.out {
        println!("wrote {}", out.join("fly.json").display());
    }
    Ok(())
}
