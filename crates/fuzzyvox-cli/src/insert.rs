use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, bail};
use clap::Args;
use fuzzyvox::map::{MapKind, MapOptions};
use fuzzyvox::{Family, IntegrationOptions, IntegrationStats};

use super::maps::{Evidence, PriorArgs, kind_parser};

/// Scans handed to the map at once by `insert`.
const SCANS_PER_BATCH: usize = 16;
use serde_json::json;

/// Integrate point clouds into a new map and report what it holds.
///
/// Inputs: text clouds (`x y z [confidence]` per line; any extension but the three below),
/// OctoMap scan graphs (`.graph`), OctoMap text logs (`.log`, `NODE x y z roll pitch yaw`
/// then points in the sensor frame) and scan lists (`.list`, `CLOUD ox oy oz` per line: a text
/// cloud in world coordinates, relative to the list's folder, and its sensor origin). Each
/// graph or log node and each list line is one scan from its own origin.
///
/// Robot recordings (`--bag`: a ROS 1 `.bag`, an `.mcap` file or a ROS 2 bag folder): every
/// `sensor_msgs/PointCloud2` on `--topic`, carried into `--frame` by the TF tree (`/tf`,
/// `/tf_static`) at the cloud's stamp, is one scan from its sensor's origin.
#[derive(Args)]
#[command(after_help = "Examples:\n  \
    fuzzyvox insert --cloud scan.dat --res 0.1 --out scan.fvx\n  \
    fuzzyvox insert --cloud scan.dat --res 0.05 --model logodds --json\n  \
    fuzzyvox insert --cloud cloud.xyz --res 0.05 --origin 0,0,1.2 --max-range 20 --op dombi:2 --json\n  \
    fuzzyvox insert --cloud confident.xyz --res 0.1 --model alpha --cuts 10 --out alpha.fvx\n  \
    fuzzyvox insert --cloud new.xyz --res 0.08 --prior geb079.bt --prior-confidence 0.6 --out updated.fvx\n  \
    fuzzyvox insert --cloud scans.list --res 0.05 --model logodds --json\n  \
    fuzzyvox insert --bag recording.bag --topic /camera/depth/points --res 0.05 --out map.fvx\n  \
    fuzzyvox insert --bag lidar.mcap --topic /points --frame lidar --res 0.2 --json")]
#[command(group(clap::ArgGroup::new("input").required(true).args(["cloud", "bag"])))]
pub struct InsertArgs {
    /// Input scans: a text cloud, an OctoMap `.graph`, an OctoMap `.log` or a scan list
    /// (`.list`).
    #[arg(long)]
    cloud: Option<PathBuf>,
    /// A robot recording: a ROS 1 `.bag`, an `.mcap` file or a ROS 2 bag folder.
    #[arg(long, requires = "topic")]
    bag: Option<PathBuf>,
    /// The recording's `sensor_msgs/PointCloud2` topic.
    #[arg(long, requires = "bag")]
    topic: Option<String>,
    /// The map's frame in the recording's TF tree (a cloud already in it needs no transform).
    #[arg(long, default_value = "map", requires = "bag")]
    frame: String,
    /// Voxel size in metres.
    #[arg(long, allow_negative_numbers = true)]
    res: f64,
    /// Sensor origin of a text cloud as X,Y,Z (metres); scan lists give their own.
    #[arg(long, value_parser = super::parse_point, default_value = "0,0,0", allow_hyphen_values = true)]
    origin: nalgebra::Point3<f64>,
    /// Cut rays longer than this (metres); the cut part clears free space only.
    #[arg(long, allow_negative_numbers = true)]
    max_range: Option<f64>,
    /// Map model.
    #[arg(long, value_parser = kind_parser(), default_value_t = MapKind::Fuzzy)]
    model: MapKind,
    /// Aggregation t-conorm of the fuzzy model as NAME[:PARAM], e.g. product, max, lukasiewicz,
    /// dombi:2, hamacher:0.5, yager:2, frank:3, einstein, aczel-alsina:2, schweizer-sklar:-1.
    #[arg(long, default_value = "product")]
    op: String,
    /// Evidence model of the fuzzy map: `dual` weighs free space by each point's reliability
    /// (1 for every point of a cloud), `paper` by its confidence.
    #[arg(long, value_enum, default_value_t = Evidence::Dual)]
    evidence: Evidence,
    /// Number of confidence cuts of the alpha model.
    #[arg(long, default_value_t = 10)]
    cuts: u32,
    #[command(flatten)]
    prior: PriorArgs,
    /// Write the map here (native format).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Print one JSON object instead of text.
    #[arg(long)]
    json: bool,
}

