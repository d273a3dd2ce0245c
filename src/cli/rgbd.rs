use std::path::PathBuf;
use std::time::{Duration, Instant};

use anyhow::{Context, bail};
use clap::{Args, ValueEnum};
use fuzzyvox::eval::{DepthCheckConfig, DepthErrors, HoldoutSplit};
use fuzzyvox::io::rgbd::RgbdFolder;
use fuzzyvox::{AnyMap, Family, IntegrationOptions};
use serde_json::json;
use tracing::{debug, info};

use super::maps::{Evidence, Model, PriorArgs, new_map};
use super::progress;

/// Map a folder of real RGB-D frames and check each map against frames it has not seen.
///
/// The folder holds `frame-N.depth.png` (16-bit millimetres, 0 = no reading), `frame-N.pose.txt`
/// (row-major 4×4 `world_from_camera`) and `camera-intrinsics.txt` (3×3 K): the 7-Scenes /
/// 3DMatch layout. Each pixel's depth interval is ±2σ of the Kinect's axial noise, σ(z) =
/// 0.0012 + 0.0019 (z - 0.4)² m (Nguyen, Izadi and Lovell, 2012).
///
/// Every map is built from all frames but every K-th (`--holdout K`); then a ray is cast through
/// the map for each pixel of each held-out frame, and the depth of the first occupied voxel is
/// compared with the measured depth. Reported per map: the median absolute depth error over the
/// pixels the map predicts, and `within_2_voxels`, the fraction of all pixels with a measured
/// depth whose prediction lies within two voxels (a pixel the map predicts nothing for is a
/// miss).
#[derive(Args)]
#[command(after_help = "Examples:\n  \
    fuzzyvox rgbd --dir ../shared/data/rgbd-7scenes-redkitchen --res 0.02\n  \
    fuzzyvox rgbd --dir ../shared/data/rgbd-7scenes-redkitchen --res 0.02 --holdout 5 --json\n  \
    fuzzyvox rgbd --dir DIR --res 0.05 --model fuzzy,logodds --pixel-step 4 --save maps/ -v\n  \
    fuzzyvox rgbd --dir DIR --res 0.05 --model fuzzy --op dombi:2")]
