use rayon::prelude::*;
use rustc_hash::FxHashMap;

use super::block::{BLOCK_CELLS, Block};
use super::key::{BlockKey, VoxelKey};
use super::region::KeyBox;
use crate::class::VoxelClass;

/// A sparse grid of dense 8×8×8 blocks, generic over the cell type.
///
/// Blocks are stored in a `Vec` in allocation order with a hash index from block key to
/// position. Nothing observable depends on that order: iteration in key order is available
/// through [`BlockGrid::sorted_block_keys`], and saved files use it.
///
/// The grid counts its writes: every call that may change cells advances a version, and each
/// block remembers the version of its last write, so any number of consumers (a planner's cost
/// field, an exporter) can each ask which blocks changed since the version they last saw
/// ([`BlockGrid::changed_since`]) without the grid keeping a dirty set per consumer.
#[derive(Clone, Debug, Default)]
pub struct BlockGrid<C> {
    index: FxHashMap<BlockKey, usize>,
    keys: Vec<BlockKey>,
    blocks: Vec<Box<Block<C>>>,
    /// Per block (in storage order), the version of its last write.
    written: Vec<u64>,
    /// Advanced by every call that may write cells.
    version: u64,
}

impl<C: Copy + Default> BlockGrid<C> {
    /// An empty grid.
    pub fn new() -> Self {
        Self {
            index: FxHashMap::default(),
            keys: Vec::new(),
            blocks: Vec::new(),
            written: Vec::new(),
            version: 0,
        }
    }

    /// The grid's version: advanced by every call that may write cells.
    pub fn version(&self) -> u64 {
        self.version
    }

    /// Keys of the blocks written after `version` (allocated ones included), in ascending
    /// order. `changed_since(0)` lists every block written since the grid was created.
    pub fn changed_since(&self, version: u64) -> Vec<BlockKey> {
        let mut keys: Vec<BlockKey> = self
            .keys
            .iter()
            .zip(&self.written)
            .filter(|(_, written)| **written > version)
            .map(|(key, _)| *key)
            .collect();
        keys.sort_unstable();
        keys
    }

    /// Starts a write: advances the version and returns it.
    pub(super) fn begin_write(&mut self) -> u64 {
        self.version += 1;
        self.version
    }

    /// Records a write to the block at `position` in the current version.
    pub(super) fn mark(&mut self, position: usize) {
        self.written[position] = self.version;
    }

    /// Number of allocated blocks.
    pub fn block_count(&self) -> usize {
        self.blocks.len()
    }

    /// Number of allocated cells (blocks × 512).
    pub fn cell_count(&self) -> usize {
        self.blocks.len() * BLOCK_CELLS
    }

    /// Whether no block is allocated.
    pub fn is_empty(&self) -> bool {
        self.blocks.is_empty()
    }

    /// Position of a block in the storage order, if allocated.
    #[inline]
    pub fn position(&self, key: BlockKey) -> Option<usize> {
        self.index.get(&key).copied()
    }

    /// The block at `key`, if allocated.
    #[inline]
    pub fn block(&self, key: BlockKey) -> Option<&Block<C>> {
        self.position(key).map(|i| &*self.blocks[i])
    }

    /// The block at `key` for writing, if allocated.
    #[inline]
    pub fn block_mut(&mut self, key: BlockKey) -> Option<&mut Block<C>> {
        let i = self.position(key)?;
        self.begin_write();
        self.mark(i);
        Some(&mut *self.blocks[i])
    }

    /// The position of the block at `key`, allocating an empty block when there is none.
    pub fn ensure_block(&mut self, key: BlockKey) -> usize {
        if let Some(&i) = self.index.get(&key) {
            return i;
        }
        self.begin_write();
        self.push(key, Box::default())
    }

    /// Appends a block that is not allocated yet, written in the current version.
    fn push(&mut self, key: BlockKey, block: Box<Block<C>>) -> usize {
        let i = self.blocks.len();
        self.index.insert(key, i);
        self.keys.push(key);
        self.blocks.push(block);
        self.written.push(self.version);
        i
    }

