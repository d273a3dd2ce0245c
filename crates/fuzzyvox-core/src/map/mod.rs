//! Maps: the dual-set fuzzy map, and the interface every map implements.

mod alpha;
mod any;
mod config;
mod counts;
mod function;
mod fuzzy;
mod kind;
mod levels;
mod logodds;
mod prior;
mod raycast;

pub use alpha::{AlphaConfig, AlphaCutMap};
pub use any::AnyMap;
pub use config::FuzzyConfig;
pub use counts::VoxelCounts;
pub use function::FunctionMap;
pub use fuzzy::FuzzyMap;
pub use kind::{MapKind, MapOptions};
pub use levels::{Accumulator, Levels};
pub use logodds::logodds as logodds_of;
pub use logodds::{LogOdds, LogOddsConfig, LogOddsMap};
pub use prior::MAX_PRIOR_VOXELS;
pub use raycast::{RayHit, cast_ray};

use nalgebra::Point3;

use crate::error::Result;
use crate::integrate::{DepthFrame, IntegrationOptions, IntegrationStats, PointCloud};
use crate::measures::{MeasureConfig, Measures, Memberships, VoxelClass};
use crate::storage::{BLOCK_CELLS, BlockKey, KeyBox, Resolution, VoxelKey};

/// What every map answers: memberships, measures and classes per voxel, counts, memory and its
/// observed voxels, so that planners, metrics and exporters run on any map alike: the three
/// maps that integrate observations, and read-only ones such as
/// [`FunctionMap`] or an OctoMap tree.
///
/// Maps that integrate observations also implement [`VoxelMapMut`].
pub trait VoxelMap: Send + Sync {
    /// The voxel size.
    fn resolution(&self) -> Resolution;

    /// How measures and classes are computed.
    fn measure_config(&self) -> &MeasureConfig;

    /// A voxel's memberships (both 0 when nothing is known about it).
    fn memberships_at(&self, key: VoxelKey) -> Memberships;

    /// The memberships of the voxels of one block (8×8×8, [`BlockKey::voxel`] order, x
    /// fastest) into `out`; voxels nothing is known about read as zero. Maps with block
    /// storage answer with one lookup; the default asks [`VoxelMap::memberships_at`] per voxel.
    fn block_memberships(&self, key: BlockKey, out: &mut [Memberships; BLOCK_CELLS]) {
        for (i, m) in out.iter_mut().enumerate() {
            *m = self.memberships_at(key.voxel(i));
        }
    }

    /// The stored state of the voxels of one block ([`BlockKey::voxel`] order) as opaque
    /// **stamps** into `out`, for consumers that follow a map's changes cell by cell: a voxel's
    /// memberships are [`VoxelMap::memberships_of_stamps`] of its stamp, so a voxel whose stamp
    /// is the one read before has not changed, and a consumer that keeps the stamps it read
    /// decodes only the voxels that did. Voxels nothing is known about have the stamp of an
    /// empty cell. Returns `false`, leaving `out` as it was, when the map keeps no such state
    /// (the default).
    fn block_stamps(&self, _key: BlockKey, _out: &mut [u64; BLOCK_CELLS]) -> bool {
        false
    }

    /// The memberships of the voxels whose stamps are `stamps` (see
    /// [`VoxelMap::block_stamps`]), in order, into `out` (as many as `stamps`; maps without
    /// stamps answer zero memberships).
    fn memberships_of_stamps(&self, _stamps: &[u64], out: &mut [Memberships]) {
        out.fill(Memberships::default());
    }

    /// Voxel counts per class over the allocated blocks (from block summaries).
    fn counts(&self) -> VoxelCounts;

