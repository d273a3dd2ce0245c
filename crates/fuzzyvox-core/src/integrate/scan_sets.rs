use nalgebra::Point3;
use rayon::prelude::*;
use rustc_hash::FxHashMap;

use super::cloud::PointCloud;
use super::evidence::{IntegrationOptions, IntegrationStats, check_ray_length};
use super::octomap_walk::walk_ray_octomap;
use crate::error::{Error, Result};
use crate::storage::{BLOCK_CELLS, BlockKey, Resolution, VoxelKey};

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
    index: FxHashMap<BlockKey, usize>,
    keys: Vec<BlockKey>,
    blocks: Vec<B>,
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
            index: FxHashMap::default(),
            keys: Vec::new(),
            blocks: Vec::new(),
        }
    }

    /// Blocks with any voxel marked, with their keys.
    pub fn blocks(&self) -> impl ExactSizeIterator<Item = (BlockKey, &B)> {
        self.keys.iter().copied().zip(self.blocks.iter())
    }

    #[inline]
    fn position(&mut self, key: BlockKey) -> usize {
        *self.index.entry(key).or_insert_with(|| {
            self.keys.push(key);
            self.blocks.push(B::default());
            self.blocks.len() - 1
        })
    }

    /// Unites two partial scans (exact, so the split does not matter).
    fn union(mut self, other: Self) -> Self {
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
        self.index
            .get(&key.block())
            .and_then(|&i| self.blocks.get(i))
            .map_or((false, false), |block| block.get(key.cell_index()))
    }
}

/// Marks voxels in a scan's record, caching the last block (the next voxel along a ray most
/// likely lies in it again).
struct Marker<'a, B> {
    sets: &'a mut ScanBlocks<B>,
    last: Option<(BlockKey, usize)>,
}

impl<B: CellMarks> Marker<'_, B> {
    #[inline]
    fn block(&mut self, key: VoxelKey) -> Option<&mut B> {
        let block_key = key.block();
        let position = match self.last {
            Some((cached, position)) if cached == block_key => position,
            _ => {
                let position = self.sets.position(block_key);
                self.last = Some((block_key, position));
                position
            }
        };
        self.sets.blocks.get_mut(position)
    }

    #[inline]
    fn pass(&mut self, key: VoxelKey, level: u16) {
        if let Some(block) = self.block(key) {
            block.pass(key.cell_index(), level);
        }
    }

    #[inline]
    fn hit(&mut self, key: VoxelKey, level: u16) {
        if let Some(block) = self.block(key) {
            block.hit(key.cell_index(), level);
        }
    }
}

/// Points per unit of parallel work.
const CHUNK: usize = 1024;

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
    walk_scan(cloud, resolution, options, |i| u16::from(include(i)))
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
    walk_scan(cloud, resolution, options, level)
}

fn walk_scan<B: CellMarks>(
    cloud: &PointCloud,
    resolution: &Resolution,
    options: &IntegrationOptions,
    level: impl Fn(usize) -> u16 + Sync,
) -> Result<(ScanBlocks<B>, IntegrationStats)> {
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
    let single = |p: &Point3<f64>| [p.x as f32, p.y as f32, p.z as f32];
    let origin32 = single(&origin);
    let max_range = options.max_range;
    // Each piece of work marks its own partial sets; `or` unites them exactly.
    let sets = cloud
        .points()
        .par_chunks(CHUNK)
        .enumerate()
        .fold(ScanBlocks::<B>::new, |mut sets, (chunk_index, chunk)| {
            let mut marker = Marker {
                sets: &mut sets,
                last: None,
            };
            for (offset, point) in chunk.iter().enumerate() {
                let level = level(chunk_index * CHUNK + offset);
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
                        walk_ray_octomap(resolution, origin32, end, |key| marker.pass(key, level));
                    }
                    _ => {
                        walk_ray_octomap(resolution, origin32, p, |key| marker.pass(key, level));
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
