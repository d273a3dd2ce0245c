use fuzzyvox_core::map::VoxelMapMut;
use nalgebra::Isometry3;
use rayon::prelude::*;
use rustc_hash::FxHashSet;

use fuzzyvox_core::error::Result;
use fuzzyvox_core::geometry::PinholeIntrinsics;
use fuzzyvox_core::integrate::{DepthFrame, IntegrationOptions, IntervalDepthImage};
use fuzzyvox_core::map::{LogOddsConfig, LogOddsMap, VoxelMap};
use fuzzyvox_core::storage::{Resolution, VoxelKey};
use fuzzyvox_sim::{Scene, render};

/// What is really there, voxel by voxel, within what the cameras could see.
#[derive(Clone, Debug)]
pub struct GroundTruth {
    resolution: Resolution,
    occupied: FxHashSet<VoxelKey>,
    observed: FxHashSet<VoxelKey>,
}

impl GroundTruth {
    /// Ground truth from explicit sets: `occupied` voxels meet the geometry, `observed` voxels
    /// are those the cameras could see (occupied ones included).
    pub fn new(
        resolution: Resolution,
        occupied: impl IntoIterator<Item = VoxelKey>,
        observed: impl IntoIterator<Item = VoxelKey>,
    ) -> Self {
        let occupied: FxHashSet<VoxelKey> = occupied.into_iter().collect();
        let mut observed: FxHashSet<VoxelKey> = observed.into_iter().collect();
        observed.extend(occupied.iter().copied());
        Self {
            resolution,
            occupied,
            observed,
        }
    }

    /// Ground truth from a scene and its gold-standard map: the observed region is every voxel
    /// the gold standard observed, and the truly occupied voxels are the observed ones that meet
    /// the scene geometry (the geometric truth).
    pub fn from_scene(scene: &Scene, gold: &dyn VoxelMap) -> Self {
        let resolution = gold.resolution();
        let observed: Vec<VoxelKey> = gold.cells().map(|(key, _)| key).collect();
        let occupied: Vec<VoxelKey> = observed
            .par_iter()
            .copied()
            .filter(|&key| meets_geometry(scene, resolution, key))
            .collect();
        Self::new(resolution, occupied, observed)
    }

    /// The voxel size.
    pub fn resolution(&self) -> Resolution {
        self.resolution
    }

    /// Whether a voxel truly meets the geometry (within the observed region).
    pub fn is_occupied(&self, key: VoxelKey) -> bool {
        self.occupied.contains(&key)
    }

    /// Whether a voxel lies in the observed region.
    pub fn is_observed(&self, key: VoxelKey) -> bool {
        self.observed.contains(&key)
    }

    /// Number of truly occupied voxels.
    pub fn occupied_count(&self) -> usize {
        self.occupied.len()
    }

    /// Number of observed voxels.
    pub fn observed_count(&self) -> usize {
        self.observed.len()
    }

    /// The truly occupied voxels.
    pub fn occupied(&self) -> impl Iterator<Item = VoxelKey> + '_ {
        self.occupied.iter().copied()
    }
}

/// Whether a voxel meets the scene geometry: its closed box, grown by a thousandth of a voxel,
/// intersects a shape. A surface lying exactly on a voxel face (flat ground at z = 0) belongs
/// to the voxels on both sides, as rays ending on it fall on either side by rounding.
pub fn meets_geometry(scene: &Scene, resolution: Resolution, key: VoxelKey) -> bool {
    let touch = nalgebra::Vector3::repeat(1e-3 * resolution.size());
    let low = resolution.corner(key) - touch;
    let high = resolution.corner(VoxelKey::new(key.x + 1, key.y + 1, key.z + 1)) + touch;
    scene.intersects_box(&low, &high)
}

/// The paper's "gold standard": the scene's true depth, seen from every camera pose, inserted
/// into the standard log-odds map. Rays that meet nothing within `max_range` clear free space
/// up to it.
pub fn gold_standard(
    scene: &Scene,
    intrinsics: &PinholeIntrinsics,
    poses: &[Isometry3<f64>],
    resolution: f64,
    max_range: f64,
) -> Result<LogOddsMap> {
    let mut map = LogOddsMap::new(LogOddsConfig::new(resolution)?)?;
    let options = IntegrationOptions {
        max_range: Some(max_range),
    };
    for pose in poses {
        let frame = render(scene, intrinsics, pose, 0, max_range * 4.0);
        // Sky: a depth beyond the range, so the ray clears free space up to max_range.
        let depth: Vec<f32> = frame
            .depth
            .iter()
            .map(|&z| {
                if z.is_finite() {
                    z
                } else {
                    (max_range * 2.0) as f32
                }
            })
            .collect();
        let image =
            IntervalDepthImage::from_depth(frame.width, frame.height, &depth, |z| (z, z, 1.0))?;
        map.integrate_depth(&DepthFrame::new(*intrinsics, *pose, image)?, &options)?;
    }
    Ok(map)
}
