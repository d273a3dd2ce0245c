//! Blocks that store each distinct value once: a map's long-lived storage.
//!
//! A scan gives most voxels of a block one of a handful of values (never observed, missed once,
//! hit once), so a dense 8×8×8 block spends most of its bytes repeating them. A packed block
//! keeps up to 16 distinct values with four bits per cell inside itself, a palette of up to 256
//! values with one byte per cell beside it, and the dense cells only when it holds more
//! distinct values than that. Updates unpack a block into a dense [`Block`], change it there
//! and pack it again, so every integrator written against dense blocks works unchanged; reads
//! go through [`PackedBlock::get`]. Values are compared by their bits ([`CellBits`]), so NaN
//! cells pack like any other value.

use rayon::prelude::*;
use rustc_hash::FxHashMap;

use super::block::{BLOCK_CELLS, Block, ClassCounts};
use super::grid::BlockGrid;
use super::key::{BlockKey, VoxelKey};
use super::region::KeyBox;
use crate::class::VoxelClass;

/// A cell value's identity for packing: equal bits, equal value.
pub trait CellBits: Copy + Default + Send + Sync {
    /// The value's bits.
    fn bits(&self) -> u64;
}

/// Most distinct values a palette block holds.
const PALETTE_LIMIT: usize = 256;

/// Most distinct values a small block holds (four bits per cell).
const SMALL_LIMIT: usize = 16;

/// The cells of one block, stored by how many distinct values they hold.
#[derive(Clone, Debug)]
#[expect(
    clippy::large_enum_variant,
    reason = "small blocks are kept inline on purpose: most reads then follow no pointer"
)]
enum Cells<C> {
    /// Up to sixteen distinct values (one, for a block whose cells all agree), four bits per
    /// cell, all inside the block: a read follows no pointer, and reads of most blocks take
    /// the same path.
    Small {
        values: [C; SMALL_LIMIT],
        codes: [u8; BLOCK_CELLS / 2],
    },
    /// Up to [`PALETTE_LIMIT`] distinct values; each cell is an index into them.
    Palette {
        values: Box<[C]>,
        index: Box<[u8; BLOCK_CELLS]>,
    },
    /// More distinct values than a palette holds.
    Dense(Box<[C; BLOCK_CELLS]>),
}

/// One packed block with its class counts.
#[derive(Clone, Debug)]
pub struct PackedBlock<C> {
    cells: Cells<C>,
    /// Class counts of the cells; kept current by the map that owns the block.
    pub summary: ClassCounts,
}

impl<C: CellBits> PackedBlock<C> {
    /// A block of default cells, all counted as unknown.
    fn unknown() -> Self {
        let block = Block::<C>::default();
        Self {
            cells: Cells::Small {
                values: [C::default(); SMALL_LIMIT],
                codes: [0; BLOCK_CELLS / 2],
            },
            summary: block.summary,
        }
    }

    /// Packs a dense block.
    pub fn pack(block: &Block<C>) -> Self {
        Self {
            cells: pack_cells(&block.cells),
            summary: block.summary,
        }
    }

    /// Cell `i` (0..512, as [`VoxelKey::cell_index`] numbers them).
    #[inline]
    pub fn get(&self, i: usize) -> C {
        match &self.cells {
            Cells::Small { values, codes } => {
                let code = codes
                    .get(i / 2)
                    .map_or(0, |byte| (byte >> (4 * (i % 2))) & 15);
                values[usize::from(code)]
            }
            Cells::Palette { values, index } => index
                .get(i)
                .and_then(|&k| values.get(usize::from(k)))
                .copied()
                .unwrap_or_default(),
            Cells::Dense(cells) => cells.get(i).copied().unwrap_or_default(),
        }
    }

    /// Writes the dense cells and the class counts into `out`.
    pub fn unpack_into(&self, out: &mut Block<C>) {
        match &self.cells {
            Cells::Small { values, codes } => {
                for (i, cell) in out.cells.iter_mut().enumerate() {
                    let code = (codes[i / 2] >> (4 * (i % 2))) & 15;
                    *cell = values[usize::from(code)];
                }
            }
            Cells::Palette { values, index } => {
                for (cell, &k) in out.cells.iter_mut().zip(index.iter()) {
                    *cell = values.get(usize::from(k)).copied().unwrap_or_default();
                }
            }
            Cells::Dense(cells) => out.cells = **cells,
        }
        out.summary = self.summary;
    }

