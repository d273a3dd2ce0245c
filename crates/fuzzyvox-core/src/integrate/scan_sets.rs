use nalgebra::Point3;
use rayon::prelude::*;
use rustc_hash::FxHashMap;

use super::cloud::PointCloud;
use super::evidence::{IntegrationOptions, IntegrationStats, check_ray_length};
use super::octomap_walk::{CellSink, walk_ray_octomap_cells};
use crate::error::{Error, Result};
use crate::storage::{BLOCK_CELLS, BlockKey, KEY_LIMIT, Resolution, VoxelKey};

/// One block of a scan's sets as bitsets: bit `i % 64` of word `i / 64` is cell `i`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BlockFlags {
    /// Cells that a ray passed through.
    pub passed: [u64; BLOCK_CELLS / 64],
    /// Cells that hold an end point.
    pub hit: [u64; BLOCK_CELLS / 64],
}

impl BlockFlags {
    /// Whether a ray passed through cell `i`, and whether it holds an end point.
    #[inline]
    pub fn get(&self, i: usize) -> (bool, bool) {
        let (word, bit) = (i / 64, 1u64 << (i % 64));
        (self.passed[word] & bit != 0, self.hit[word] & bit != 0)
    }
}

/// What a scan records about the cells of one block as rays are walked: whether (or, with
/// levels, up to which level) a ray passed through a cell and an end point lies in it.
pub trait CellMarks: Copy + Default + Send {
    /// A ray of `level` passed through cell `i`.
    fn pass(&mut self, i: usize, level: u16);
    /// An end point of `level` lies in cell `i`.
    fn hit(&mut self, i: usize, level: u16);
    /// Takes in another partial record of the same block (exact: the split does not matter).
    fn unite(&mut self, other: &Self);
}

impl CellMarks for BlockFlags {
    #[inline]
    fn pass(&mut self, i: usize, _level: u16) {
        self.passed[i / 64] |= 1 << (i % 64);
    }

    #[inline]
    fn hit(&mut self, i: usize, _level: u16) {
        self.hit[i / 64] |= 1 << (i % 64);
    }

    fn unite(&mut self, other: &Self) {
        for w in 0..BLOCK_CELLS / 64 {
            self.passed[w] |= other.passed[w];
            self.hit[w] |= other.hit[w];
        }
    }
}

/// One block of a scan whose points carry levels (the alpha-cut map's nested confidence
/// cuts): per cell, the highest level of a ray that passed through it and of an end point in
/// it (0: none).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BlockLevels {
    /// Highest level of a ray that passed through each cell.
    pub passed: [u16; BLOCK_CELLS],
    /// Highest level of an end point in each cell.
    pub hit: [u16; BLOCK_CELLS],
}

impl Default for BlockLevels {
    fn default() -> Self {
        Self {
            passed: [0; BLOCK_CELLS],
            hit: [0; BLOCK_CELLS],
        }
    }
}

impl CellMarks for BlockLevels {
    #[inline]
    fn pass(&mut self, i: usize, level: u16) {
        if let Some(cell) = self.passed.get_mut(i) {
            *cell = (*cell).max(level);
        }
    }

    #[inline]
    fn hit(&mut self, i: usize, level: u16) {
        if let Some(cell) = self.hit.get_mut(i) {
            *cell = (*cell).max(level);
        }
    }

    fn unite(&mut self, other: &Self) {
        for (a, b) in self.passed.iter_mut().zip(&other.passed) {
            *a = (*a).max(*b);
        }
        for (a, b) in self.hit.iter_mut().zip(&other.hit) {
            *a = (*a).max(*b);
        }
    }
}

/// One scan's record, block by block, for the blocks that rays reached.
#[derive(Clone, Debug, Default)]
pub struct ScanBlocks<B> {
    index: BlockIndex,
    keys: Vec<BlockKey>,
    blocks: Vec<B>,
}

/// Where each reached block sits in a scan's record.
///
/// Rays from one origin stay inside the box of the origin and their end points, so a scan
/// whose box holds at most [`DENSE_INDEX_LIMIT`] blocks finds its blocks in a flat array over
/// that box (one load instead of a hash lookup each time a ray enters a block, most of a
/// walk's cost); a larger box uses a hash map.
#[derive(Clone, Debug)]
enum BlockIndex {
    Dense {
        lo: BlockKey,
        dims: [usize; 3],
        /// Position + 1 of each block of the box in the record, 0 when not reached yet.
        slots: Vec<u32>,
    },
    Sparse(FxHashMap<BlockKey, usize>),
}

