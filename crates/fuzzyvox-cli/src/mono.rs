use std::path::PathBuf;

use anyhow::Context;
use clap::Args;
use fuzzyvox::bag::{Bag, BagFrames};
use fuzzyvox::depth::ConsistencyParams;
use fuzzyvox::eval::{
    HeldOutConfig, MapCheckReport, MonoConfig, RealFlightConfig, run_mono_on, write_held_out_maps,
};
use fuzzyvox::io::posed::{PosedFolder, PosedFrames};
use fuzzyvox::io::rgbd::read_pose_txt;
use tracing::info;

use super::held_out::{MapCheckArgs, StageBars, flag_error, print_table};

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
/// the view by plane sweep, with `--views N` earlier views at once. Each depth image is then
/// checked against its neighbours in the stream (`--consistency N` on each side): a pixel's
/// depth, carried into a neighbouring image, must land on that image's own depth (within 3%)
/// in at least `--min-agreeing K` of them, or it is dropped; kept pixels take the mean of the
/// agreeing depths, an interval of at least ±5%, and a confidence scaled by the share of
/// neighbours that agree rather than see through. Every map integrates the same checked
/// images. Every K-th frame (`--holdout K`) never reaches the depth stage.
///
/// Sensor depth (`frame-N.depth.png`), when present, is never used for mapping: it measures the
/// depth stage (the median relative error of `P0` and how often the sensor's depth lies inside
/// `[P-, P+]`, over all pixels and the most confident half) and checks the maps against the
/// held-out frames (`within_2_voxels`, as `rgbd` does).
///
/// A robot recording works too (`--bag`: a ROS 1 `.bag`, an `.mcap` file or a ROS 2 bag
/// folder): the colour images of `--image-topic` (`sensor_msgs/CompressedImage` or `Image`), the
/// intrinsics of the `sensor_msgs/CameraInfo` beside them (`--info-topic` to choose another),
/// each image posed in `--frame` by the TF tree at its stamp. Recordings carry no sensor depth
/// for the checks, so only the maps and the depth stage's counts are reported.
#[derive(Args)]
#[command(after_help = "Examples:\n  \
    fuzzyvox mono --dir ../shared/data/rgbd-7scenes-redkitchen --res 0.04\n  \
    fuzzyvox mono --dir ../shared/data/rgbd-7scenes-redkitchen --res 0.04 --views 2 --consistency 0 --json\n  \
    fuzzyvox mono --dir DIR --res 0.05 --trajectory poses.tum --model fuzzy --out maps/\n  \
    fuzzyvox mono --dir ../shared/data/rgbd-hololens-000 --res 0.05 --plan 50 --json\n  \
    fuzzyvox mono --bag ../shared/data/robot-logs/hololens-000-mcap --image-topic /camera/color/image_raw/compressed --res 0.05 --out maps/")]
#[command(group(clap::ArgGroup::new("input").required(true).args(["dir", "bag"])))]
pub struct MonoArgs {
    /// The folder of posed colour frames.
    #[arg(long)]
    dir: Option<PathBuf>,
    /// A robot recording instead of a folder.
    #[arg(long, requires = "image_topic", conflicts_with_all = ["trajectory", "extrinsics"])]
    bag: Option<PathBuf>,
    /// The recording's colour images (`sensor_msgs/CompressedImage` or `sensor_msgs/Image`).
    #[arg(long, requires = "bag")]
    image_topic: Option<String>,
    /// The recording's `sensor_msgs/CameraInfo` topic (default: `camera_info` beside the
    /// images, or the only one).
    #[arg(long, requires = "bag")]
    info_topic: Option<String>,
    /// The world frame of the recording's TF tree.
    #[arg(long, default_value = "map", requires = "bag")]
    frame: String,
    #[command(flatten)]
    maps: MapCheckArgs,
    /// Views matched at once for each depth image (2: pairs).
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u32).range(2..=17))]
    views: u32,
    /// Check each depth image against this many neighbouring depth images on each side: a
    /// pixel keeps its depth only where enough of them agree (0: no check).
    #[arg(long, default_value_t = 4, value_name = "N")]
    consistency: usize,
    /// Neighbouring depth images that must agree with a pixel for it to keep its depth.
    #[arg(long, default_value_t = 1, value_name = "K")]
    min_agreeing: usize,
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
    /// Plan N flights through every map: start/goal pairs drawn in the free space of a
    /// reference map of the folder's sensor depth (all frames, log-odds), near the camera path,
    /// planned with unknown space forbidden and checked against the reference's occupied voxels
    /// (JSON per map: plan_queries, plan_success, plan_collisions, plan_failures,
    /// plan_collision_details, reference_plan_success).
    #[arg(long, value_name = "N")]
    plan: Option<usize>,
    /// Seed of the flights' draw.
    #[arg(long, default_value_t = 1, requires = "plan")]
    seed: u64,
    /// The vehicle's radius for the flights (metres).
    #[arg(
        long,
        value_name = "M",
        default_value_t = 0.2,
        requires = "plan",
        allow_negative_numbers = true
    )]
    radius: f64,
    /// Write every map here: MODEL.fvx, MODEL-top.png (a top view by height with the camera's
    /// path) and MODEL.html (its 3D viewer page).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Print one JSON object instead of text.
    #[arg(long)]
    json: bool,
}

