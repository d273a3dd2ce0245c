use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use clap::Args;
use fuzzyvox::io::{LoadedMap, load_map};
use fuzzyvox::{AnyMap, FuzzyMap, VoxelMap};
use serde_json::json;

/// Merge saved fuzzy maps into one: every voxel's memberships are combined with the maps'
/// t-conorm, as if every map's observations had been integrated into one map.
///
/// The maps must share their resolution and operator. Log-odds and alpha-cut maps are refused:
/// they clamp their cells, so a merge of them would depend on the order. The output is written
/// atomically; nothing is written when a map cannot be read or merged.
#[derive(Args)]
#[command(after_help = "Examples:\n  \
    fuzzyvox merge part-1.fvx part-2.fvx part-3.fvx --out whole.fvx\n  \
    fuzzyvox merge drone-a.fvx drone-b.fvx --out fleet.fvx --json")]
pub struct MergeArgs {
    /// Fuzzy map files (`insert --out`), at least one.
    #[arg(required = true)]
    maps: Vec<PathBuf>,
    /// Where to write the merged map.
    #[arg(long)]
    out: PathBuf,
    /// Print one JSON object instead of text.
    #[arg(long)]
    json: bool,
}

fn load_fuzzy(path: &Path) -> anyhow::Result<FuzzyMap> {
    let loaded = load_map(path).with_context(|| format!("reading {}", path.display()))?;
    match loaded {
        LoadedMap::Native {
            map: AnyMap::Fuzzy(map),
            ..
        } => Ok(map),
        LoadedMap::Native { map, .. } => bail!(
            "{} is a {} map: only fuzzy maps merge (log-odds and alpha-cut cells are clamped, \
             so merging them would depend on the order)",
            path.display(),
            map.kind().name()
        ),
        LoadedMap::OctoMap(_) => bail!(
            "{} is an OctoMap tree: only fuzzy maps merge (start a fuzzy map from a tree with \
             `insert --prior`)",
            path.display()
        ),
    }
}

pub fn run(args: MergeArgs) -> anyhow::Result<()> {
    let loading = super::progress::spinner("merging the maps", args.json);
    let mut paths = args.maps.iter();
    let first = paths.next().context("no map to merge")?;
    let mut merged = load_fuzzy(first)?;
    for path in paths {
        let map = load_fuzzy(path)?;
        merged
            .merge(&map)
            .with_context(|| format!("merging {} into {}", path.display(), first.display()))?;
    }
    merged
        .save(&args.out)
        .with_context(|| format!("writing {}", args.out.display()))?;
    loading.finish_and_clear();
    let counts = VoxelMap::counts(&merged);
    if args.json {
        return super::print_json(&json!({
            "out": args.out,
            "maps": args.maps.len(),
            "resolution": merged.resolution().size(),
            "operator": merged.operator().to_string(),
            "occupied": counts.occupied,
            "free": counts.free,
            "ambiguous": counts.ambiguous,
            "unknown": counts.unknown,
        }));
    }
    println!(
        "merged {} maps into {}: {} occupied, {} free, {} ambiguous voxels",
        args.maps.len(),
        args.out.display(),
        counts.occupied,
        counts.free,
        counts.ambiguous
    );
    Ok(())
}