impl Default for BlockIndex {
    fn default() -> Self {
        Self::Sparse(FxHashMap::default())
    }
}

/// Largest box, in blocks, indexed by a flat array (16 MiB of slots).
const DENSE_INDEX_LIMIT: usize = 1 << 22;

impl BlockIndex {
    /// An index for the blocks between `lo` and `hi` (inclusive): flat when the box is small
    /// enough, else hashed.
    fn for_box(lo: BlockKey, hi: BlockKey) -> Self {
        let span = |a: i32, b: i32| usize::try_from(i64::from(b) - i64::from(a) + 1).ok();
        let dims = [span(lo.x, hi.x), span(lo.y, hi.y), span(lo.z, hi.z)];
        match dims {
            [Some(x), Some(y), Some(z)]
                if x.checked_mul(y)
                    .and_then(|xy| xy.checked_mul(z))
                    .is_some_and(|n| n <= DENSE_INDEX_LIMIT) =>
            {
                Self::Dense {
                    lo,
                    dims: [x, y, z],
                    // Zeroed memory: pages are only touched where rays go.
                    slots: vec![0; x * y * z],
                }
            }
            _ => Self::default(),
        }
    }

    /// The slot of `key` in a flat index, if inside its box.
    #[inline]
    fn slot(lo: BlockKey, dims: [usize; 3], key: BlockKey) -> Option<usize> {
        let x = usize::try_from(key.x.wrapping_sub(lo.x)).ok()?;
        let y = usize::try_from(key.y.wrapping_sub(lo.y)).ok()?;
        let z = usize::try_from(key.z.wrapping_sub(lo.z)).ok()?;
        (x < dims[0] && y < dims[1] && z < dims[2]).then(|| x + dims[0] * (y + dims[1] * z))
    }

    #[inline]
    fn get(&self, key: BlockKey) -> Option<usize> {
        match self {
            Self::Dense { lo, dims, slots } => {
                let slot = Self::slot(*lo, *dims, key)?;
                slots.get(slot).and_then(|&p| (p as usize).checked_sub(1))
            }
            Self::Sparse(map) => map.get(&key).copied(),
        }
    }

    /// Records `position` for `key`; a key outside a flat index's box moves the index to a
    /// hash map (rays never leave the box, so this only guards against misuse).
    fn insert(&mut self, key: BlockKey, position: usize, keys: &[BlockKey]) {
        if let Self::Dense { lo, dims, slots } = self {
            match (Self::slot(*lo, *dims, key), u32::try_from(position + 1)) {
                (Some(slot), Ok(value)) => {
                    slots[slot] = value;
                    return;
                }
                _ => {
                    let map = keys.iter().enumerate().map(|(i, k)| (*k, i)).collect();
                    *self = Self::Sparse(map);
                }
            }
        }
        if let Self::Sparse(map) = self {
            map.insert(key, position);
        }
    }
}

/// One scan in the standard method's terms: per voxel, whether a ray passed through it and
/// whether an end point lies in it (a voxel with both counts as hit). Two bits per voxel keep
/// a whole scan's sets small enough to stay in cache while rays are walked.
pub type ScanSets = ScanBlocks<BlockFlags>;

/// A scan whose points carry levels: per voxel, the highest level of a ray through it and of
/// an end point in it. The scan of the points of level `k` and up passes through the voxels
/// whose ray level is at least `k` and ends in those whose end-point level is at least `k`.
pub type ScanLevels = ScanBlocks<BlockLevels>;

impl<B: CellMarks> ScanBlocks<B> {
    /// No voxel marked.
    pub fn new() -> Self {
        Self {
            index: BlockIndex::default(),
            keys: Vec::new(),
            blocks: Vec::new(),
        }
    }

    /// No voxel marked, for rays inside the box of voxel keys `lo..=hi`.
    pub(crate) fn for_box(lo: VoxelKey, hi: VoxelKey) -> Self {
        Self {
            index: BlockIndex::for_box(lo.block(), hi.block()),
            keys: Vec::new(),
            blocks: Vec::new(),
        }
    }

    /// Blocks with any voxel marked, with their keys.
    pub fn blocks(&self) -> impl ExactSizeIterator<Item = (BlockKey, &B)> {
        self.keys.iter().copied().zip(self.blocks.iter())
    }

    /// The position of block `key` in the record, added unmarked if new.
    #[inline]
    pub(crate) fn position(&mut self, key: BlockKey) -> usize {
        if let Some(position) = self.index.get(key) {
            return position;
        }
        let position = self.blocks.len();
        self.keys.push(key);
        self.blocks.push(B::default());
        self.index.insert(key, position, &self.keys);
        position
    }

