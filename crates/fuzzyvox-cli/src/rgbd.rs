use std::path::PathBuf;

use anyhow::Context;
use clap::Args;
use fuzzyvox::eval::{run_rgbd_on, save_held_out_maps};
use fuzzyvox::io::rgbd::RgbdFolder;
use tracing::info;

use super::held_out::{MapCheckArgs, StageBars, flag_error, print_table};

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
    #[command(flatten)]
    maps: MapCheckArgs,
    /// Save every map here as MODEL.fvx.
    #[arg(long)]
    save: Option<PathBuf>,
    /// Print one JSON object instead of text.
    #[arg(long)]
    json: bool,
}

pub fn run(args: RgbdArgs) -> anyhow::Result<()> {
    let config = args.maps.config()?;
    let folder = RgbdFolder::open(&args.dir)
        .with_context(|| format!("opening the RGB-D folder {}", args.dir.display()))?;
    let mut bars = StageBars::new(args.json);
    let run = run_rgbd_on(&folder, &config, &mut |stage, done, total| {
        bars.update(stage, done, total)
    })
    .map_err(flag_error)
    .with_context(|| format!("mapping {}", args.dir.display()))?;
    bars.finish();
    let report = &run.report;
    info!(
        "{} frames in {}: {} built the maps, {} were held out",
        report.split.frames,
        args.dir.display(),
        report.split.build_frames,
        report.split.held_out_frames
    );
    if let Some(dir) = &args.save {
        for file in save_held_out_maps(dir, &run.maps)
            .with_context(|| format!("saving the maps into {}", dir.display()))?
        {
            info!("saved {}", file.display());
        }
    }
    if args.json {
        return super::print_json(&serde_json::to_value(report)?);
    }
    println!(
        "{}: {} frames, maps from {} at {} m, checked on {} held-out frames (every {}th)",
        args.dir.display(),
        report.split.frames,
        report.split.build_frames,
        report.split.resolution,
        report.split.held_out_frames,
        report.split.holdout,
    );
    print_table(&report.maps);
    Ok(())
}