    /// Inserts (or replaces) a whole block.
    pub fn insert_block(&mut self, key: BlockKey, block: Box<Block<C>>) {
        self.begin_write();
        match self.index.get(&key) {
            Some(&i) => {
                self.blocks[i] = block;
                self.mark(i);
            }
            None => {
                self.push(key, block);
            }
        }
    }

    /// The block at a storage position.
    #[inline]
    pub fn block_at(&self, position: usize) -> &Block<C> {
        &self.blocks[position]
    }

    /// The block at a storage position, for writing.
    #[inline]
    pub fn block_at_mut(&mut self, position: usize) -> &mut Block<C> {
        self.begin_write();
        self.mark(position);
        &mut self.blocks[position]
    }

    /// Cell `cell` of the block at a storage position, for writing, without recording the
    /// write: for a writer that has already recorded it ([`super::AccessorMut`] records each
    /// block once when it enters it).
    #[inline]
    pub(super) fn cell_at_mut_unrecorded(&mut self, position: usize, cell: usize) -> &mut C {
        &mut self.blocks[position].cells[cell]
    }

    /// The cell at `key`, if its block is allocated.
    #[inline]
    pub fn cell(&self, key: VoxelKey) -> Option<&C> {
        self.block(key.block()).map(|b| &b.cells[key.cell_index()])
    }

    /// The cell at `key` for writing, allocating its block when needed.
    #[inline]
    pub fn cell_or_insert(&mut self, key: VoxelKey) -> &mut C {
        let i = self.ensure_block(key.block());
        self.begin_write();
        self.mark(i);
        &mut self.blocks[i].cells[key.cell_index()]
    }

    /// Allocated blocks with their keys, in storage order.
    pub fn blocks(&self) -> impl ExactSizeIterator<Item = (BlockKey, &Block<C>)> {
        self.keys
            .iter()
            .copied()
            .zip(self.blocks.iter().map(|b| &**b))
    }

    /// Allocated blocks with their keys, in storage order, for writing. Each item is a distinct
    /// block, so the slice can be split across threads. Every block counts as written.
    pub fn blocks_mut(&mut self) -> (&[BlockKey], &mut [Box<Block<C>>]) {
        let version = self.begin_write();
        self.written.fill(version);
        (&self.keys, &mut self.blocks)
    }

    /// Block keys in ascending order: the canonical order for output.
    pub fn sorted_block_keys(&self) -> Vec<BlockKey> {
        let mut keys = self.keys.clone();
        keys.sort_unstable();
        keys
    }

    /// Every allocated cell with its key, in storage order.
    pub fn cells(&self) -> impl Iterator<Item = (VoxelKey, &C)> {
        self.blocks().flat_map(|(key, block)| {
            block
                .cells
                .iter()
                .enumerate()
                .map(move |(i, c)| (key.voxel(i), c))
        })
    }