    /// The marks of the block at `position` (from [`ScanBlocks::position`]).
    #[inline]
    pub(crate) fn block_at_mut(&mut self, position: usize) -> Option<&mut B> {
        self.blocks.get_mut(position)
    }

    /// The marks of block `key`, when a ray reached it.
    pub(crate) fn block(&self, key: BlockKey) -> Option<&B> {
        self.index.get(key).and_then(|i| self.blocks.get(i))
    }

    /// Unites two partial scans (exact, so the split does not matter).
    pub(crate) fn union(mut self, other: Self) -> Self {
        if self.blocks.len() < other.blocks.len() {
            return other.union(self);
        }
        for (key, marks) in other.blocks() {
            let position = self.position(key);
            if let Some(target) = self.blocks.get_mut(position) {
                target.unite(marks);
            }
        }
        self
    }
}

impl ScanSets {
    /// Whether a ray passed through `key`, and whether it holds an end point.
    pub fn flags(&self, key: VoxelKey) -> (bool, bool) {
        self.block(key.block())
            .map_or((false, false), |block| block.get(key.cell_index()))
    }
}

/// Marks voxels in a scan's record, caching the last block (the next voxel along a ray most
/// likely lies in it again): a visit inside the cached block is a compare and a bit set.
struct Marker<'a, B> {
    sets: &'a mut ScanBlocks<B>,
    /// The cached block's key; `i32::MIN` coordinates (never a valid block) before the first.
    key: BlockKey,
    position: usize,
    /// The level of the ray being walked.
    level: u16,
}

impl<B: CellMarks> CellSink for Marker<'_, B> {
    #[inline(always)]
    fn enter(&mut self, block: BlockKey) {
        if block != self.key {
            Marker::enter(self, block);
        }
    }

    #[inline(always)]
    fn mark(&mut self, cell: usize) {
        if let Some(block) = self.sets.blocks.get_mut(self.position) {
            block.pass(cell, self.level);
        }
    }
}

impl<'a, B: CellMarks> Marker<'a, B> {
    fn new(sets: &'a mut ScanBlocks<B>) -> Self {
        Self {
            sets,
            key: BlockKey::new(i32::MIN, i32::MIN, i32::MIN),
            position: 0,
            level: 0,
        }
    }

    #[inline(always)]
    fn block(&mut self, key: VoxelKey) -> Option<&mut B> {
        let block_key = key.block();
        if block_key != self.key {
            Marker::enter(self, block_key);
        }
        self.sets.blocks.get_mut(self.position)
    }

    #[inline(never)]
    fn enter(&mut self, block_key: BlockKey) {
        self.position = self.sets.position(block_key);
        self.key = block_key;
    }

    #[inline(always)]
    fn hit(&mut self, key: VoxelKey, level: u16) {
        if let Some(block) = self.block(key) {
            block.hit(key.cell_index(), level);
        }
    }
}

/// Fewest points per unit of parallel work.
const CHUNK: usize = 1024;

/// The box of voxel keys that every ray of the scan stays in: the keys of the origin and of
/// the finite end points (in single precision, as the walk sees them), one voxel wider on
/// each side.
pub(crate) fn key_box(
    cloud: &PointCloud,
    resolution: &Resolution,
    origin: &[f32; 3],
) -> (VoxelKey, VoxelKey) {
    let key_of = |p: [f32; 3]| {
        resolution.try_key_of(&Point3::new(
            f64::from(p[0]),
            f64::from(p[1]),
            f64::from(p[2]),
        ))
    };
    let start = key_of(*origin).unwrap_or(VoxelKey::new(0, 0, 0));
    let widen = |(lo, hi): (VoxelKey, VoxelKey), k: VoxelKey| {
        (
            VoxelKey::new(lo.x.min(k.x), lo.y.min(k.y), lo.z.min(k.z)),
            VoxelKey::new(hi.x.max(k.x), hi.y.max(k.y), hi.z.max(k.z)),
        )
    };
    let (lo, hi) = cloud
        .points()
        .par_iter()
        .filter_map(|p| key_of([p.x as f32, p.y as f32, p.z as f32]))
        .fold(|| (start, start), widen)
        .reduce(|| (start, start), |a, b| widen(widen(a, b.0), b.1));
    let step = |k: i32, d: i32| k.saturating_add(d).clamp(-KEY_LIMIT, KEY_LIMIT);
    (
        VoxelKey::new(step(lo.x, -1), step(lo.y, -1), step(lo.z, -1)),
        VoxelKey::new(step(hi.x, 1), step(hi.y, 1), step(hi.z, 1)),
    )
}

