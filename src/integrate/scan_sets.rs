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

/// One scan in the standard method's terms: per voxel, whether a ray passed through it and
/// whether an end point lies in it (a voxel with both counts as hit). Two bits per voxel keep
/// a whole scan's sets small enough to stay in cache while rays are walked.
#[derive(Clone, Debug, Default)]
pub struct ScanSets {
    index: FxHashMap<BlockKey, usize>,
    keys: Vec<BlockKey>,
    blocks: Vec<BlockFlags>,
}

impl ScanSets {
    /// No voxel marked.
    pub fn new() -> Self {
        Self::default()
    }

    /// Blocks with any voxel marked, with their keys.
    pub fn blocks(&self) -> impl ExactSizeIterator<Item = (BlockKey, &BlockFlags)> {
        self.keys.iter().copied().zip(self.blocks.iter())
    }

    /// Whether a ray passed through `key`, and whether it holds an end point.
    pub fn flags(&self, key: VoxelKey) -> (bool, bool) {
        self.index
            .get(&key.block())
            .map_or((false, false), |&i| self.blocks[i].get(key.cell_index()))
    }

    #[inline]
    fn position(&mut self, key: BlockKey) -> usize {
        *self.index.entry(key).or_insert_with(|| {
            self.keys.push(key);
            self.blocks.push(BlockFlags::default());
            self.blocks.len() - 1
        })
    }

    /// Unites two partial scans (bitwise or: exact, so the split does not matter).
    fn union(mut self, other: ScanSets) -> ScanSets {
        if self.blocks.len() < other.blocks.len() {
            return other.union(self);
        }
        for (key, flags) in other.blocks() {
            let position = self.position(key);
            let target = &mut self.blocks[position];
            for w in 0..BLOCK_CELLS / 64 {
                target.passed[w] |= flags.passed[w];
                target.hit[w] |= flags.hit[w];
            }
        }
        self
    }
}

/// Marks voxels in a [`ScanSets`], caching the last block.
struct Marker<'a> {
    sets: &'a mut ScanSets,
    last: Option<(BlockKey, usize)>,
}

impl Marker<'_> {
    #[inline]
    fn block(&mut self, key: VoxelKey) -> &mut BlockFlags {
        let block_key = key.block();
        let position = match self.last {
            Some((cached, position)) if cached == block_key => position,
            _ => {
                let position = self.sets.position(block_key);
                self.last = Some((block_key, position));
                position
            }
        };
        &mut self.sets.blocks[position]
    }

    #[inline]
    fn pass(&mut self, key: VoxelKey) {
        let i = key.cell_index();
        self.block(key).passed[i / 64] |= 1 << (i % 64);
    }

    #[inline]
    fn hit(&mut self, key: VoxelKey) {
        let i = key.cell_index();
        self.block(key).hit[i / 64] |= 1 << (i % 64);
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
        .fold(ScanSets::new, |mut sets, (chunk_index, chunk)| {
            let mut marker = Marker {
                sets: &mut sets,
                last: None,
            };
            for (offset, point) in chunk.iter().enumerate() {
                if !finite(point) || !include(chunk_index * CHUNK + offset) {
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
                        walk_ray_octomap(resolution, origin32, end, |key| marker.pass(key));
                    }
                    _ => {
                        walk_ray_octomap(resolution, origin32, p, |key| marker.pass(key));
                        let end = Point3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2]));
                        if let Some(key) = resolution.try_key_of(&end) {
                            marker.hit(key);
                        }
                    }
                }
            }
            sets
        })
        .reduce(ScanSets::new, ScanSets::union);
    let mut stats = IntegrationStats::default();
    for (i, p) in cloud.points().iter().enumerate() {
        if !finite(p) {
            stats.skipped += 1;
        } else if include(i) {
            stats.integrated += 1;
            stats.clipped += usize::from(max_range.is_some_and(|max| (p - origin).norm() > max));
        }
    }
    Ok((sets, stats))
}
