use nalgebra::Point3;

use super::block::ClassCounts;
use super::key::{BlockKey, Resolution, VoxelKey};
use crate::class::VoxelClass;
use crate::error::Result;

/// An axis-aligned box of voxel keys, bounds inclusive.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct KeyBox {
    /// Smallest key on each axis.
    pub min: VoxelKey,
    /// Largest key on each axis.
    pub max: VoxelKey,
}

impl KeyBox {
    /// The box spanned by two keys (in any order).
    pub fn new(a: VoxelKey, b: VoxelKey) -> Self {
        Self {
            min: VoxelKey::new(a.x.min(b.x), a.y.min(b.y), a.z.min(b.z)),
            max: VoxelKey::new(a.x.max(b.x), a.y.max(b.y), a.z.max(b.z)),
        }
    }

    /// The voxels that meet the world-space box with corners `a` and `b`.
    pub fn from_points(resolution: &Resolution, a: &Point3<f64>, b: &Point3<f64>) -> Result<Self> {
        Ok(Self::new(resolution.key_of(a)?, resolution.key_of(b)?))
    }

    /// Whether `key` lies inside.
    #[inline]
    pub fn contains(&self, key: VoxelKey) -> bool {
        (self.min.x..=self.max.x).contains(&key.x)
            && (self.min.y..=self.max.y).contains(&key.y)
            && (self.min.z..=self.max.z).contains(&key.z)
    }

    /// Number of voxels in the box.
    pub fn voxel_count(&self) -> u128 {
        span(self.min.x, self.max.x) * span(self.min.y, self.max.y) * span(self.min.z, self.max.z)
    }

    /// The smallest and largest block keys that the box touches.
    pub fn block_bounds(&self) -> (BlockKey, BlockKey) {
        (self.min.block(), self.max.block())
    }

    /// Number of blocks the box touches.
    pub fn block_count(&self) -> u128 {
        let (lo, hi) = self.block_bounds();
        span(lo.x, hi.x) * span(lo.y, hi.y) * span(lo.z, hi.z)
    }

    /// Whether block `block` lies entirely inside the box.
    pub fn covers_block(&self, block: BlockKey) -> bool {
        self.contains(block.origin()) && self.contains(block.voxel(super::BLOCK_CELLS - 1))
    }

    /// Whether block `block` meets the box.
    pub fn meets_block(&self, block: BlockKey) -> bool {
        let (lo, hi) = self.block_bounds();
        (lo.x..=hi.x).contains(&block.x)
            && (lo.y..=hi.y).contains(&block.y)
            && (lo.z..=hi.z).contains(&block.z)
    }

    /// Every block key the box touches, z slowest.
    pub fn blocks(&self) -> impl Iterator<Item = BlockKey> + use<> {
        let (lo, hi) = self.block_bounds();
        (lo.z..=hi.z).flat_map(move |z| {
            (lo.y..=hi.y).flat_map(move |y| (lo.x..=hi.x).map(move |x| BlockKey::new(x, y, z)))
        })
    }
}

/// Whether any voxel of `region` is of class `class` in a grid of `allocated` blocks, answered
/// from each block's class counts (`summary`) wherever a block lies wholly inside the box or
/// has no cell of that class, and from its cells (`cell_class`) only for blocks the box's
/// boundary cuts. Voxels of unallocated blocks are unknown. Visits whichever is fewer: the
/// box's blocks (through `block`) or the allocated ones (`blocks`). Shared by
/// [`BlockGrid`](super::BlockGrid) and [`PackedGrid`](super::PackedGrid).
pub(super) fn any_of_class_in_box<B: Copy>(
    region: &KeyBox,
    class: VoxelClass,
    allocated: usize,
    block: impl Fn(BlockKey) -> Option<B>,
    blocks: impl Iterator<Item = (BlockKey, B)>,
    summary: impl Fn(B) -> ClassCounts,
    cell_class: impl Fn(B, usize) -> VoxelClass,
) -> bool {
    let box_blocks = region.block_count();
    if class == VoxelClass::Unknown && box_blocks > allocated as u128 {
        // More blocks in the box than allocated in the whole grid: one is missing.
        return true;
    }
    let decide = |key: BlockKey, b: B| {
        if summary(b).get(class) == 0 {
            false
        } else if region.covers_block(key) {
            true
        } else {
            (0..super::BLOCK_CELLS)
                .any(|i| region.contains(key.voxel(i)) && cell_class(b, i) == class)
        }
    };
    if box_blocks <= allocated as u128 {
        region.blocks().any(|key| match block(key) {
            Some(b) => decide(key, b),
            None => class == VoxelClass::Unknown,
        })
    } else {
        blocks
            .filter(|(key, _)| region.meets_block(*key))
            .any(|(key, b)| decide(key, b))
    }
}

fn span(lo: i32, hi: i32) -> u128 {
    (i64::from(hi) - i64::from(lo) + 1) as u128
}