/// The free and hit sets of one scan exactly as OctoMap 1.9's `insertPointCloud` builds them
/// (`computeUpdate` without discretisation): points in single precision, OctoMap's ray
/// traversal, rays longer than `max_range` cut there and clearing only. `include` selects the
/// points that belong to the scan (all, or one confidence cut).
///
/// Errors (before any work): a finite point outside the key range, or a ray (cut at
/// `max_range`) longer than [`IntegrationOptions::MAX_RAY_VOXELS`].
pub fn scan_sets(
    cloud: &PointCloud,
    resolution: &Resolution,
    options: &IntegrationOptions,
    include: impl Fn(usize) -> bool + Sync,
) -> Result<(ScanSets, IntegrationStats)> {
    walk_scan(cloud, resolution, options, Checked::No, |i| {
        u16::from(include(i))
    })
}

/// The levels of one scan whose points carry levels (`level(i)`, 0 leaves point `i` out), in
/// one walk of the rays; the voxels of level `k` and up are exactly what [`scan_sets`] of the
/// points of level `k` and up marks. The alpha-cut map inserts its nested cuts this way
/// (`LogOddsMap::apply_levels`). Errors as [`scan_sets`].
pub fn scan_levels(
    cloud: &PointCloud,
    resolution: &Resolution,
    options: &IntegrationOptions,
    level: impl Fn(usize) -> u16 + Sync,
) -> Result<(ScanLevels, IntegrationStats)> {
    walk_scan(cloud, resolution, options, Checked::No, level)
}

/// Checks everything that [`scan_sets`] and [`scan_levels`] reject, before any work: the
/// options, the origin's key, every finite point's key (in double and single precision) and
/// every ray's length (cut at `max_range`).
pub(crate) fn check_octomap_scan(
    cloud: &PointCloud,
    resolution: &Resolution,
    options: &IntegrationOptions,
) -> Result<()> {
    let options = options.validate()?;
    let origin = cloud.origin();
    resolution.key_of(&origin)?;
    let finite = |p: &Point3<f64>| p.iter().all(|v| v.is_finite());
    if let Some(p) = cloud
        .points()
        .par_iter()
        .filter(|p| finite(p))
        .find_first(|p| {
            resolution.try_key_of(p).is_none() || p.iter().any(|v| !(*v as f32).is_finite())
        })
    {
        return Err(Error::OutOfKeyRange {
            x: p.x,
            y: p.y,
            z: p.z,
            resolution: resolution.size(),
        });
    }
    let cut = |p: &Point3<f64>| {
        let range = (p - origin).norm();
        options.max_range.map_or(range, |max| range.min(max))
    };
    if let Some(p) = cloud
        .points()
        .par_iter()
        .filter(|p| finite(p))
        .find_first(|p| check_ray_length(cut(p), resolution.size()).is_err())
    {
        check_ray_length(cut(p), resolution.size())?;
    }
    Ok(())
}

/// Whether a scan still needs [`check_octomap_scan`] (a batch checks all its scans first).
#[derive(Clone, Copy, PartialEq, Eq)]
pub(crate) enum Checked {
    /// Check the scan before walking it.
    No,
    /// The caller has checked it.
    Yes,
}

