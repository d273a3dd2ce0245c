//! The leaves of OctoMap trees, as the `.ot` reader makes them and [`OcTreeMap`](super::OcTreeMap)
//! hands them out.

use fuzzyvox_core::map::LogOdds;
use fuzzyvox_core::measures::Memberships;
use fuzzyvox_core::storage::VoxelKey;

use super::keys::TREE_DEPTH;

/// A leaf of an OctoMap tree with its occupancy log-odds: a cube of `side()³` voxels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OctreeLeaf {
    /// The fuzzyvox key (OctoMap key − 32768) of the cube's lowest-corner voxel.
    pub key: VoxelKey,
    /// Tree depth, 0..=16: the leaf covers `2^(16 - depth)` voxels per side (one at depth 16).
    pub depth: u8,
    /// Occupancy log-odds, `ln(p / (1 - p))`.
    pub log_odds: f32,
}

impl OctreeLeaf {
    /// Voxels per side of the cube.
    pub fn side(&self) -> u32 {
        1 << (TREE_DEPTH - self.depth.min(TREE_DEPTH))
    }

    /// Voxels in the cube.
    pub fn voxel_count(&self) -> u64 {
        u64::from(self.side()).pow(3)
    }

    /// The memberships every voxel of the cube has: `μO = p`, `μE = 1 - p`.
    pub fn memberships(&self) -> Memberships {
        LogOdds(self.log_odds).memberships()
    }
}
