use fuzzyvox_core::error::Result;
use fuzzyvox_core::map::VoxelMap;
use fuzzyvox_core::measures::VoxelClass;
use fuzzyvox_core::storage::{KeyBox, VoxelKey};
use nalgebra::Point3;

use crate::config::{PlannerConfig, UnknownPolicy};

/// Questions a planner asks of any map, answered with one [`PlannerConfig`].
///
/// A voxel is *safe* when it is free with safety at or above the threshold, or unknown while
/// unknown space is allowed at a cost.
pub trait SafetyQueries {
    /// Whether one voxel is safe under `config`.
    fn is_safe_voxel(&self, key: VoxelKey, config: &PlannerConfig) -> bool;

    /// Whether a ball of `radius` metres at `point` touches only safe voxels.
    fn is_safe(&self, point: &Point3<f64>, radius: f64, config: &PlannerConfig) -> Result<bool>;

    /// The centre of the safe voxel nearest to `point` within `max_distance` metres (ties
    /// broken by key order), or `None`.
    fn nearest_safe(
        &self,
        point: &Point3<f64>,
        max_distance: f64,
        config: &PlannerConfig,
    ) -> Result<Option<Point3<f64>>>;

    /// Every safe voxel in a box.
    fn safe_voxels_in_box(&self, region: &KeyBox, config: &PlannerConfig) -> Vec<VoxelKey>;
}

impl<M: VoxelMap + ?Sized> SafetyQueries for M {
    fn is_safe_voxel(&self, key: VoxelKey, config: &PlannerConfig) -> bool {
        let m = self.measures_at(key);
        match m.class {
            VoxelClass::Free => m.safety >= config.safety_threshold,
            VoxelClass::Unknown => matches!(config.unknown, UnknownPolicy::Cost(_)),
            VoxelClass::Occupied | VoxelClass::Ambiguous => false,
        }
    }

    fn is_safe(&self, point: &Point3<f64>, radius: f64, config: &PlannerConfig) -> Result<bool> {
        let config = config.validate()?;
        let resolution = self.resolution();
        let offset = nalgebra::Vector3::repeat(radius.max(0.0));
        let region = KeyBox::from_points(&resolution, &(point - offset), &(point + offset))?;
        let half = resolution.size() * 0.5;
        for z in region.min.z..=region.max.z {
            for y in region.min.y..=region.max.y {
                for x in region.min.x..=region.max.x {
                    let key = VoxelKey::new(x, y, z);
                    // The ball touches the voxel when the voxel's box comes within `radius`.
                    let c = resolution.center(key);
                    let gap = (point - c).map(|d| (d.abs() - half).max(0.0));
                    if gap.norm() <= radius && !self.is_safe_voxel(key, &config) {
                        return Ok(false);
                    }
                }
            }
        }
        Ok(true)
    }

    fn nearest_safe(
        &self,
        point: &Point3<f64>,
        max_distance: f64,
        config: &PlannerConfig,
    ) -> Result<Option<Point3<f64>>> {
        let config = config.validate()?;
        let resolution = self.resolution();
        let offset = nalgebra::Vector3::repeat(max_distance.max(0.0));
        let region = KeyBox::from_points(&resolution, &(point - offset), &(point + offset))?;
        let mut best: Option<(f64, VoxelKey)> = None;
        for z in region.min.z..=region.max.z {
            for y in region.min.y..=region.max.y {
                for x in region.min.x..=region.max.x {
                    let key = VoxelKey::new(x, y, z);
                    let d = (resolution.center(key) - point).norm();
                    if d <= max_distance
                        && best.is_none_or(|(bd, bk)| (d, key) < (bd, bk))
                        && self.is_safe_voxel(key, &config)
                    {
                        best = Some((d, key));
                    }
                }
            }
        }
        Ok(best.map(|(_, key)| resolution.center(key)))
    }

    fn safe_voxels_in_box(&self, region: &KeyBox, config: &PlannerConfig) -> Vec<VoxelKey> {
        let mut safe = Vec::new();
        for z in region.min.z..=region.max.z {
            for y in region.min.y..=region.max.y {
                for x in region.min.x..=region.max.x {
                    let key = VoxelKey::new(x, y, z);
                    if self.is_safe_voxel(key, config) {
                        safe.push(key);
                    }
                }
            }
        }
        safe
    }
}
