//! `run_rgbd`: maps built from the sensor depth of an RGB-D folder, checked against its
//! held-out frames (what `fuzzyvox rgbd` runs).

use std::path::Path;

use serde::Serialize;

use super::config::HeldOutConfig;
use super::maps::{MapCheckReport, MapUnderTest, check_all, integrate_all};
use super::run::{FolderSplit, HeldOutRun};
use super::stage::HeldOutStage;
use crate::rgbd::HoldoutSplit;
use fuzzyvox_core::error::Result;
use fuzzyvox_core::integrate::IntegrationOptions;
use fuzzyvox_io::rgbd::RgbdFolder;

/// What [`run_rgbd`] returns.
pub type RgbdRun = HeldOutRun<RgbdReport>;

/// Opens the RGB-D folder `dir` (`frame-N.depth.png`, `frame-N.pose.txt`,
/// `camera-intrinsics.txt`: the 7-Scenes / 3DMatch layout) and runs [`run_rgbd_on`] on it.
pub fn run_rgbd(
    dir: &Path,
    config: &HeldOutConfig,
    progress: &mut dyn FnMut(HeldOutStage, usize, usize),
) -> Result<RgbdRun> {
    config.validate()?;
    let folder = RgbdFolder::open(dir)?;
    run_rgbd_on(&folder, config, progress)
}

/// Builds every map of `config` from all frames of `folder` but every K-th (each pixel's depth
/// interval ±2σ of the Kinect's axial noise), then casts a ray through each map for every
/// checked pixel of each held-out frame and compares the depth of the first occupied voxel with
/// the measured depth.
///
/// `progress(stage, done, total)` is called with `done = 0` when a stage starts and after each
/// frame. Each frame is read once and fed to every map, so memory holds one frame at a time.
pub fn run_rgbd_on(
    folder: &RgbdFolder,
    config: &HeldOutConfig,
    progress: &mut dyn FnMut(HeldOutStage, usize, usize),
) -> Result<RgbdRun> {
    config.validate()?;
    let split = HoldoutSplit::new(folder.frames.len(), config.holdout)?;
    let check = config.check();
    let mut maps: Vec<MapUnderTest> = config
        .new_maps()?
        .into_iter()
        .map(MapUnderTest::new)
        .collect();
    let options = IntegrationOptions::default();
    let stages = [
        (HeldOutStage::Integrating, &split.build),
        (HeldOutStage::RayCasting, &split.held_out),
    ];
    for (stage, positions) in stages {
        progress(stage, 0, positions.len());
        for (done, &position) in positions.iter().enumerate() {
            let frame = folder.read_kinect_frame(position)?;
            match stage {
                HeldOutStage::RayCasting => check_all(&mut maps, &frame, &check)?,
                _ => integrate_all(&mut maps, &frame, &options)?,
            }
            progress(stage, done + 1, positions.len());
        }
    }
    let report = RgbdReport {
        split: FolderSplit::new(
            &folder.dir,
            folder.frames.len(),
            &split,
            config.holdout,
            config.resolution,
        ),
        pixel_step: config.pixel_step,
        cast_range: config.cast_range,
        stop_at_ambiguous: config.stop_at_ambiguous,
        maps: maps
            .iter()
            .map(|m| m.report(config.operator, config.resolution))
            .collect(),
    };
    Ok(RgbdRun {
        report,
        maps: maps.into_iter().map(|m| m.map).collect(),
    })
}

/// The report of [`run_rgbd`]: its JSON is what `fuzzyvox rgbd --json` prints.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RgbdReport {
    /// The RGB-D folder and which of its frames built the maps.
    #[serde(flatten)]
    pub split: FolderSplit,
    /// Every N-th pixel of the held-out frames was checked.
    pub pixel_step: u32,
    /// Rays were cast this far (m).
    pub cast_range: f64,
    /// Whether ambiguous voxels stopped rays.
    pub stop_at_ambiguous: bool,
    /// One report per map, in [`fuzzyvox_core::map::MapKind::ALL`] order.
    pub maps: Vec<MapCheckReport>,
}