    /// The dense block.
    pub fn unpack(&self) -> Block<C> {
        let mut block = Block::default();
        self.unpack_into(&mut block);
        block
    }

    /// Every cell in order.
    pub fn iter(&self) -> impl Iterator<Item = C> + '_ {
        (0..BLOCK_CELLS).map(move |i| self.get(i))
    }

    /// Heap bytes the cells take beside the block itself.
    fn heap_bytes(&self) -> usize {
        match &self.cells {
            Cells::Small { .. } => 0,
            Cells::Palette { values, .. } => {
                std::mem::size_of_val(&**values) + std::mem::size_of::<[u8; BLOCK_CELLS]>()
            }
            Cells::Dense(_) => std::mem::size_of::<[C; BLOCK_CELLS]>(),
        }
    }
}

/// Packs dense cells: inside the block, in a palette, or as they are.
fn pack_cells<C: CellBits>(cells: &[C; BLOCK_CELLS]) -> Cells<C> {
    // Distinct values in order of first appearance, found through a small open-addressing
    // table of their bits (twice the palette's size, on the stack); runs of one value (the
    // common case) skip the lookup.
    const SLOTS: usize = 2 * PALETTE_LIMIT;
    let mut table = [(0u64, u16::MAX); SLOTS];
    let mut values: Vec<C> = Vec::new();
    let mut index = Box::new([0u8; BLOCK_CELLS]);
    let mut last: Option<(u64, u8)> = None;
    for (i, cell) in cells.iter().enumerate() {
        let bits = cell.bits();
        let k = match last {
            Some((seen, k)) if seen == bits => k,
            _ => {
                let mut slot = (bits.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 55) as usize % SLOTS;
                let k = loop {
                    match table[slot] {
                        (_, u16::MAX) => {
                            if values.len() == PALETTE_LIMIT {
                                return Cells::Dense(Box::new(*cells));
                            }
                            let k = values.len() as u8;
                            values.push(*cell);
                            table[slot] = (bits, u16::from(k));
                            break k;
                        }
                        (seen, k) if seen == bits => break k as u8,
                        _ => slot = (slot + 1) % SLOTS,
                    }
                };
                last = Some((bits, k));
                k
            }
        };
        index[i] = k;
    }
    if values.len() <= SMALL_LIMIT {
        let mut small = [C::default(); SMALL_LIMIT];
        small[..values.len()].copy_from_slice(&values);
        let mut codes = [0u8; BLOCK_CELLS / 2];
        for (i, &k) in index.iter().enumerate() {
            codes[i / 2] |= k << (4 * (i % 2));
        }
        return Cells::Small {
            values: small,
            codes,
        };
    }
    Cells::Palette {
        values: values.into_boxed_slice(),
        index,
    }
}

/// A sparse grid of packed 8×8×8 blocks: [`BlockGrid`]'s layout, index and write versions,
/// with blocks that store each distinct value once.
#[derive(Clone, Debug, Default)]
pub struct PackedGrid<C> {
    index: FxHashMap<BlockKey, usize>,
    keys: Vec<BlockKey>,
    blocks: Vec<PackedBlock<C>>,
    /// Per block (in storage order), the version of its last write.
    written: Vec<u64>,
    /// Advanced by every call that may write cells.
    version: u64,
}

impl<C: CellBits> PackedGrid<C> {
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

    /// Packs every block of a dense grid (class counts as the dense blocks hold them).
    pub fn from_dense(grid: &BlockGrid<C>) -> Self {
        let mut packed = Self::new();
        for key in grid.sorted_block_keys() {
            if let Some(block) = grid.block(key) {
                packed.insert_block(key, block);
            }
        }
        packed
    }

    /// The grid's version: advanced by every call that may write cells.
    pub fn version(&self) -> u64 {
        self.version
    }

    /// Keys of the blocks written after `version`, in ascending order (see
    /// [`BlockGrid::changed_since`]).
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

    /// Number of allocated blocks.
    pub fn block_count(&self) -> usize {
        self.blocks.len()
    }

