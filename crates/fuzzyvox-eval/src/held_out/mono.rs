//! `run_mono`: maps built with the one-camera depth stage from posed colour images, checked
//! against the sensor depth of held-out frames (what `fuzzyvox mono` runs).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

use serde::Serialize;

use super::flights::{fly_real, reference_map};
use super::maps::{MapCheckReport, MapUnderTest, check_all, integrate_all};
use super::mono_config::MonoConfig;
use super::run::{FolderSplit, HeldOutRun};
use super::stage::HeldOutStage;
use crate::depth_stage::{DepthStageErrors, DepthStageSummary};
use crate::rgbd::HoldoutSplit;
use fuzzyvox_core::error::{Error, Result};
use fuzzyvox_core::integrate::DepthFrame;
use fuzzyvox_core::integrate::IntegrationOptions;
use fuzzyvox_core::map::VoxelMap;
use fuzzyvox_depth::{ConsistencyFilter, ConsistencyParams};
use fuzzyvox_io::posed::{PosedFolder, PosedFrames};
use fuzzyvox_io::rgbd::read_pose_txt;

/// The depth stage's own depth against the sensor's, with its share of the time.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct DepthStageReport {
    /// Errors and interval coverage over all compared pixels and the most confident half.
    #[serde(flatten)]
    pub summary: DepthStageSummary,
    /// Time in the depth stage (s).
    pub seconds: f64,
    /// The depth stage's share of the mapping time (reading, depth stage, integration).
    pub share_of_mapping_time: f64,
}

/// What the consistency check did (see [`fuzzyvox_depth::check_consistency`]).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ConsistencyReport {
    /// Neighbouring depth images checked on each side (0: no check).
    pub neighbours: usize,
    /// Agreeing neighbours a pixel needed.
    pub min_agreeing: usize,
    /// Pixels with depth before the check.
    pub pixels_checked: usize,
    /// Of those, the pixels kept.
    pub pixels_kept: usize,
}

/// Where a mono run's time went (s).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct MonoSeconds {
    /// Reading the colour images.
    pub read: f64,
    /// The depth stage.
    pub depth: f64,
    /// Integrating into every map.
    pub integrate: f64,
    /// Reading sensor depth and checking the depth stage and the maps against it.
    pub check: f64,
}

/// The report of [`run_mono`]: its JSON is what `fuzzyvox mono --json` prints.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MonoReport {
    /// The image folder and which of its frames went through the depth stage into the maps.
    #[serde(flatten)]
    pub split: FolderSplit,
    /// Held-out frames with sensor depth, the ones the maps were checked on.
    pub held_out_checked: usize,
    /// Views matched at once.
    pub views: u32,
    /// `[near, far]` searched (m).
    pub depth_range: [f64; 2],
    /// The colour camera's intrinsics file.
    pub color_intrinsics: PathBuf,
    /// Depth images the depth stage made.
    pub depth_images: usize,
    /// Of those, from rectified pairs.
    pub rectified: usize,
    /// Of those, by plane sweep.
    pub swept: usize,
    /// Of those, from more than two views.
    pub multi_view: usize,
    /// Earlier views left out because they needed too many planes.
    pub views_dropped: usize,
    /// The check of each depth image against its neighbours.
    pub consistency: ConsistencyReport,
    /// Build frames without a depth image, by reason.
    pub skipped: BTreeMap<String, usize>,
    /// The depth stage against sensor depth.
    pub depth_stage: DepthStageReport,
    /// Where the time went.
    pub seconds: MonoSeconds,
    /// Build frames per second of mapping time.
    pub frames_per_second: f64,
    /// One report per map, in [`fuzzyvox_core::map::MapKind::ALL`] order.
    pub maps: Vec<MapCheckReport>,
}

/// What [`run_mono`] returns.
pub type MonoRun = HeldOutRun<MonoReport>;

/// Opens the folder of posed colour frames `dir` (`frame-N.color.png` or `.jpg`, poses from
/// `frame-N.pose.txt` or `config.trajectory`, `camera-intrinsics.txt` and optionally
/// `color-intrinsics.txt`; `config.extrinsics` read as `depth_from_color`) and runs
/// [`run_mono_on`] on it.
pub fn run_mono(
    dir: &Path,
    config: &MonoConfig,
    progress: &mut dyn FnMut(HeldOutStage, usize, usize),
) -> Result<MonoRun> {
    config.validate()?;
    let extrinsics = match &config.extrinsics {
        Some(path) => Some(read_pose_txt(path)?),
        None => None,
    };
    let folder = PosedFolder::open(dir, config.trajectory.as_deref(), extrinsics)?;
    run_mono_on(&folder, config, progress)
}