pub(crate) fn walk_scan<B: CellMarks>(
    cloud: &PointCloud,
    resolution: &Resolution,
    options: &IntegrationOptions,
    checked: Checked,
    level: impl Fn(usize) -> u16 + Sync,
) -> Result<(ScanBlocks<B>, IntegrationStats)> {
    if checked == Checked::No {
        check_octomap_scan(cloud, resolution, options)?;
    }
    let options = options.validate()?;
    let origin = cloud.origin();
    let finite = |p: &Point3<f64>| p.iter().all(|v| v.is_finite());
    let single = |p: &Point3<f64>| [p.x as f32, p.y as f32, p.z as f32];
    let origin32 = single(&origin);
    let max_range = options.max_range;
    let (lo, hi) = key_box(cloud, resolution, &origin32);
    // Each piece of the cloud marks its own partial sets; `union` unites them exactly, so the
    // split does not matter. A few pieces per thread balance rays of different lengths.
    let pieces = (rayon::current_num_threads() * 4).max(1);
    let piece = cloud.points().len().div_ceil(pieces).max(CHUNK);
    let sets = cloud
        .points()
        .par_chunks(piece)
        .enumerate()
        .map(|(piece_index, chunk)| {
            let mut sets = ScanBlocks::<B>::for_box(lo, hi);
            let mut marker = Marker::new(&mut sets);
            for (offset, point) in chunk.iter().enumerate() {
                let level = level(piece_index * piece + offset);
                if !finite(point) || level == 0 {
                    continue;
                }
                let p = single(point);
                let delta = [p[0] - origin32[0], p[1] - origin32[1], p[2] - origin32[2]];
                let norm_sq = delta[0] * delta[0] + delta[1] * delta[1] + delta[2] * delta[2];
                let range = f64::from(norm_sq).sqrt();
                match max_range {
                    Some(max) if range > max => {
                        // OctoMap: origin + normalized direction × (float) max_range.
                        let (length, m) = (range as f32, max as f32);
                        let end = [
                            origin32[0] + delta[0] / length * m,
                            origin32[1] + delta[1] / length * m,
                            origin32[2] + delta[2] / length * m,
                        ];
                        marker.level = level;
                        walk_ray_octomap_cells(resolution, origin32, end, &mut marker);
                    }
                    _ => {
                        marker.level = level;
                        walk_ray_octomap_cells(resolution, origin32, p, &mut marker);
                        let end = Point3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2]));
                        if let Some(key) = resolution.try_key_of(&end) {
                            marker.hit(key, level);
                        }
                    }
                }
            }
            sets
        })
        .reduce(ScanBlocks::<B>::new, ScanBlocks::union);
    let mut stats = IntegrationStats::default();
    for (i, p) in cloud.points().iter().enumerate() {
        if !finite(p) {
            stats.skipped += 1;
        } else if level(i) > 0 {
            stats.integrated += 1;
            stats.clipped += usize::from(max_range.is_some_and(|max| (p - origin).norm() > max));
        }
    }
    Ok((sets, stats))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn marked(sets: &ScanSets) -> Vec<(BlockKey, BlockFlags)> {
        let mut blocks: Vec<_> = sets.blocks().map(|(k, b)| (k, *b)).collect();
        blocks.sort_by_key(|(k, _)| *k);
        blocks
    }

    #[test]
    fn flat_and_hashed_indexes_record_the_same_marks() {
        let keys: Vec<VoxelKey> = (0..500)
            .map(|i| VoxelKey::new(i % 37 - 18, (i * 7) % 29 - 14, (i * 13) % 23 - 11))
            .collect();
        let mut flat = ScanSets::for_box(VoxelKey::new(-18, -14, -11), VoxelKey::new(18, 14, 11));
        assert!(matches!(flat.index, BlockIndex::Dense { .. }));
        let mut hashed = ScanSets::new();
        for (i, key) in keys.iter().enumerate() {
            for sets in [&mut flat, &mut hashed] {
                let mut marker = Marker::new(sets);
                if i % 3 == 0 {
                    marker.hit(*key, 1);
                } else {
                    marker.level = 1;
                    CellSink::enter(&mut marker, key.block());
                    CellSink::mark(&mut marker, key.cell_index());
                }
            }
        }
        assert_eq!(marked(&flat), marked(&hashed));
        assert_eq!(flat.flags(keys[3]), (false, true));
        assert_eq!(flat.flags(keys[4]), hashed.flags(keys[4]));
        assert_eq!(flat.flags(VoxelKey::new(500, 0, 0)), (false, false));
    }

    #[test]
    fn a_block_outside_the_flat_box_moves_the_index_to_a_hash_map() {
        let mut sets = ScanSets::for_box(VoxelKey::new(0, 0, 0), VoxelKey::new(15, 15, 15));
        Marker::new(&mut sets).hit(VoxelKey::new(3, 3, 3), 1);
        Marker::new(&mut sets).hit(VoxelKey::new(-100, 3, 3), 1);
        assert!(matches!(sets.index, BlockIndex::Sparse(_)));
        assert_eq!(sets.flags(VoxelKey::new(3, 3, 3)), (false, true));
        assert_eq!(sets.flags(VoxelKey::new(-100, 3, 3)), (false, true));
        assert_eq!(sets.blocks().len(), 2);
    }

    #[test]
    fn a_box_too_large_for_a_flat_index_is_hashed() {
        let far = 1 << 20;
        let sets = ScanSets::for_box(
            VoxelKey::new(-far, -far, -far),
            VoxelKey::new(far, far, far),
        );
        assert!(matches!(sets.index, BlockIndex::Sparse(_)));
    }
}