    /// Every allocated cell inside `region`, with its key.
    pub fn cells_in_box<'a>(
        &'a self,
        region: &'a KeyBox,
    ) -> impl Iterator<Item = (VoxelKey, &'a C)> + 'a {
        self.blocks_meeting(region)
            .into_iter()
            .flat_map(move |(key, block)| {
                block
                    .cells
                    .iter()
                    .enumerate()
                    .map(move |(i, c)| (key.voxel(i), c))
                    .filter(move |(k, _)| region.contains(*k))
            })
    }

    /// Whether any voxel of `region` is of class `class`, answered from the per-block class
    /// counts wherever a block lies wholly inside or has no cell of that class, and from the
    /// cells (classified by `classify`) only for blocks cut by the box boundary. Voxels in
    /// unallocated blocks count as [`VoxelClass::Unknown`].
    pub fn any_in_box(
        &self,
        region: &KeyBox,
        class: VoxelClass,
        classify: impl Fn(&C) -> VoxelClass,
    ) -> bool {
        super::region::any_of_class_in_box(
            region,
            class,
            self.blocks.len(),
            |key| self.block(key),
            self.blocks(),
            |block| block.summary,
            |block, i| block.cells.get(i).map_or(VoxelClass::Unknown, &classify),
        )
    }

    /// Allocated blocks that meet `region`, visiting whichever is smaller: the box's blocks or
    /// the allocated ones.
    fn blocks_meeting(&self, region: &KeyBox) -> Vec<(BlockKey, &Block<C>)> {
        if region.block_count() <= self.blocks.len() as u128 {
            region
                .blocks()
                .filter_map(|key| self.block(key).map(|b| (key, b)))
                .collect()
        } else {
            self.blocks()
                .filter(|(key, _)| region.meets_block(*key))
                .collect()
        }
    }

    /// Updates every block that has a counterpart in `source` with `update(block, source_block)`,
    /// in parallel, each block by one thread (so the result does not depend on the thread
    /// count). Missing blocks are allocated first. `update` returns a count and whether it
    /// changed the block; returns the sum of the counts.
    pub fn update_from<S: Copy + Default + Sync>(
        &mut self,
        source: &BlockGrid<S>,
        update: impl Fn(&mut Block<C>, &Block<S>) -> (usize, bool) + Sync,
    ) -> usize
    where
        C: Send + Sync,
    {
        self.update_blocks(source.blocks().collect(), update)
    }

    /// Like [`BlockGrid::update_from`] for any per-block payload: `sources` pairs block keys
    /// with what each block is updated from. Missing blocks are allocated in key order, so
    /// the storage order does not depend on the order of `sources`. `update` returns a count
    /// and whether it changed the block: a block counts as written when it changed or was
    /// allocated, so that consumers of [`changed_since`](BlockGrid::changed_since) skip blocks
    /// whose cells a scan left as they were (repeated evidence at a bound, say). Returns the
    /// sum of the counts.
    pub fn update_blocks<S: Sync>(
        &mut self,
        mut sources: Vec<(BlockKey, &S)>,
        update: impl Fn(&mut Block<C>, &S) -> (usize, bool) + Sync,
    ) -> usize
    where
        C: Send + Sync,
    {
        sources.sort_unstable_by_key(|(key, _)| *key);
        self.begin_write();
        let missing: Vec<BlockKey> = sources
            .iter()
            .map(|(key, _)| *key)
            .filter(|&key| self.position(key).is_none())
            .collect();
        // The (page-faulting) allocations run in parallel; the insertions are cheap.
        let fresh: Vec<Box<Block<C>>> = missing.par_iter().map(|_| Box::default()).collect();
        for (key, block) in missing.into_iter().zip(fresh) {
            self.push(key, block);
        }
        let mut by_position: Vec<Option<&S>> = vec![None; self.blocks.len()];
        for (key, source) in sources {
            if let Some(position) = self.position(key) {
                by_position[position] = Some(source);
            }
        }
        let results: Vec<(usize, bool)> = self
            .blocks
            .par_iter_mut()
            .zip(by_position.par_iter())
            .map(|(block, source)| source.map_or((0, false), |s| update(block, s)))
            .collect();
        let mut total = 0;
        for (position, (count, changed)) in results.into_iter().enumerate() {
            total += count;
            if changed {
                self.mark(position);
            }
        }
        total
    }

    /// Heap memory held by the grid, in bytes (blocks, key list and hash index).
    pub fn memory_bytes(&self) -> usize {
        let block = std::mem::size_of::<Block<C>>() + std::mem::size_of::<Box<Block<C>>>();
        let key = std::mem::size_of::<BlockKey>();
        // hashbrown stores one control byte per bucket beside each (key, value) pair.
        let entry = key + std::mem::size_of::<usize>() + 1;
        self.blocks.capacity() * std::mem::size_of::<Box<Block<C>>>()
            + self.blocks.len() * (block - std::mem::size_of::<Box<Block<C>>>())
            + self.keys.capacity() * key
            + self.written.capacity() * std::mem::size_of::<u64>()
            + self.index.capacity() * entry
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn classify(c: &u8) -> VoxelClass {
        match c {
            0 => VoxelClass::Unknown,
            1 => VoxelClass::Free,
            _ => VoxelClass::Occupied,
        }
    }

    #[test]
    fn cells_read_back_and_blocks_are_shared() {
        let mut grid = BlockGrid::<u8>::new();
        *grid.cell_or_insert(VoxelKey::new(-1, -1, -1)) = 2;
        *grid.cell_or_insert(VoxelKey::new(-8, -8, -8)) = 1;
        assert_eq!(grid.block_count(), 1);
        assert_eq!(grid.cell(VoxelKey::new(-1, -1, -1)), Some(&2));
        assert_eq!(grid.cell(VoxelKey::new(0, 0, 0)), None);
        assert_eq!(grid.cells().filter(|(_, c)| **c != 0).count(), 2);
    }

    #[test]
    fn box_queries_use_summaries_and_partial_blocks() {
        let mut grid = BlockGrid::<u8>::new();
        for x in 0..16 {
            *grid.cell_or_insert(VoxelKey::new(x, 0, 0)) = 1;
        }
        *grid.cell_or_insert(VoxelKey::new(12, 3, 3)) = 2;
        let (keys, blocks) = grid.blocks_mut();
        assert_eq!(keys.len(), 2);
        for b in blocks.iter_mut() {
            b.refresh_summary(classify);
        }
        let occ = VoxelClass::Occupied;
        let whole = KeyBox::new(VoxelKey::new(0, 0, 0), VoxelKey::new(15, 7, 7));
        assert!(grid.any_in_box(&whole, occ, classify));
        let partial_hit = KeyBox::new(VoxelKey::new(12, 3, 3), VoxelKey::new(12, 3, 3));
        assert!(grid.any_in_box(&partial_hit, occ, classify));
        let partial_miss = KeyBox::new(VoxelKey::new(8, 0, 0), VoxelKey::new(11, 7, 7));
        assert!(!grid.any_in_box(&partial_miss, occ, classify));
        assert!(grid.any_in_box(&partial_miss, VoxelClass::Free, classify));
        // Unallocated space is unknown; fully observed space is not.
        let outside = KeyBox::new(VoxelKey::new(100, 0, 0), VoxelKey::new(101, 0, 0));
        assert!(grid.any_in_box(&outside, VoxelClass::Unknown, classify));
        let row = KeyBox::new(VoxelKey::new(0, 0, 0), VoxelKey::new(15, 0, 0));
        assert!(!grid.any_in_box(&row, VoxelClass::Unknown, classify));
        let huge = KeyBox::new(
            VoxelKey::new(-1000, -1000, -1000),
            VoxelKey::new(1000, 1000, 1000),
        );
        assert!(grid.any_in_box(&huge, occ, classify));
        assert_eq!(grid.cells_in_box(&row).count(), 16);
        assert_eq!(grid.cells_in_box(&huge).count(), 2 * 512);
    }

    #[test]
    fn versions_name_the_blocks_written_since() {
        let mut grid = BlockGrid::<u8>::new();
        let start = grid.version();
        *grid.cell_or_insert(VoxelKey::new(0, 0, 0)) = 1;
        let (a, b) = (
            VoxelKey::new(0, 0, 0).block(),
            VoxelKey::new(20, 0, 0).block(),
        );
        assert_eq!(grid.changed_since(start), vec![a]);
        let after_first = grid.version();
        assert!(grid.changed_since(after_first).is_empty());
        // A batch update marks the blocks it allocated or changed, not those it left alone.
        let source = 7u8;
        let write = |block: &mut crate::storage::Block<u8>, s: &u8| {
            let changed = block.cells[0] != *s;
            block.cells[0] = *s;
            (1, changed)
        };
        grid.update_blocks(vec![(b, &source)], write);
        assert_eq!(grid.changed_since(after_first), vec![b]);
        assert_eq!(grid.changed_since(start), vec![a, b]);
        let unchanged = grid.version();
        grid.update_blocks(vec![(b, &source)], write);
        assert!(grid.changed_since(unchanged).is_empty());
        grid.update_blocks(vec![(b, &9)], write);
        assert_eq!(grid.changed_since(unchanged), vec![b]);
        // Reads leave the version alone; every write path advances it.
        let read = grid.version();
        let _ = grid.cell(VoxelKey::new(0, 0, 0));
        let _ = grid.block(a);
        assert_eq!(grid.version(), read);
        grid.block_mut(a);
        assert_eq!(grid.changed_since(read), vec![a]);
        let again = grid.version();
        grid.blocks_mut();
        assert_eq!(grid.changed_since(again), vec![a, b]);
        let last = grid.version();
        let position = grid.position(b).unwrap();
        grid.block_at_mut(position);
        grid.insert_block(a, Box::default());
        assert_eq!(grid.changed_since(last), vec![a, b]);
    }
}
