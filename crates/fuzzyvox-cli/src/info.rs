use std::path::{Path, PathBuf};

use anyhow::Context;
use clap::Args;
use fuzzyvox::bag::{Bag, BagInfo};
use fuzzyvox::io::{LoadedMap, load_map};
use fuzzyvox::plan::ObservedExtent;
use serde_json::json;

/// Describe a saved map: kind, resolution, operator, voxel counts per class, extent and memory.
///
/// Reads fuzzyvox maps and OctoMap's `.bt` and `.ot` trees, told apart by content. An OctoMap
/// tree's counts are its finest-level voxels (a pruned leaf counts every voxel it covers).
///
/// With `--bag`, describes a robot recording instead (a ROS 1 `.bag`, an `.mcap` file or a
/// ROS 2 bag folder), as `rosbag info` does: topics with their types and message counts, the
/// time span, and the frames of its TF tree.
#[derive(Args)]
#[command(after_help = "Examples:\n  \
    fuzzyvox info scan.fvx\n  \
    fuzzyvox info scan.fvx --json\n  \
    fuzzyvox info geb079.bt --json\n  \
    fuzzyvox info --bag recording.bag\n  \
    fuzzyvox info --bag rosbag2_folder --json")]
#[command(group(clap::ArgGroup::new("input").required(true).args(["map", "bag"])))]
pub struct InfoArgs {
    /// A map file: a fuzzyvox map (`insert --out`), an OctoMap `.bt` or an OctoMap `.ot`.
    map: Option<PathBuf>,
    /// A robot recording instead of a map.
    #[arg(long)]
    bag: Option<PathBuf>,
    /// Print one JSON object instead of text.
    #[arg(long)]
    json: bool,
}

pub fn run(args: InfoArgs) -> anyhow::Result<()> {
    let path = match (&args.map, &args.bag) {
        (_, Some(bag)) => return bag_info(bag, args.json),
        (Some(map), None) => map.clone(),
        (None, None) => anyhow::bail!("give a map file or --bag"),
    };
    let loading = super::progress::spinner("loading the map", args.json);
    let map = load_map(&path)?;
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
            "path": path,
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
            path.display(),
            map.model_name(),
            tree.node_count(),
            tree.leaf_count()
        ),
        (_, version) => println!(
            "{}: {} map, format version {}",
            path.display(),
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

/// `info --bag`: the recording's topics, time span and TF frames.
fn bag_info(path: &Path, json: bool) -> anyhow::Result<()> {
    let reading = super::progress::spinner("reading the recording", json);
    let info = Bag::open(path)
        .and_then(|bag| BagInfo::of(&bag))
        .with_context(|| format!("reading {}", path.display()))?;
    reading.finish_and_clear();
    if json {
        let mut value = serde_json::to_value(&info)?;
        if let Some(object) = value.as_object_mut() {
            object.insert("path".into(), json!(path));
        }
        return super::print_json(&value);
    }
    println!(
        "{}: {} recording, {} messages over {:.3} s (from {:.3} s)",
        path.display(),
        info.format,
        info.message_count,
        info.duration_s,
        info.start_ns as f64 * 1e-9
    );
    let width = info
        .topics
        .iter()
        .map(|t| t.name.len())
        .max()
        .unwrap_or(5)
        .max(5);
    println!("{:<width$}  {:>8}  type", "topic", "messages");
    for t in &info.topics {
        println!("{:<width$}  {:>8}  {}", t.name, t.count, t.msg_type);
    }
    if info.tf.is_empty() {
        println!("no TF transforms (/tf, /tf_static)");
    } else {
        println!("TF tree ({} edges):", info.tf.len());
        for e in &info.tf {
            let kind = if e.is_static { "static" } else { "dynamic" };
            println!(
                "  {} -> {}  {kind}, {} transform(s), {:.3} to {:.3} s",
                e.parent, e.child, e.samples, e.first, e.last
            );
        }
    }
    if info.tf_invalid > 0 {
        println!(
            "{} TF transform(s) skipped: not a rigid transform",
            info.tf_invalid
        );
    }
    Ok(())
}