    /// Whether any voxel of `region` is of class `class` (voxels nothing is known about are
    /// [`VoxelClass::Unknown`]). Maps with block storage answer from their per-block class
    /// counts and read cells only in blocks the box's boundary cuts; the default reads every
    /// block of the box with [`VoxelMap::block_memberships`].
    fn any_in_box(&self, region: &KeyBox, class: VoxelClass) -> bool {
        let config = self.measure_config();
        let mut cells = [Memberships::default(); BLOCK_CELLS];
        region.blocks().any(|block| {
            self.block_memberships(block, &mut cells);
            let whole = region.covers_block(block);
            cells.iter().enumerate().any(|(i, m)| {
                (whole || region.contains(block.voxel(i))) && config.classify(*m) == class
            })
        })
    }

    /// Heap memory held by the map, in bytes.
    fn memory_bytes(&self) -> usize;

    /// Every observed voxel (one that some evidence reached) with its memberships, in storage
    /// order.
    fn cells(&self) -> Box<dyn Iterator<Item = (VoxelKey, Memberships)> + '_>;

    /// The map's write version, for consumers that follow its changes (see
    /// [`VoxelMap::changed_blocks_since`]); `None` when the map does not track its writes
    /// (read-only maps, whose voxels never change).
    fn write_version(&self) -> Option<u64> {
        None
    }

    /// Keys of the blocks (8×8×8 voxels, [`VoxelKey::block`]) changed after `version`, in
    /// ascending order: every voxel whose memberships changed since the map's
    /// [`write_version`](VoxelMap::write_version) was `version` lies in one of them (a block
    /// an integration reached but left as it was need not be listed). `None` when the map does
    /// not track its writes.
    fn changed_blocks_since(&self, _version: u64) -> Option<Vec<BlockKey>> {
        None
    }

    /// A voxel's memberships at a world point (an error outside the key range).
    fn memberships_at_point(&self, point: &Point3<f64>) -> Result<Memberships> {
        Ok(self.memberships_at(self.resolution().key_of(point)?))
    }

    /// Every measure at a world point.
    fn measures_at_point(&self, point: &Point3<f64>) -> Result<Measures> {
        Ok(self.measures_at(self.resolution().key_of(point)?))
    }

    /// The class at a world point.
    fn class_at_point(&self, point: &Point3<f64>) -> Result<VoxelClass> {
        Ok(self.class_at(self.resolution().key_of(point)?))
    }

    /// Every measure of a voxel.
    fn measures_at(&self, key: VoxelKey) -> Measures {
        self.measure_config().measures(self.memberships_at(key))
    }

    /// The class of a voxel.
    fn class_at(&self, key: VoxelKey) -> VoxelClass {
        self.measure_config().classify(self.memberships_at(key))
    }
}

/// What a map that integrates observations adds to [`VoxelMap`]: the same point clouds and
/// interval depth images for every map, so that experiments can feed identical data to each map
/// and compare them fairly. Read-only maps do not implement it, so writing to one does not
/// compile.
pub trait VoxelMapMut: VoxelMap {
    /// Integrates one point cloud as one scan. On error the map is unchanged.
    fn integrate_cloud(
        &mut self,
        cloud: &PointCloud,
        options: &IntegrationOptions,
    ) -> Result<IntegrationStats>;

    /// Integrates point clouds, each as one scan, in order: the map becomes, bit for bit, what
    /// integrating them one after another with [`VoxelMapMut::integrate_cloud`] makes it.
    /// Returns each scan's statistics.
    ///
    /// This crate's maps walk the rays of several scans side by side and apply them in order,
    /// which is faster for many small scans (a list of depth images, say), and check every
    /// scan before integrating any, so on error the map is unchanged. The default integrates
    /// the scans one by one and stops at the first error, leaving the scans before it
    /// integrated.
    fn integrate_clouds(
        &mut self,
        clouds: &[PointCloud],
        options: &IntegrationOptions,
    ) -> Result<Vec<IntegrationStats>> {
        clouds
            .iter()
            .map(|cloud| self.integrate_cloud(cloud, options))
            .collect()
    }

    /// Integrates one interval depth image as one scan. On error the map is unchanged.
    fn integrate_depth(
        &mut self,
        frame: &DepthFrame,
        options: &IntegrationOptions,
    ) -> Result<IntegrationStats>;
}
