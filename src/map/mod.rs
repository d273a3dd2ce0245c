//! Maps: the dual-set fuzzy map, and the interface every map implements.

mod config;
mod fuzzy;

pub use config::FuzzyConfig;
pub use fuzzy::{FuzzyMap, VoxelCounts};

use crate::error::Result;
use crate::integrate::{DepthFrame, IntegrationOptions, IntegrationStats, PointCloud};
use crate::measures::{MeasureConfig, Measures, Memberships, VoxelClass};
use crate::storage::{Resolution, VoxelKey};

/// What every map offers: integration of the same observations, and the same measures per
/// voxel, so that experiments can feed identical data to each map and compare them fairly.
pub trait VoxelMap {
    /// The voxel size.
    fn resolution(&self) -> Resolution;

    /// How measures and classes are computed.
    fn measure_config(&self) -> &MeasureConfig;

    /// A voxel's memberships (both 0 when nothing is known about it).
    fn memberships_at(&self, key: VoxelKey) -> Memberships;

    /// Integrates one point cloud as one scan. On error the map is unchanged.
    fn integrate_cloud(
        &mut self,
        cloud: &PointCloud,
        options: &IntegrationOptions,
    ) -> Result<IntegrationStats>;

    /// Integrates one interval depth image as one scan. On error the map is unchanged.
    fn integrate_depth(
        &mut self,
        frame: &DepthFrame,
        options: &IntegrationOptions,
    ) -> Result<IntegrationStats>;

    /// Every measure of a voxel.
    fn measures_at(&self, key: VoxelKey) -> Measures {
        self.measure_config().measures(self.memberships_at(key))
    }

    /// The class of a voxel.
    fn class_at(&self, key: VoxelKey) -> VoxelClass {
        self.measure_config().classify(self.memberships_at(key))
    }
}
