//! What a held-out run returns: its report (with which frames of the folder it used) and the
//! maps it built.

use std::path::{Path, PathBuf};

use fuzzyvox_core::map::AnyMap;
use serde::Serialize;

use crate::rgbd::HoldoutSplit;

/// A held-out run's report (the command's `--json`) and the maps it built, in the report's
/// order: from every frame but the held-out ones.
#[derive(Debug)]
pub struct HeldOutRun<R> {
    /// The report.
    pub report: R,
    /// The maps.
    pub maps: Vec<AnyMap>,
}

/// Which frames of a folder a held-out run used (the first keys of its report).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FolderSplit {
    /// The folder.
    pub dir: PathBuf,
    /// Frames in the folder.
    pub frames: usize,
    /// Frames that built the maps.
    pub build_frames: usize,
    /// Frames held out.
    pub held_out_frames: usize,
    /// Every K-th frame was held out.
    pub holdout: usize,
    /// Voxel size (m).
    pub resolution: f64,
}

impl FolderSplit {
    /// `split` of `dir`'s `frames` frames (every `holdout`-th held out), maps at `resolution`
    /// metres.
    pub(super) fn new(
        dir: &Path,
        frames: usize,
        split: &HoldoutSplit,
        holdout: usize,
        resolution: f64,
    ) -> Self {
        Self {
            dir: dir.to_path_buf(),
            frames,
            build_frames: split.build.len(),
            held_out_frames: split.held_out.len(),
            holdout,
            resolution,
        }
    }
}