    /// The block at `key`, if allocated.
    #[inline]
    pub fn block(&self, key: BlockKey) -> Option<&PackedBlock<C>> {
        self.index.get(&key).map(|&i| &self.blocks[i])
    }

    /// The cell at `key`, if its block is allocated.
    #[inline]
    pub fn cell(&self, key: VoxelKey) -> Option<C> {
        self.block(key.block()).map(|b| b.get(key.cell_index()))
    }

    /// Allocated blocks with their keys, in storage order.
    pub fn blocks(&self) -> impl ExactSizeIterator<Item = (BlockKey, &PackedBlock<C>)> {
        self.keys.iter().copied().zip(self.blocks.iter())
    }

    /// Block keys in ascending order: the canonical order for output.
    pub fn sorted_block_keys(&self) -> Vec<BlockKey> {
        let mut keys = self.keys.clone();
        keys.sort_unstable();
        keys
    }

    /// Every allocated cell with its key, in storage order.
    pub fn cells(&self) -> impl Iterator<Item = (VoxelKey, C)> + '_ {
        self.blocks().flat_map(|(key, block)| {
            block
                .iter()
                .enumerate()
                .map(move |(i, c)| (key.voxel(i), c))
        })
    }

    /// Inserts (or replaces) a block, packed.
    pub fn insert_block(&mut self, key: BlockKey, block: &Block<C>) {
        self.version += 1;
        let packed = PackedBlock::pack(block);
        match self.index.get(&key) {
            Some(&i) => {
                self.blocks[i] = packed;
                self.written[i] = self.version;
            }
            None => {
                self.index.insert(key, self.blocks.len());
                self.keys.push(key);
                self.blocks.push(packed);
                self.written.push(self.version);
            }
        }
    }

    /// Recomputes every block's class counts from its cells.
    pub fn refresh_summaries(&mut self, classify: impl Fn(&C) -> VoxelClass + Sync) {
        self.blocks.par_iter_mut().for_each(|b| {
            let mut counts = [0usize; 4];
            let mut last: Option<(u64, VoxelClass)> = None;
            for c in b.iter() {
                let class = match last {
                    Some((bits, class)) if bits == c.bits() => class,
                    _ => {
                        let class = classify(&c);
                        last = Some((c.bits(), class));
                        class
                    }
                };
                counts[class.index()] += 1;
            }
            b.summary = ClassCounts::from_counts(counts);
        });
    }

    /// [`BlockGrid::update_blocks`] for packed blocks: each block `sources` names is unpacked,
    /// updated by `update` (in parallel, each block by one thread, so the result does not
    /// depend on the thread count) and packed again when it changed. Missing blocks are
    /// allocated in key order first. Returns the sum of the counts `update` returns.
    pub fn update_blocks<S: Sync>(
        &mut self,
        mut sources: Vec<(BlockKey, &S)>,
        update: impl Fn(&mut Block<C>, &S) -> (usize, bool) + Sync,
    ) -> usize {
        sources.sort_unstable_by_key(|(key, _)| *key);
        self.version += 1;
        let version = self.version;
        let mut positions = Vec::with_capacity(sources.len());
        for (key, _) in &sources {
            let position = match self.index.get(key) {
                Some(&i) => i,
                None => {
                    let i = self.blocks.len();
                    self.index.insert(*key, i);
                    self.keys.push(*key);
                    self.blocks.push(PackedBlock::unknown());
                    self.written.push(version);
                    i
                }
            };
            positions.push(position);
        }
        let mut by_position: Vec<Option<&S>> = vec![None; self.blocks.len()];
        for (position, (_, source)) in positions.iter().zip(&sources) {
            by_position[*position] = Some(*source);
        }
        let results: Vec<(usize, bool)> = self
            .blocks
            .par_iter_mut()
            .zip(by_position.par_iter())
            .map_init(Block::<C>::default, |scratch, (block, source)| {
                let Some(source) = source else {
                    return (0, false);
                };
                block.unpack_into(scratch);
                let (count, changed) = update(scratch, source);
                if changed {
                    *block = PackedBlock::pack(scratch);
                }
                (count, changed)
            })
            .collect();
        let mut total = 0;
        for (position, (count, changed)) in results.into_iter().enumerate() {
            total += count;
            if changed {
                self.written[position] = version;
            }
        }
        total
    }

    /// Whether any voxel of `region` is of class `class` (see [`BlockGrid::any_in_box`]).
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
            |block, i| classify(&block.get(i)),
        )
    }

    /// Heap memory held by the grid, in bytes (blocks and their cells, key list, versions and
    /// hash index).
    pub fn memory_bytes(&self) -> usize {
        let key = std::mem::size_of::<BlockKey>();
        let entry = key + std::mem::size_of::<usize>() + 1;
        self.blocks.capacity() * std::mem::size_of::<PackedBlock<C>>()
            + self
                .blocks
                .iter()
                .map(PackedBlock::heap_bytes)
                .sum::<usize>()
            + self.keys.capacity() * key
            + self.written.capacity() * std::mem::size_of::<u64>()
            + self.index.capacity() * entry
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    impl CellBits for u32 {
        fn bits(&self) -> u64 {
            u64::from(*self)
        }
    }

    fn classify(c: &u32) -> VoxelClass {
        match c {
            0 => VoxelClass::Unknown,
            1 => VoxelClass::Free,
            _ => VoxelClass::Occupied,
        }
    }

    fn block_of(f: impl Fn(usize) -> u32) -> Block<u32> {
        let mut block = Block::default();
        for (i, c) in block.cells.iter_mut().enumerate() {
            *c = f(i);
        }
        block.refresh_summary(classify);
        block
    }

    #[test]
    fn blocks_pack_by_their_distinct_values_and_read_back() {
        for (f, kind) in [
            (Box::new(|_| 7u32) as Box<dyn Fn(usize) -> u32>, "small"),
            (Box::new(|i| (i % 5) as u32), "small"),
            (Box::new(|i| (i % 17) as u32), "palette"),
            (Box::new(|i| (i % 16) as u32 * 3), "small"),
            (Box::new(|i| (i % 256) as u32 + 1), "palette"),
            (Box::new(|i| i as u32), "dense"),
        ] {
            let block = block_of(f);
            let packed = PackedBlock::pack(&block);
            let found = match packed.cells {
                Cells::Small { .. } => "small",
                Cells::Palette { .. } => "palette",
                Cells::Dense(_) => "dense",
            };
            assert_eq!(found, kind);
            assert_eq!(packed.unpack(), block);
            assert!(packed.iter().eq(block.cells.iter().copied()));
        }
    }

    #[test]
    fn updates_pack_again_and_record_versions() {
        let mut grid = PackedGrid::<u32>::new();
        let (a, b) = (BlockKey::new(0, 0, 0), BlockKey::new(-3, 2, 1));
        let write = |block: &mut Block<u32>, s: &u32| {
            let changed = block.cells[5] != *s;
            block.summary.moved(classify(&block.cells[5]), classify(s));
            block.cells[5] = *s;
            (1, changed)
        };
        let start = grid.version();
        assert_eq!(grid.update_blocks(vec![(b, &2), (a, &1)], write), 2);
        let mut both = vec![a, b];
        both.sort_unstable();
        assert_eq!(grid.changed_since(start), both);
        assert_eq!(grid.cell(a.voxel(5)), Some(1));
        assert_eq!(grid.cell(b.voxel(5)), Some(2));
        assert_eq!(grid.cell(b.voxel(6)), Some(0));
        assert_eq!(
            grid.block(b).map(|x| x.summary.get(VoxelClass::Occupied)),
            Some(1)
        );
        let unchanged = grid.version();
        grid.update_blocks(vec![(a, &1)], write);
        assert!(grid.changed_since(unchanged).is_empty());
        assert_eq!(grid.cells().filter(|(_, c)| *c != 0).count(), 2);
        let whole = KeyBox::new(a.voxel(0), a.voxel(BLOCK_CELLS - 1));
        assert!(grid.any_in_box(&whole, VoxelClass::Free, classify));
        assert!(!grid.any_in_box(&whole, VoxelClass::Occupied, classify));
        // Packing a dense grid keeps every cell.
        let mut dense = BlockGrid::<u32>::new();
        *dense.cell_or_insert(VoxelKey::new(3, -9, 4)) = 9;
        let packed = PackedGrid::from_dense(&dense);
        assert_eq!(packed.cell(VoxelKey::new(3, -9, 4)), Some(9));
        assert!(packed.memory_bytes() < dense.memory_bytes());
    }
}
