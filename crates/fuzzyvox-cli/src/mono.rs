use std::path::PathBuf;
use std::time::Instant;

use anyhow::Context;
use clap::Args;
use fuzzyvox::IntegrationOptions;
use fuzzyvox::depth::{DepthParams, DepthStream, PairCriteria};
use fuzzyvox::eval::{DepthStageErrors, HoldoutSplit};
use fuzzyvox::io::posed::PosedFolder;
use fuzzyvox::io::rgbd::read_pose_txt;
use serde_json::json;
use tracing::info;

use super::held_out::{MapCheckArgs, check_all, integrate_all, print_table, reports, save_all};
use super::progress;

/// Map a folder of real posed colour images with the one-camera depth stage, and check the maps
/// against the sensor depth of frames they have not seen.
///
/// The folder holds `frame-N.color.png` or `.jpg` with `frame-N.pose.txt` (row-major 4×4
/// `world_from_camera`) and `camera-intrinsics.txt`: the RGB-D layout. `color-intrinsics.txt`,
/// when present, is the colour camera's K. Poses may come from a TUM trajectory instead
/// (`--trajectory`, one pose per frame in frame order). When the poses are the depth camera's
/// (as in 7-Scenes), `--extrinsics` gives the colour camera in the depth camera's frame.
///
/// Frames stream through pair selection and the depth stage: each frame is paired with the
/// earlier frame of the best `Q_ABD` (baseline between --min-baseline and 2 m, within 2 s,
/// views within 20°); sideways pairs are rectified and matched along rows, pairs moving along
/// the view by plane sweep, with `--views N` earlier views at once. Every map integrates the
/// same interval depth images. Every K-th frame (`--holdout K`) never reaches the depth stage.
///
/// Sensor depth (`frame-N.depth.png`), when present, is never used for mapping: it measures the
/// depth stage (the median relative error of `P0` and how often the sensor's depth lies inside
/// `[P-, P+]`, over all pixels and the most confident half) and checks the maps against the
/// held-out frames (`within_2_voxels`, as `rgbd` does).
#[derive(Args)]
#[command(after_help = "Examples:\n  \
    fuzzyvox mono --dir ../shared/data/rgbd-7scenes-redkitchen --res 0.04\n  \
    fuzzyvox mono --dir ../shared/data/rgbd-7scenes-redkitchen --res 0.04 --views 3 --json\n  \
    fuzzyvox mono --dir DIR --res 0.05 --trajectory poses.tum --model fuzzy --out maps/")]
pub struct MonoArgs {
    /// The folder of posed colour frames.
    #[arg(long)]
    dir: PathBuf,
    #[command(flatten)]
    maps: MapCheckArgs,
    /// Views matched at once for each depth image (2: pairs).
    #[arg(long, default_value_t = 2, value_parser = clap::value_parser!(u32).range(2..=17))]
    views: u32,
    /// Poses from a TUM trajectory (`timestamp tx ty tz qx qy qz qw` per line, the k-th pose
    /// for the k-th frame) instead of `frame-N.pose.txt`.
    #[arg(long, value_name = "FILE")]
    trajectory: Option<PathBuf>,
    /// The colour camera's pose in the depth camera's frame (`depth_from_color`, a row-major
    /// 4×4 matrix as in `pose.txt`), when the poses are the depth camera's.
    #[arg(long, value_name = "FILE")]
    extrinsics: Option<PathBuf>,
    /// Nearest depth searched (metres).
    #[arg(long, default_value_t = 0.3, allow_negative_numbers = true)]
    near: f64,
    /// Farthest depth searched (metres); also the integration's range.
    #[arg(long, default_value_t = 8.0, allow_negative_numbers = true)]
    far: f64,
    /// Smallest baseline of a pair (metres).
    #[arg(long, default_value_t = 0.05, allow_negative_numbers = true)]
    min_baseline: f64,
    /// Save every map here as MODEL.fvx.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Print one JSON object instead of text.
    #[arg(long)]
    json: bool,
}

