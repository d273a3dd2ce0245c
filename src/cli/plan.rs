use std::path::PathBuf;
use std::time::Instant;

use clap::{Args, ValueEnum};
use fuzzyvox::AnyMap;
use fuzzyvox::plan::{PlannerConfig, UnknownPolicy, plan_path};
use serde_json::json;

/// Plan a safe flight through a saved map with A*.
///
/// The path keeps the vehicle radius from every voxel that is occupied, ambiguous, not safe
/// enough or (unless `--unknown cost`) unknown, and prefers safe, open space.
#[derive(Args)]
#[command(after_help = "Examples:\n  \
    fuzzyvox plan --map scan.fvx --from 1,0,0.5 --to 6,3,0.5\n  \
    fuzzyvox plan --map scan.fvx --from 1,0,0.5 --to 6,3,0.5 --radius 0.4 --unknown cost --json")]
pub struct PlanArgs {
    /// A map file written by `fuzzyvox insert --out`.
    #[arg(long)]
    map: PathBuf,
    /// Start as X,Y,Z (metres).
    #[arg(long, value_parser = super::parse_point, allow_hyphen_values = true)]
    from: nalgebra::Point3<f64>,
    /// Goal as X,Y,Z (metres).
    #[arg(long, value_parser = super::parse_point, allow_hyphen_values = true)]
    to: nalgebra::Point3<f64>,
    /// Vehicle radius in metres.
    #[arg(long, default_value_t = 0.3, allow_negative_numbers = true)]
    radius: f64,
    /// Unknown space: forbidden, or allowed at a cost.
    #[arg(long, value_enum, default_value_t = Unknown::Forbid)]
    unknown: Unknown,
    /// Extra cost per metre through unknown space; only with `--unknown cost` [default: 5].
    #[arg(long, value_name = "C", allow_negative_numbers = true)]
    unknown_cost: Option<f32>,
    /// Lowest safety a voxel may have to be entered.
    #[arg(long, default_value_t = 0.2, allow_negative_numbers = true)]
    safety: f32,
    /// Print one JSON object instead of text.
    #[arg(long)]
    json: bool,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Unknown {
    /// Never enter unknown space.
    Forbid,
    /// Enter unknown space at `--unknown-cost` per metre.
    Cost,
}

/// Extra cost per metre through unknown space when `--unknown cost` comes without
/// `--unknown-cost`.
pub const DEFAULT_UNKNOWN_COST: f32 = 5.0;

impl Unknown {
    /// The planner's policy from `--unknown` and `--unknown-cost`. A cost given while unknown
    /// space is forbidden is a usage error rather than silently ignored: whoever typed it
    /// expected the planner to enter unknown space.
    pub fn policy(self, cost: Option<f32>) -> Result<UnknownPolicy, clap::Error> {
        match (self, cost) {
            (Self::Forbid, None) => Ok(UnknownPolicy::Forbid),
            (Self::Forbid, Some(_)) => Err(clap::Error::raw(
                clap::error::ErrorKind::ArgumentConflict,
                "--unknown-cost only applies with `--unknown cost` (unknown space is forbidden \
                 by default); add `--unknown cost` or drop `--unknown-cost`\n",
            )),
            (Self::Cost, cost) => Ok(UnknownPolicy::Cost(cost.unwrap_or(DEFAULT_UNKNOWN_COST))),
        }
    }
}

pub fn run(args: PlanArgs) -> anyhow::Result<()> {
    let unknown = args
        .unknown
        .policy(args.unknown_cost)
        .unwrap_or_else(|e| e.exit());
    let spinner = super::progress::spinner("loading the map", args.json);
    let map = AnyMap::load(&args.map)?;
    tracing::info!(
        "{} map at {} m loaded from {}",
        map.kind().name(),
        map.as_map().resolution().size(),
        args.map.display()
    );
    spinner.set_message("planning");
    let config = PlannerConfig {
        vehicle_radius: args.radius,
        safety_threshold: args.safety,
        unknown,
        ..PlannerConfig::default()
    };
    let started = Instant::now();
    let path = plan_path(map.as_map(), &args.from, &args.to, &config)?;
    let seconds = started.elapsed().as_secs_f64();
    spinner.finish_and_clear();
    if args.json {
        let waypoints: Vec<[f64; 3]> = path.waypoints.iter().map(|p| [p.x, p.y, p.z]).collect();
        return super::print_json(&json!({
            "map": args.map,
            "model": map.kind().name(),
            "waypoints": waypoints,
            "length_m": path.length,
            "cost": path.cost,
            "min_safety": path.min_safety,
            "min_clearance_m": path.min_clearance,
            "expanded": path.expanded,
            "plan_seconds": seconds,
        }));
    }
    println!(
        "path of {:.2} m through {} waypoints (min safety {:.2}, min clearance {:.2} m; {} voxels expanded in {:.3} s):",
        path.length,
        path.waypoints.len(),
        path.min_safety,
        path.min_clearance,
        path.expanded,
        seconds
    );
    for p in &path.waypoints {
        println!("  {:.2}, {:.2}, {:.2}", p.x, p.y, p.z);
    }
    Ok(())
}
