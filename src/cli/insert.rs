use std::path::PathBuf;
use std::time::Instant;

use anyhow::Context;
use clap::{Args, ValueEnum};
use fuzzyvox::io::read_text_cloud;
use fuzzyvox::{Family, FuzzyConfig, FuzzyMap, IntegrationOptions, TConorm, VoxelMap};
use serde_json::json;

/// Integrate a point cloud into a new map and report what it holds.
///
/// The cloud is a text file with one `x y z [confidence]` per line (metres, world frame,
/// confidence in [0, 1]).
#[derive(Args)]
#[command(after_help = "Examples:\n  \
    fuzzyvox insert --cloud scan.dat --res 0.1 --out scan.fvx\n  \
    fuzzyvox insert --cloud cloud.xyz --res 0.05 --origin 0,0,1.2 --max-range 20 --op dombi:2 --json")]
pub struct InsertArgs {
    /// Text point cloud (`x y z [confidence]` per line).
    #[arg(long)]
    cloud: PathBuf,
    /// Voxel size in metres.
    #[arg(long)]
    res: f64,
    /// Sensor origin as X,Y,Z (metres).
    #[arg(long, value_parser = super::parse_point, default_value = "0,0,0", allow_hyphen_values = true)]
    origin: nalgebra::Point3<f64>,
    /// Cut rays longer than this (metres); the cut part clears free space only.
    #[arg(long)]
    max_range: Option<f64>,
    /// Map model.
    #[arg(long, value_enum, default_value_t = Model::Fuzzy)]
    model: Model,
    /// Aggregation t-conorm as NAME[:PARAM], e.g. product, max, lukasiewicz, dombi:2,
    /// hamacher:0.5, yager:2, frank:3, einstein, aczel-alsina:2, schweizer-sklar:-1.
    #[arg(long, default_value = "product")]
    op: String,
    /// Write the map here (native format).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Print one JSON object instead of text.
    #[arg(long)]
    json: bool,
}

#[derive(Clone, Copy, ValueEnum)]
enum Model {
    /// The dual-set fuzzy map.
    Fuzzy,
}

pub fn run(args: InsertArgs) -> anyhow::Result<()> {
    let family: Family = args.op.parse().context("--op")?;
    let config = FuzzyConfig::new(args.res)
        .context("--res")?
        .with_operator(TConorm::new(family)?);
    let cloud = read_text_cloud(&args.cloud, args.origin)
        .with_context(|| format!("reading the cloud {}", args.cloud.display()))?;
    let mut map = FuzzyMap::new(config)?;
    let options = IntegrationOptions {
        max_range: args.max_range,
    };
    let started = Instant::now();
    let stats = map
        .integrate_cloud(&cloud, &options)
        .context("integrating the cloud")?;
    let seconds = started.elapsed().as_secs_f64();
    let counts = map.counts();
    if let Some(out) = &args.out {
        map.save(out)
            .with_context(|| format!("saving the map to {}", out.display()))?;
    }
    let model = match args.model {
        Model::Fuzzy => "fuzzy",
    };
    if args.json {
        return super::print_json(&json!({
            "points": cloud.len(),
            "integrated": stats.integrated,
            "skipped": stats.skipped,
            "resolution": map.resolution().size(),
            "model": model,
            "operator": family.to_string(),
            "occupied": counts.occupied,
            "free": counts.free,
            "ambiguous": counts.ambiguous,
            "unknown": counts.unknown,
            "blocks": map.grid().block_count(),
            "insert_seconds": seconds,
            "memory_bytes": map.memory_bytes(),
            "out": args.out,
        }));
    }
    println!(
        "integrated {} of {} points ({} skipped) into a {model} map at {} m with {family} in {:.3} s",
        stats.integrated,
        cloud.len(),
        stats.skipped,
        map.resolution().size(),
        seconds
    );
    println!(
        "voxels: {} occupied, {} free, {} ambiguous, {} unknown in {} blocks ({:.1} MB)",
        counts.occupied,
        counts.free,
        counts.ambiguous,
        counts.unknown,
        map.grid().block_count(),
        map.memory_bytes() as f64 / 1e6
    );
    if let Some(out) = &args.out {
        println!("saved {}", out.display());
    }
    Ok(())
}