pub fn run(args: MonoArgs) -> anyhow::Result<()> {
    let family = args.maps.family()?;
    let check = args.maps.check()?;
    if !(args.near.is_finite() && args.near > 0.0 && args.far.is_finite() && args.far > args.near) {
        anyhow::bail!(
            "--near {} --far {}: expected 0 < near < far, both finite (metres)",
            args.near,
            args.far
        );
    }
    let extrinsics = match &args.extrinsics {
        Some(path) => Some(
            read_pose_txt(path)
                .with_context(|| format!("reading the extrinsics {}", path.display()))?,
        ),
        None => None,
    };
    let folder = PosedFolder::open(&args.dir, args.trajectory.as_deref(), extrinsics)
        .with_context(|| format!("opening the image folder {}", args.dir.display()))?;
    let holdout = args.maps.holdout;
    let split = HoldoutSplit::new(folder.frames.len(), holdout)
        .with_context(|| format!("--holdout {holdout} with {} frames", folder.frames.len()))?;
    let criteria = PairCriteria {
        min_baseline: args.min_baseline,
        ..PairCriteria::default()
    };
    let params = DepthParams {
        depth_range: Some((args.near, args.far)),
        ..DepthParams::default()
    };
    let mut stream = DepthStream::new(criteria, args.views as usize, params)
        .context("--views / --min-baseline")?;
    let mut maps = args.maps.maps(family)?;
    info!(
        "{} frames in {} ({}): {} build the maps, {} are held out",
        folder.frames.len(),
        args.dir.display(),
        folder.color_intrinsics.display(),
        split.build.len(),
        split.held_out.len()
    );

    let options = IntegrationOptions {
        max_range: Some(args.far),
    };
    let label = |position: usize| format!("frame {}", folder.frames[position].number);
    let mut stage = DepthStageErrors::default();
    let (mut read_s, mut depth_s, mut integrate_s, mut check_s) = (0.0, 0.0, 0.0, 0.0);
    let bar = progress::bar(split.build.len() as u64, "depth and mapping", args.json);
    for &position in &split.build {
        let t = Instant::now();
        let frame = folder
            .read_frame(position)
            .with_context(|| format!("reading {}", label(position)))?;
        read_s += t.elapsed().as_secs_f64();
        let t = Instant::now();
        let result = stream
            .push(frame)
            .with_context(|| format!("the depth stage on {}", label(position)))?;
        depth_s += t.elapsed().as_secs_f64();
        bar.inc(1);
        let Some(result) = result else {
            continue;
        };
        // Consecutive images that share views repeat each other's errors: weigh them so that
        // every camera position counts as much as in a stream of pairs.
        let weight = result.reuse_weight();
        let mut depth = result.frame;
        if weight < 1.0 {
            depth.scale_confidence(weight)?;
        }
        let t = Instant::now();
        if let Some(sensor) = folder.read_sensor_depth(position)? {
            stage.add(&depth, &sensor);
        }
        check_s += t.elapsed().as_secs_f64();
        let t = Instant::now();
        integrate_all(&mut maps, &depth, &options, &label(position))?;
        integrate_s += t.elapsed().as_secs_f64();
    }
    bar.finish_and_clear();
    let bar = progress::bar(split.held_out.len() as u64, "ray casting", args.json);
    let mut checked = 0;
    for &position in &split.held_out {
        let t = Instant::now();
        if let Some(sensor) = folder.read_sensor_depth(position)? {
            check_all(&mut maps, &sensor, &check, &label(position))?;
            checked += 1;
        }
        check_s += t.elapsed().as_secs_f64();
        bar.inc(1);
    }
    bar.finish_and_clear();
    if let Some(dir) = &args.out {
        save_all(&maps, dir)?;
    }

    let res = args.maps.res;
    let reports = reports(&maps, family, res);
    let counts = stream.counts();
    let skipped: serde_json::Map<String, serde_json::Value> = counts
        .skipped
        .iter()
        .map(|(reason, n)| (reason.name().to_string(), json!(n)))
        .collect();
    let summary = stage.summary();
    let mapping_s = read_s + depth_s + integrate_s;
    let frames_per_second = split.build.len() as f64 / mapping_s.max(1e-9);
    if args.json {
        return super::print_json(&json!({
            "dir": args.dir,
            "frames": folder.frames.len(),
            "build_frames": split.build.len(),
            "held_out_frames": split.held_out.len(),
            "held_out_checked": checked,
            "holdout": holdout,
            "resolution": res,
            "views": args.views,
            "depth_range": [args.near, args.far],
            "color_intrinsics": folder.color_intrinsics,
            "depth_images": counts.depth_images(),
            "rectified": counts.rectified,
            "swept": counts.swept,
            "multi_view": counts.multi_view,
            "views_dropped": stream.views_dropped(),
            "skipped": skipped,
            "depth_stage": {
                "images": summary.images,
                "pixels": summary.pixels,
                "median_rel_error": summary.median_rel_error,
                "interval_coverage": summary.interval_coverage,
                "median_confidence": summary.median_confidence,
                "pixels_top50": summary.pixels_top50,
                "median_rel_error_top50": summary.median_rel_error_top50,
                "interval_coverage_top50": summary.interval_coverage_top50,
                "seconds": depth_s,
                "share_of_mapping_time": depth_s / mapping_s.max(1e-9),
            },
            "seconds": {
                "read": read_s,
                "depth": depth_s,
                "integrate": integrate_s,
                "check": check_s,
            },
            "frames_per_second": frames_per_second,
            "maps": reports,
        }));
    }
    println!(
        "{}: {} frames; {} build the maps ({} depth images: {} rectified, {} swept, {} multi-view; \
         {} without), {} held out ({checked} with sensor depth)",
        args.dir.display(),
        folder.frames.len(),
        split.build.len(),
        counts.depth_images(),
        counts.rectified,
        counts.swept,
        counts.multi_view,
        counts.skipped.values().sum::<usize>(),
        split.held_out.len(),
    );
    for (reason, n) in &counts.skipped {
        println!("  {n} frame(s) without depth: {}", reason.name());
    }
    println!(
        "depth stage against sensor depth: {} pixels, median relative error {:.3} (most confident \
         half {:.3}), interval coverage {:.3} (most confident half {:.3})",
        summary.pixels,
        summary.median_rel_error,
        summary.median_rel_error_top50,
        summary.interval_coverage,
        summary.interval_coverage_top50
    );
    println!(
        "{frames_per_second:.2} frames/s ({:.0}% of the time in the depth stage)",
        100.0 * depth_s / mapping_s.max(1e-9)
    );
    print_table(&reports);
    Ok(())
}
