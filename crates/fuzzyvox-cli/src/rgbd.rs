use std::path::PathBuf;

use anyhow::Context;
use clap::Args;
use fuzzyvox::IntegrationOptions;
use fuzzyvox::eval::HoldoutSplit;
use fuzzyvox::io::rgbd::RgbdFolder;
use serde_json::json;
use tracing::info;

use super::held_out::{MapCheckArgs, check_all, integrate_all, print_table, reports, save_all};
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
    let family = args.maps.family()?;
    let check = args.maps.check()?;
    let folder = RgbdFolder::open(&args.dir)
        .with_context(|| format!("opening the RGB-D folder {}", args.dir.display()))?;
    let holdout = args.maps.holdout;
    let split = HoldoutSplit::new(folder.frames.len(), holdout)
        .with_context(|| format!("--holdout {holdout} with {} frames", folder.frames.len()))?;
    info!(
        "{} frames in {}: {} build the maps, {} are held out",
        folder.frames.len(),
        args.dir.display(),
        split.build.len(),
        split.held_out.len()
    );
    let mut maps = args.maps.maps(family)?;

    // Each frame is read once and fed to every map, so memory holds one frame at a time.
    let read = |position: usize| {
        let files = &folder.frames[position];
        folder
            .read_kinect_frame(position)
            .with_context(|| format!("reading frame {}", files.depth.display()))
    };
    let label = |position: usize| format!("frame {}", folder.frames[position].number);
    let options = IntegrationOptions::default();
    let bar = progress::bar(split.build.len() as u64, "integrating", args.json);
    for &position in &split.build {
        integrate_all(&mut maps, &read(position)?, &options, &label(position))?;
        bar.inc(1);
    }
    bar.finish_and_clear();
    let bar = progress::bar(split.held_out.len() as u64, "ray casting", args.json);
    for &position in &split.held_out {
        check_all(&mut maps, &read(position)?, &check, &label(position))?;
        bar.inc(1);
    }
    bar.finish_and_clear();
    if let Some(dir) = &args.save {
        save_all(&maps, dir)?;
    }
    let res = args.maps.res;
    let reports = reports(&maps, family, res);
    if args.json {
        return super::print_json(&json!({
            "dir": args.dir,
            "frames": folder.frames.len(),
            "build_frames": split.build.len(),
            "held_out_frames": split.held_out.len(),
            "holdout": holdout,
            "resolution": res,
            "pixel_step": args.maps.pixel_step,
            "cast_range": args.maps.cast_range,
            "stop_at_ambiguous": args.maps.stop_at_ambiguous,
            "maps": reports,
        }));
    }
    println!(
        "{}: {} frames, maps from {} at {res} m, checked on {} held-out frames (every {holdout}th)",
        args.dir.display(),
        folder.frames.len(),
        split.build.len(),
        split.held_out.len(),
    );
    print_table(&reports);
    Ok(())
}