pub fn run(args: MonoArgs) -> anyhow::Result<()> {
    let defaults = MonoConfig::new(args.maps.res);
    let config = MonoConfig {
        // The depth stage's checked images take the evidence model made for them.
        held_out: HeldOutConfig {
            evidence: defaults.held_out.evidence,
            ..args.maps.config()?
        },
        views: args.views,
        trajectory: args.trajectory.clone(),
        extrinsics: args.extrinsics.clone(),
        near: args.near,
        far: args.far,
        min_baseline: args.min_baseline,
        consistency: ConsistencyParams {
            neighbours: args.consistency,
            min_agreeing: args.min_agreeing,
            ..defaults.consistency
        },
        flights: args.plan.map(|queries| RealFlightConfig {
            seed: args.seed,
            vehicle_radius: args.radius,
            ..RealFlightConfig::new(queries)
        }),
    };
    config.validate().map_err(flag_error)?;
    let (frames, source) = open_frames(&args)?;
    let mut bars = StageBars::new(args.json);
    let run = run_mono_on(frames.as_ref(), &config, &mut |stage, done, total| {
        bars.update(stage, done, total)
    })
    .map_err(flag_error)
    .with_context(|| format!("mapping {}", source.display()))?;
    bars.finish();
    if let Some(dir) = &args.out {
        let cameras: Vec<_> = frames
            .poses()
            .iter()
            .map(|p| p.translation.vector.into())
            .collect();
        let title = source.file_name().unwrap_or_default().to_string_lossy();
        for file in write_held_out_maps(dir, &title, &run.maps, &cameras)
            .with_context(|| format!("writing the maps into {}", dir.display()))?
        {
            info!("wrote {}", file.display());
        }
    }
    let report = &run.report;
    if args.json {
        return super::print_json(&serde_json::to_value(report)?);
    }
    println!(
        "{}: {} frames; {} build the maps ({} depth images: {} rectified, {} swept, {} multi-view; \
         {} without), {} held out ({} with sensor depth)",
        source.display(),
        report.split.frames,
        report.split.build_frames,
        report.depth_images,
        report.rectified,
        report.swept,
        report.multi_view,
        report.skipped.values().sum::<usize>(),
        report.split.held_out_frames,
        report.held_out_checked,
    );
    for (reason, n) in &report.skipped {
        println!("  {n} frame(s) without depth: {reason}");
    }
    let check = &report.consistency;
    if check.neighbours > 0 {
        println!(
            "consistency check ({} neighbours each side, {} agreeing needed): kept {} of {} \
             pixels ({:.0}%)",
            check.neighbours,
            check.min_agreeing,
            check.pixels_kept,
            check.pixels_checked,
            100.0 * check.pixels_kept as f64 / check.pixels_checked.max(1) as f64,
        );
    }
    let stage = &report.depth_stage;
    println!(
        "depth stage against sensor depth: {} pixels, median relative error {:.3} (most confident \
         half {:.3}), interval coverage {:.3} (most confident half {:.3})",
        stage.summary.pixels,
        stage.summary.median_rel_error,
        stage.summary.median_rel_error_top50,
        stage.summary.interval_coverage,
        stage.summary.interval_coverage_top50
    );
    println!(
        "{:.2} frames/s ({:.0}% of the time in the depth stage)",
        report.frames_per_second,
        100.0 * stage.share_of_mapping_time
    );
    print_table(&report.maps);
    print_flights(&report.maps);
    Ok(())
}

/// The posed frames of the folder or of the recording, and its path.
fn open_frames(args: &MonoArgs) -> anyhow::Result<(Box<dyn PosedFrames>, PathBuf)> {
    if let (Some(bag), Some(topic)) = (&args.bag, &args.image_topic) {
        let reading = || format!("reading {}", bag.display());
        let recording = Bag::open(bag).with_context(reading)?;
        let frames = BagFrames::open(&recording, topic, args.info_topic.as_deref(), &args.frame)
            .with_context(reading)?;
        info!("{} frames on {topic} in {}", frames.len(), bag.display());
        return Ok((Box::new(frames), bag.clone()));
    }
    let Some(dir) = &args.dir else {
        anyhow::bail!("give --dir or --bag with --image-topic");
    };
    let extrinsics = match &args.extrinsics {
        Some(path) => Some(
            read_pose_txt(path)
                .with_context(|| format!("reading the extrinsics {}", path.display()))?,
        ),
        None => None,
    };
    let folder = PosedFolder::open(dir, args.trajectory.as_deref(), extrinsics)
        .with_context(|| format!("opening the image folder {}", dir.display()))?;
    info!(
        "{} frames in {} ({})",
        folder.frames.len(),
        dir.display(),
        folder.color_intrinsics.display(),
    );
    Ok((Box::new(folder), dir.clone()))
}

/// The flights of every map, when there were any.
fn print_flights(maps: &[MapCheckReport]) {
    let flown: Vec<_> = maps
        .iter()
        .filter_map(|m| Some((m.model, m.flights.as_ref()?)))
        .collect();
    let Some((_, first)) = flown.first() else {
        return;
    };
    println!(
        "flights: {} start/goal pairs near the camera path; the sensor-depth reference solves {:.2}",
        first.summary.plan_queries, first.reference_plan_success
    );
    println!("{:<8} {:>9} {:>10}", "model", "success", "collisions");
    for (model, f) in flown {
        println!(
            "{:<8} {:>9.2} {:>10}",
            model.name(),
            f.summary.plan_success,
            f.summary.plan_collisions
        );
    }
}