pub fn run(args: InsertArgs) -> anyhow::Result<()> {
    let family: Family = args.op.parse().context("--op")?;
    if args.model != MapKind::Fuzzy && args.op != "product" {
        bail!("--op applies to the fuzzy model only");
    }
    if args.model != MapKind::Fuzzy && args.evidence != Evidence::Dual {
        bail!("--evidence applies to the fuzzy model only");
    }
    args.prior.check_models(&[args.model])?;
    let options = MapOptions {
        operator: family,
        evidence: args.evidence.model(),
        cuts: args.cuts,
    };
    let mut map = args
        .model
        .new_map_with(args.res, &options)
        .map_err(super::held_out::flag_error)?;
    let prior_voxels = args.prior.apply(&mut map)?;
    let reading = super::progress::spinner("reading the scans", args.json);
    let input = super::input::read_input(
        args.cloud.as_deref(),
        args.origin,
        args.bag.as_deref().zip(args.topic.as_deref()),
        &args.frame,
    )?;
    let (scans, source) = (input.scans, input.source);
    reading.finish_and_clear();
    tracing::info!("{} scan(s) read from {}", scans.len(), source.display());
    if args.model == MapKind::AlphaCut && scans.iter().any(|s| s.confidence().is_none()) {
        bail!(
            "the alpha model needs a confidence per point, and {} has none: give a text cloud \
             with `x y z confidence` lines (confidence in [0, 1]), or use --model logodds",
            source.display()
        );
    }
    let options = IntegrationOptions {
        max_range: args.max_range,
    };
    let started = Instant::now();
    let mut total = IntegrationStats::default();
    let bar = super::progress::bar(scans.len() as u64, "integrating", args.json);
    // Scans go to the map a batch at a time (it walks a batch's scans side by side), small
    // enough batches for the progress bar to move.
    for (batch, chunk) in scans.chunks(SCANS_PER_BATCH).enumerate() {
        let first = batch * SCANS_PER_BATCH;
        let all = map
            .as_map_mut()
            .integrate_clouds(chunk, &options)
            .with_context(|| match chunk.len() {
                1 => format!("integrating scan {first}"),
                n => format!("integrating scans {first} to {}", first + n - 1),
            })?;
        for (offset, stats) in all.iter().enumerate() {
            total.integrated += stats.integrated;
            total.skipped += stats.skipped;
            total.clipped += stats.clipped;
            total.voxels_updated += stats.voxels_updated;
            tracing::debug!(
                "scan {}: {} points, {} voxels updated",
                first + offset,
                stats.integrated,
                stats.voxels_updated
            );
        }
        bar.inc(chunk.len() as u64);
    }
    bar.finish_and_clear();
    let seconds = started.elapsed().as_secs_f64();
    let points: usize = scans.iter().map(|s| s.len()).sum();
    let view = map.as_map();
    let counts = view.counts();
    if let Some(out) = &args.out {
        tracing::info!("saving {}", out.display());
        map.save(out)
            .with_context(|| format!("saving the map to {}", out.display()))?;
    }
    let model = map.kind().name();
    let operator = (args.model == MapKind::Fuzzy).then(|| family.to_string());
    if args.json {
        return super::print_json(&json!({
            "points": points,
            "scans": scans.len(),
            "dropped_points": input.dropped_points,
            "integrated": total.integrated,
            "skipped": total.skipped,
            "clipped": total.clipped,
            "resolution": view.resolution().size(),
            "model": model,
            "operator": operator,
            "occupied": counts.occupied,
            "free": counts.free,
            "ambiguous": counts.ambiguous,
            "unknown": counts.unknown,
            "insert_seconds": seconds,
            "memory_bytes": view.memory_bytes(),
            "prior": args.prior.prior,
            "prior_voxels": prior_voxels,
            "out": args.out,
        }));
    }
    let with = operator.map(|o| format!(" with {o}")).unwrap_or_default();
    if let Some(prior) = &args.prior.prior {
        println!(
            "prior {}: {prior_voxels} voxels at confidence {}",
            prior.display(),
            args.prior.prior_confidence
        );
    }
    println!(
        "integrated {} of {points} points from {} scan(s) ({} skipped) into a {model} map at {} m{with} in {seconds:.3} s",
        total.integrated,
        scans.len(),
        total.skipped,
        view.resolution().size(),
    );
    println!(
        "voxels: {} occupied, {} free, {} ambiguous, {} unknown ({:.1} MB)",
        counts.occupied,
        counts.free,
        counts.ambiguous,
        counts.unknown,
        view.memory_bytes() as f64 / 1e6
    );
    if let Some(out) = &args.out {
        println!("saved {}", out.display());
    }
    Ok(())
}
