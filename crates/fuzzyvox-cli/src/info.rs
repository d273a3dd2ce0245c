use std::path::PathBuf;

use clap::Args;
use fuzzyvox::io::{LoadedMap, load_map};
use fuzzyvox::plan::ObservedExtent;
use serde_json::json;

/// Describe a saved map: kind, resolution, operator, voxel counts per class, extent and memory.
///
/// Reads fuzzyvox maps and OctoMap's `.bt` and `.ot` trees, told apart by content. An OctoMap
/// tree's counts are its finest-level voxels (a pruned leaf counts every voxel it covers).
#[derive(Args)]
#[command(after_help = "Examples:\n  \
    fuzzyvox info scan.fvx\n  \
    fuzzyvox info scan.fvx --json\n  \
    fuzzyvox info geb079.bt --json")]
pub struct InfoArgs {
    /// A map file: a fuzzyvox map (`insert --out`), an OctoMap `.bt` or an OctoMap `.ot`.
    map: PathBuf,
    /// Print one JSON object instead of text.
    #[arg(long)]
    json: bool,
}

pub fn run(args: InfoArgs) -> anyhow::Result<()> {
    let loading = super::progress::spinner("loading the map", args.json);
    let map = load_map(&args.map)?;
    loading.finish_and_clear();
    let view = map.as_map();
    let counts = view.counts();
    let resolution = view.resolution();
    // The same extent the planner quotes when a start or goal lies outside it.
    let corners = ObservedExtent::of(view).map(|e| {
        let (lo, hi) = (e.min, e.max);
        ([lo.x, lo.y, lo.z], [hi.x, hi.y, hi.z])
    });
    let (version, operator) = match &map {
        LoadedMap::Native { header, .. } => {
            (Some(header.version), header.operator.map(|f| f.to_string()))
        }
        LoadedMap::OctoMap(_) => (None, None),
    };
    let tree = match &map {
        LoadedMap::OctoMap(tree) => Some(json!({
            "nodes": tree.node_count(),
            "leaves": tree.leaf_count(),
        })),
        LoadedMap::Native { .. } => None,
    };
    if args.json {
        return super::print_json(&json!({
            "path": args.map,
            "format_version": version,
            "model": map.model_name(),
            "resolution": resolution.size(),
            "operator": operator,
            "occupied": counts.occupied,
            "free": counts.free,
            "ambiguous": counts.ambiguous,
            "unknown": counts.unknown,
            "memory_bytes": view.memory_bytes(),
            "bounds_min": corners.map(|c| c.0),
            "bounds_max": corners.map(|c| c.1),
            "octree": tree,
        }));
    }
    match (&map, version) {
        (LoadedMap::OctoMap(tree), _) => println!(
            "{}: OctoMap tree ({}), {} nodes, {} leaves",
            args.map.display(),
            map.model_name(),
            tree.node_count(),
            tree.leaf_count()
        ),
        (_, version) => println!(
            "{}: {} map, format version {}",
            args.map.display(),
            map.model_name(),
            version.unwrap_or_default()
        ),
    }
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
