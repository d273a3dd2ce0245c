use std::path::PathBuf;
use std::time::Instant;

use clap::{Args, ValueEnum};
use fuzzyvox::VoxelClass;
use fuzzyvox::io::load_map;
use fuzzyvox::plan::{Blocker, PlanError, PlannerConfig, UnknownPolicy, plan_path};
use serde_json::json;

/// Plan a safe flight through a saved map with A*.
///
/// The path keeps the vehicle radius from every voxel that is occupied, ambiguous, not safe
/// enough or (unless `--unknown cost`) unknown, and prefers safe, open space.
#[derive(Args)]
#[command(after_help = "Examples:\n  \
    fuzzyvox insert --cloud scan.dat --res 0.1 --out scan.fvx          # OctoMap's laser scan\n  \
    fuzzyvox plan --map scan.fvx --from 3,0,0.5 --to 7,-11,0.5         # 11.8 m, bending once in free space\n  \
    fuzzyvox plan --map scan.fvx --from 3,0,0.5 --to 12,8,0.5 --radius 0.4 --unknown cost --json  # into unknown space, at a cost\n\n\
    A start or goal the planner refuses is reported with what blocks it (unknown, occupied, \
    ambiguous, low safety, too close to a blocked voxel, or outside the map's observed extent) \
    and a hint with the option that would change it.")]
pub struct PlanArgs {
    /// A map file: a fuzzyvox map (`insert --out`), an OctoMap `.bt` or an OctoMap `.ot`.
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
    let map = load_map(&args.map)?;
    tracing::info!(
        "{} map at {} m loaded from {}",
        map.model_name(),
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
    let result = plan_path(map.as_map(), &args.from, &args.to, &config);
    let seconds = started.elapsed().as_secs_f64();
    spinner.finish_and_clear();
    let path = match result {
        Ok(path) => path,
        Err(error) => {
            let hint = hint(&error, &config);
            if args.json {
                // A script gets the reason on standard output too, next to the exit status.
                super::print_json(&json!({
                    "map": args.map,
                    "model": map.model_name(),
                    "error": error.to_string(),
                    "failure": failure_name(&error),
                    "reason": error.blocker(),
                    "hint": hint,
                    "plan_seconds": seconds,
                }))?;
            }
            return Err(match hint {
                Some(hint) => anyhow::anyhow!("{error}\n  hint: try {hint}"),
                None => error.into(),
            });
        }
    };
    if args.json {
        let waypoints: Vec<[f64; 3]> = path.waypoints.iter().map(|p| [p.x, p.y, p.z]).collect();
        return super::print_json(&json!({
            "map": args.map,
            "model": map.model_name(),
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

/// A stable name for the kind of failure, for JSON output.
fn failure_name(error: &PlanError) -> &'static str {
    match error {
        PlanError::OutOfRegion(_) => "out_of_region",
        PlanError::StartUnsafe(_) => "start_unsafe",
        PlanError::GoalUnsafe(_) => "goal_unsafe",
        PlanError::GoalAvoided => "goal_avoided",
        PlanError::Disconnected { .. } => "disconnected",
        PlanError::Map(_) => "invalid_request",
    }
}

/// Which command-line options would change a failed plan, if any (printed after `hint: try`):
/// the library says what blocks the start or goal and which setting would help, this names
/// the flag and its value.
fn hint(error: &PlanError, config: &PlannerConfig) -> Option<String> {
    let unknown_forbidden = config.unknown == UnknownPolicy::Forbid;
    let (flag, blocker) = match error {
        PlanError::StartUnsafe(why) => ("--from", why),
        PlanError::GoalUnsafe(why) => ("--to", why),
        PlanError::Disconnected { .. } => {
            let mut hint = String::from("a smaller `--radius` (fits through narrower gaps)");
            if unknown_forbidden {
                hint.push_str(", or `--unknown cost` (lets the path cross unknown space)");
            }
            return Some(hint);
        }
        _ => return None,
    };
    Some(match blocker {
        Blocker::OutsideObservedExtent { .. } => {
            format!("a {flag} inside that extent, or `--unknown cost`")
        }
        Blocker::Unknown => "`--unknown cost`".into(),
        Blocker::Occupied { .. } | Blocker::Ambiguous { .. } => {
            format!("another {flag}: no option lets the planner enter such a voxel")
        }
        Blocker::LowSafety { .. } => format!(
            "`--safety {:.2}` or lower",
            blocker.safety_to_accept().unwrap_or(0.0)
        ),
        Blocker::TooClose { nearest, .. } => {
            let mut options = Vec::new();
            if let Some(radius) = blocker.radius_to_fit() {
                options.push(format!("`--radius {radius:.2}` or smaller"));
            }
            if nearest.is_some_and(|n| n.class == VoxelClass::Unknown) && unknown_forbidden {
                options.push("`--unknown cost` (the blocked voxel is unknown)".into());
            }
            if let Some(safety) = blocker.safety_to_accept() {
                options.push(format!(
                    "`--safety {safety:.2}` or lower (the blocked voxel is free but not safe enough)"
                ));
            }
            options.push(format!("a {flag} farther from the blocked voxel"));
            options.join(", or ")
        }
        _ => return None,
    })
}