pub struct RgbdArgs {
    /// The RGB-D folder.
    #[arg(long)]
    dir: PathBuf,
    /// Voxel size in metres.
    #[arg(long, allow_negative_numbers = true)]
    res: f64,
    /// Which maps to build and check, comma-separated, or all three.
    #[arg(long, value_enum, value_delimiter = ',', default_value = "all")]
    model: Vec<Choice>,
    /// Hold out every K-th frame (the K-th, 2K-th, ...); the others build the maps.
    #[arg(long, default_value_t = 5)]
    holdout: usize,
    /// Check every N-th pixel in both directions of the held-out frames (1: every pixel).
    #[arg(long, default_value_t = 1)]
    pixel_step: u32,
    /// Cast rays this far (metres); pixels measured farther are not checked.
    #[arg(long, default_value_t = 8.0, allow_negative_numbers = true)]
    cast_range: f64,
    /// Let ambiguous voxels stop rays too (by default only occupied voxels do; log-odds maps
    /// have no ambiguous voxels).
    #[arg(long)]
    stop_at_ambiguous: bool,
    /// Aggregation t-conorm of the fuzzy model as NAME[:PARAM] (see `insert --help`).
    #[arg(long, default_value = "product")]
    op: String,
    /// Number of confidence cuts of the alpha model.
    #[arg(long, default_value_t = 10)]
    cuts: u32,
    #[command(flatten)]
    prior: PriorArgs,
    /// Save every map here as MODEL.fvx.
    #[arg(long)]
    save: Option<PathBuf>,
    /// Print one JSON object instead of text.
    #[arg(long)]
    json: bool,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum Choice {
    Fuzzy,
    Logodds,
    Alpha,
    All,
}

/// One map under test.
struct Entry {
    model: Model,
    map: AnyMap,
    build: Duration,
    predict: Duration,
    errors: DepthErrors,
}

pub fn run(args: RgbdArgs) -> anyhow::Result<()> {
    let family: Family = args.op.parse().context("--op")?;
    // The order of reports is fixed (log-odds, alpha, fuzzy), whatever the order asked for.
    let models: Vec<Model> = Model::ALL
        .into_iter()
        .filter(|m| {
            args.model.iter().any(|c| match c {
                Choice::Fuzzy => *m == Model::Fuzzy,
                Choice::Logodds => *m == Model::Logodds,
                Choice::Alpha => *m == Model::Alpha,
                Choice::All => true,
            })
        })
        .collect();
    if !models.contains(&Model::Fuzzy) && args.op != "product" {
        bail!("--op applies to the fuzzy model only");
    }
    args.prior.check_models(&models)?;
    let check = DepthCheckConfig {
        pixel_step: args.pixel_step,
        max_range: args.cast_range,
        stop_at_ambiguous: args.stop_at_ambiguous,
    }
    .validate()
    .context("--pixel-step / --cast-range")?;
    let folder = RgbdFolder::open(&args.dir)
        .with_context(|| format!("opening the RGB-D folder {}", args.dir.display()))?;
    let split = HoldoutSplit::new(folder.frames.len(), args.holdout).with_context(|| {
        format!(
            "--holdout {} with {} frames",
            args.holdout,
            folder.frames.len()
        )
    })?;
    info!(
        "{} frames in {}: {} build the maps, {} are held out",
        folder.frames.len(),
        args.dir.display(),
        split.build.len(),
        split.held_out.len()
    );
    let mut entries: Vec<Entry> = models
        .iter()
        .map(|&model| {
            let mut map = new_map(model, args.res, family, Evidence::Dual, args.cuts)?;
            args.prior.apply(&mut map)?;
            Ok(Entry {
                model,
                map,
                build: Duration::ZERO,
                predict: Duration::ZERO,
                errors: DepthErrors::default(),
            })
        })
        .collect::<anyhow::Result<_>>()?;

    // Each frame is read once and fed to every map, so memory holds one frame at a time.
    let read = |position: usize| {
        let files = &folder.frames[position];
        folder
            .read_kinect_frame(position)
            .with_context(|| format!("reading frame {}", files.depth.display()))
    };
    let options = IntegrationOptions::default();
    let bar = progress::bar(split.build.len() as u64, "integrating", args.json);
    for &position in &split.build {
        let frame = read(position)?;
        for entry in &mut entries {
            let started = Instant::now();
            let stats = entry
                .map
                .as_map_mut()
                .integrate_depth(&frame, &options)
                .with_context(|| format!("integrating frame {}", folder.frames[position].number))?;
            entry.build += started.elapsed();
            debug!(
                "frame {} into the {} map: {} pixels, {} voxels updated",
                folder.frames[position].number,
                entry.map.kind().name(),
                stats.integrated,
                stats.voxels_updated
            );
        }
        bar.inc(1);
    }
    bar.finish_and_clear();
    let bar = progress::bar(split.held_out.len() as u64, "ray casting", args.json);
    for &position in &split.held_out {
        let frame = read(position)?;
        for entry in &mut entries {
            let started = Instant::now();
            entry
                .errors
                .add_frame(entry.map.as_map(), &frame, &check)
                .with_context(|| format!("checking frame {}", folder.frames[position].number))?;
            entry.predict += started.elapsed();
        }
        bar.inc(1);
    }
    bar.finish_and_clear();

    if let Some(dir) = &args.save {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
        for entry in &entries {
            let path = dir.join(format!("{}.fvx", entry.map.kind().name()));
            entry
                .map
                .save(&path)
                .with_context(|| format!("saving {}", path.display()))?;
            info!("saved {}", path.display());
        }
    }

    let reports: Vec<serde_json::Value> = entries
        .iter()
        .map(|entry| {
            let view = entry.map.as_map();
            let counts = view.counts();
            let summary = entry.errors.summary(args.res);
            json!({
                "model": entry.map.kind().name(),
                "operator": (entry.model == Model::Fuzzy).then(|| family.to_string()),
                "build_seconds": entry.build.as_secs_f64(),
                "predict_seconds": entry.predict.as_secs_f64(),
                "occupied": counts.occupied,
                "free": counts.free,
                "ambiguous": counts.ambiguous,
                "unknown": counts.unknown,
                "memory_bytes": view.memory_bytes(),
                "valid_pixels": summary.valid_pixels,
                "predicted_pixels": summary.predicted_pixels,
                "predicted": summary.predicted,
                "median_abs_depth_error_m": summary.median_abs_depth_error_m,
                "median_depth_error_m": summary.median_depth_error_m,
                "within_2_voxels": summary.within_2_voxels,
                "too_near": summary.too_near,
                "too_far": summary.too_far,
            })
        })
        .collect();
    if args.json {
        return super::print_json(&json!({
            "dir": args.dir,
            "frames": folder.frames.len(),
            "build_frames": split.build.len(),
            "held_out_frames": split.held_out.len(),
            "holdout": args.holdout,
            "resolution": args.res,
            "pixel_step": args.pixel_step,
            "cast_range": args.cast_range,
            "stop_at_ambiguous": args.stop_at_ambiguous,
            "maps": reports,
        }));
    }
    println!(
        "{}: {} frames, maps from {} at {} m, checked on {} held-out frames (every {}th)",
        args.dir.display(),
        folder.frames.len(),
        split.build.len(),
        args.res,
        split.held_out.len(),
        args.holdout
    );
    println!(
        "{:<8} {:>8} {:>10} {:>10} {:>15} {:>10} {:>9} {:>9} {:>9}",
        "model",
        "build s",
        "predict s",
        "predicted",
        "median error m",
        "within 2v",
        "too near",
        "too far",
        "occupied"
    );
    for r in &reports {
        println!(
            "{:<8} {:>8.2} {:>10.2} {:>10.3} {:>15.4} {:>10.3} {:>9.3} {:>9.3} {:>9}",
            r["model"].as_str().unwrap_or("?"),
            r["build_seconds"].as_f64().unwrap_or(f64::NAN),
            r["predict_seconds"].as_f64().unwrap_or(f64::NAN),
            r["predicted"].as_f64().unwrap_or(f64::NAN),
            r["median_abs_depth_error_m"].as_f64().unwrap_or(f64::NAN),
            r["within_2_voxels"].as_f64().unwrap_or(f64::NAN),
            r["too_near"].as_f64().unwrap_or(f64::NAN),
            r["too_far"].as_f64().unwrap_or(f64::NAN),
            r["occupied"].as_u64().unwrap_or(0),
        );
    }
    Ok(())
}
