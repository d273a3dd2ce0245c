use std::path::PathBuf;

use clap::Args;
use fuzzyvox::AnyMap;
use fuzzyvox::io::read_header;
use fuzzyvox::plan::ObservedExtent;
use serde_json::json;

/// Describe a saved map: kind, resolution, operator, voxel counts per class, extent and memory.
#[derive(Args)]
#[command(after_help = "Examples:\n  fuzzyvox info scan.fvx\n  fuzzyvox info scan.fvx --json")]
pub struct InfoArgs {
    /// A map file written by `fuzzyvox insert --out`.
    map: PathBuf,
    /// Print one JSON object instead of text.
    #[arg(long)]
    json: bool,
}

pub fn run(args: InfoArgs) -> anyhow::Result<()> {
    let loading = super::progress::spinner("loading the map", args.json);
    let header = read_header(&args.map)?;
    let map = AnyMap::load(&args.map)?;
    loading.finish_and_clear();
    let view = map.as_map();
    let counts = view.counts();
    let resolution = view.resolution();
    // The same extent the planner quotes when a start or goal lies outside it.
    let corners = ObservedExtent::of(view).map(|e| {
        let (lo, hi) = (e.min, e.max);
        ([lo.x, lo.y, lo.z], [hi.x, hi.y, hi.z])
    });
    let operator = header.operator.map(|f| f.to_string());
    if args.json {
        return super::print_json(&json!({
            "path": args.map,
            "format_version": header.version,
            "model": header.kind.name(),
            "resolution": resolution.size(),
            "operator": operator,
            "occupied": counts.occupied,
            "free": counts.free,
            "ambiguous": counts.ambiguous,
            "unknown": counts.unknown,
            "memory_bytes": view.memory_bytes(),
            "bounds_min": corners.map(|c| c.0),
            "bounds_max": corners.map(|c| c.1),
        }));
    }
    println!(
        "{}: {} map, format version {}",
        args.map.display(),
        header.kind.name(),
        header.version
    );
    match operator {
        Some(op) => println!("resolution {} m, operator {op}", resolution.size()),
        None => println!("resolution {} m", resolution.size()),
    }
    println!(
        "voxels: {} occupied, {} free, {} ambiguous, {} unknown ({:.1} MB in memory)",
        counts.occupied,
        counts.free,
        counts.ambiguous,
        counts.unknown,
        view.memory_bytes() as f64 / 1e6
    );
    if let Some((lo, hi)) = corners {
        println!(
            "observed extent: [{:.2}, {:.2}, {:.2}] to [{:.2}, {:.2}, {:.2}] m",
            lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]
        );
    }
    Ok(())
}
