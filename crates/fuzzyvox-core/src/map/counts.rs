use serde::{Deserialize, Serialize};

use crate::measures::VoxelClass;
use crate::storage::BlockGrid;

/// Voxel counts per class over a map's allocated blocks.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct VoxelCounts {
    /// Occupied voxels.
    pub occupied: usize,
    /// Free voxels.
    pub free: usize,
    /// Ambiguous voxels.
    pub ambiguous: usize,
    /// Voxels inside allocated blocks that are unknown (including those no evidence reached).
    pub unknown: usize,
}

impl VoxelCounts {
    /// The count for one class.
    pub fn get(&self, class: VoxelClass) -> usize {
        match class {
            VoxelClass::Occupied => self.occupied,
            VoxelClass::Free => self.free,
            VoxelClass::Ambiguous => self.ambiguous,
            VoxelClass::Unknown => self.unknown,
        }
    }

    /// Sums the per-block class counts of a grid (no cell is visited).
    pub fn of_grid<C: Copy + Default>(grid: &BlockGrid<C>) -> Self {
        let mut counts = Self::default();
        for (_, block) in grid.blocks() {
            counts.occupied += block.summary.get(VoxelClass::Occupied);
            counts.free += block.summary.get(VoxelClass::Free);
            counts.ambiguous += block.summary.get(VoxelClass::Ambiguous);
            counts.unknown += block.summary.get(VoxelClass::Unknown);
        }
        counts
    }
}