/// Streams every frame of `folder` but every K-th through pair selection and the depth stage
/// and integrates each depth image into every map of `config` (weighed so that images sharing
/// views count as much as a stream of pairs); sensor depth, where present, measures the depth
/// stage and, on the held-out frames, checks the maps. The folder's poses and extrinsics are
/// the ones it was opened with (`config.trajectory` and `config.extrinsics` are not read).
///
/// `progress(stage, done, total)` is called with `done = 0` when a stage starts and after each
/// frame.
pub fn run_mono_on(
    folder: &dyn PosedFrames,
    config: &MonoConfig,
    progress: &mut dyn FnMut(HeldOutStage, usize, usize),
) -> Result<MonoRun> {
    config.validate()?;
    let held_out = &config.held_out;
    let split = HoldoutSplit::new(folder.len(), held_out.holdout)?;
    let mut stream = config.stream()?;
    let check = held_out.check();
    let mut maps: Vec<MapUnderTest> = held_out
        .new_maps()?
        .into_iter()
        .map(MapUnderTest::new)
        .collect();
    let options = IntegrationOptions {
        max_range: Some(config.far),
    };
    let mut stage = DepthStageErrors::default();
    // The check drops depths at the far end of the search (see `ConsistencyParams::search_far`).
    let mut consistency = ConsistencyFilter::new(ConsistencyParams {
        search_far: Some(config.far),
        ..config.consistency
    })?;
    let mut seconds = MonoSeconds::default();
    let total = split.build.len();
    progress(HeldOutStage::DepthAndMapping, 0, total);
    for (done, &position) in split.build.iter().enumerate() {
        let t = Instant::now();
        let frame = folder.read_frame(position)?;
        seconds.read += t.elapsed().as_secs_f64();
        let t = Instant::now();
        let result = stream.push(frame)?;
        seconds.depth += t.elapsed().as_secs_f64();
        progress(HeldOutStage::DepthAndMapping, done + 1, total);
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
        let checked = consistency.push(position, depth)?;
        seconds.depth += t.elapsed().as_secs_f64();
        add_checked(
            folder,
            checked,
            &mut maps,
            &mut stage,
            &mut seconds,
            &options,
        )?;
    }
    let t = Instant::now();
    let checked = consistency.finish()?;
    seconds.depth += t.elapsed().as_secs_f64();
    add_checked(
        folder,
        checked,
        &mut maps,
        &mut stage,
        &mut seconds,
        &options,
    )?;
    let total = split.held_out.len();
    progress(HeldOutStage::RayCasting, 0, total);
    let mut checked = 0;
    for (done, &position) in split.held_out.iter().enumerate() {
        let t = Instant::now();
        if let Some(sensor) = folder.read_sensor_depth(position)? {
            check_all(&mut maps, &sensor, &check)?;
            checked += 1;
        }
        seconds.check += t.elapsed().as_secs_f64();
        progress(HeldOutStage::RayCasting, done + 1, total);
    }

    let flights = match &config.flights {
        Some(flights) => {
            progress(HeldOutStage::Flights, 0, 1);
            let t = Instant::now();
            let reference = reference_map(folder, held_out.resolution)?.ok_or(Error::Empty(
                "sensor depth in the frames (flights are checked against a map of it)",
            ))?;
            let cameras: Vec<_> = folder
                .poses()
                .iter()
                .map(|p| p.translation.vector.into())
                .collect();
            let views: Vec<&dyn VoxelMap> = maps.iter().map(|m| m.map.as_map()).collect();
            let flown = fly_real(&views, &reference, &cameras, flights)?;
            seconds.check += t.elapsed().as_secs_f64();
            progress(HeldOutStage::Flights, 1, 1);
            Some(flown)
        }
        None => None,
    };
    let counts = stream.counts();
    let mapping = (seconds.read + seconds.depth + seconds.integrate).max(1e-9);
    let report = MonoReport {
        split: FolderSplit::new(
            folder.source(),
            folder.len(),
            &split,
            held_out.holdout,
            held_out.resolution,
        ),
        held_out_checked: checked,
        views: config.views,
        depth_range: [config.near, config.far],
        color_intrinsics: folder.intrinsics_source(),
        depth_images: counts.depth_images(),
        rectified: counts.rectified,
        swept: counts.swept,
        multi_view: counts.multi_view,
        views_dropped: stream.views_dropped(),
        consistency: ConsistencyReport {
            neighbours: config.consistency.neighbours,
            min_agreeing: config.consistency.min_agreeing,
            pixels_checked: consistency.counts().checked,
            pixels_kept: consistency.counts().kept,
        },
        skipped: counts
            .skipped
            .iter()
            .map(|(reason, n)| (reason.name().to_string(), *n))
            .collect(),
        depth_stage: DepthStageReport {
            summary: stage.summary(),
            seconds: seconds.depth,
            share_of_mapping_time: seconds.depth / mapping,
        },
        seconds,
        frames_per_second: split.build.len() as f64 / mapping,
        maps: maps
            .iter()
            .enumerate()
            .map(|(i, m)| {
                let mut report = m.report(held_out.operator, held_out.resolution);
                report.flights = flights.as_ref().and_then(|f| f.get(i).cloned());
                report
            })
            .collect(),
    };
    Ok(MonoRun {
        report,
        maps: maps.into_iter().map(|m| m.map).collect(),
    })
}

/// Measures checked depth images (each with its frame's position in the folder) against their
/// frames' sensor depth, where there is some, and integrates them into every map.
fn add_checked(
    folder: &dyn PosedFrames,
    checked: Vec<(usize, DepthFrame)>,
    maps: &mut [MapUnderTest],
    stage: &mut DepthStageErrors,
    seconds: &mut MonoSeconds,
    options: &IntegrationOptions,
) -> Result<()> {
    for (position, depth) in checked {
        let t = Instant::now();
        if let Some(sensor) = folder.read_sensor_depth(position)? {
            stage.add(&depth, &sensor);
        }
        seconds.check += t.elapsed().as_secs_f64();
        let t = Instant::now();
        integrate_all(maps, &depth, options)?;
        seconds.integrate += t.elapsed().as_secs_f64();
    }
    Ok(())
}
