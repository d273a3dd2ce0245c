use std::path::PathBuf;

use clap::Args;
use fuzzyvox::io::{MapKind, read_header};
use fuzzyvox::{FuzzyMap, VoxelMap};
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
    let header = read_header(&args.map)?;
    let map = match header.kind {
        MapKind::Fuzzy => FuzzyMap::load(&args.map)?,
        other => anyhow::bail!(
            "{}: {} maps are not supported by this build",
            args.map.display(),
            other.name()
        ),
    };
    let counts = map.counts();
    let resolution = map.resolution();
    let (lo, hi) = map
        .grid()
        .blocks()
        .map(|(k, _)| k)
        .fold(
            None,
            |acc: Option<(fuzzyvox::BlockKey, fuzzyvox::BlockKey)>, k| {
                Some(match acc {
                    None => (k, k),
                    Some((lo, hi)) => (
                        fuzzyvox::BlockKey::new(lo.x.min(k.x), lo.y.min(k.y), lo.z.min(k.z)),
                        fuzzyvox::BlockKey::new(hi.x.max(k.x), hi.y.max(k.y), hi.z.max(k.z)),
                    ),
                })
            },
        )
        .map(|(lo, hi)| {
            let side = 8.0 * resolution.size();
            let corner = |k: fuzzyvox::BlockKey, extra: i32| {
                [
                    f64::from(k.x + extra) * side,
                    f64::from(k.y + extra) * side,
                    f64::from(k.z + extra) * side,
                ]
            };
            (Some(corner(lo, 0)), Some(corner(hi, 1)))
        })
        .unwrap_or((None, None));
    let operator = map.operator().family().to_string();
    if args.json {
        return super::print_json(&json!({
            "path": args.map,
            "format_version": header.version,
            "model": header.kind.name(),
            "resolution": resolution.size(),
            "operator": operator,
            "blocks": map.grid().block_count(),
            "occupied": counts.occupied,
            "free": counts.free,
            "ambiguous": counts.ambiguous,
            "unknown": counts.unknown,
            "memory_bytes": map.memory_bytes(),
            "bounds_min": lo,
            "bounds_max": hi,
        }));
    }
    let path = args.map.display();
    println!(
        "{path}: {} map, format version {}",
        header.kind.name(),
        header.version
    );
    println!("resolution {} m, operator {operator}", resolution.size());
    println!(
        "voxels: {} occupied, {} free, {} ambiguous, {} unknown in {} blocks ({:.1} MB in memory)",
        counts.occupied,
        counts.free,
        counts.ambiguous,
        counts.unknown,
        map.grid().block_count(),
        map.memory_bytes() as f64 / 1e6
    );
    if let (Some(lo), Some(hi)) = (lo, hi) {
        println!(
            "extent (block bounds): [{:.2}, {:.2}, {:.2}] to [{:.2}, {:.2}, {:.2}] m",
            lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]
        );
    }
    Ok(())
}
