use serde::{Deserialize, Serialize};

use crate::measures::VoxelClass;
use crate::storage::{BlockGrid, CellBits, ClassCounts, PackedGrid};

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
        Self::of_summaries(grid.blocks().map(|(_, block)| &block.summary))
    }

    /// Sums the per-block class counts of a packed grid (no cell is visited).
    pub fn of_packed<C: CellBits>(grid: &PackedGrid<C>) -> Self {
        Self::of_summaries(grid.blocks().map(|(_, block)| &block.summary))
    }

    fn of_summaries<'a>(summaries: impl Iterator<Item = &'a ClassCounts>) -> Self {
        let mut counts = Self::default();
        for summary in summaries {
            counts.occupied += summary.get(VoxelClass::Occupied);
            counts.free += summary.get(VoxelClass::Free);
            counts.ambiguous += summary.get(VoxelClass::Ambiguous);
            counts.unknown += summary.get(VoxelClass::Unknown);
        }
        counts
    }
}
