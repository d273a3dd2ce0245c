//! Reading a map into a cost field by blocks: each block's part of the planning region
//! ([`block_parts`]), and the field cut into slabs, one per layer of blocks ([`layers`]), that
//! tasks read in parallel, in place, for a full build ([`Layer::fill`]) or an update
//! ([`Layer::update`]).

use std::ops::Range;

use fuzzyvox_core::map::VoxelMap;
use fuzzyvox_core::measures::{MeasureConfig, Memberships};
use fuzzyvox_core::storage::{BLOCK_CELLS, BLOCK_SIDE, BlockKey};

use crate::least_rate::{LeastRate, RateTally};
use crate::region::PlanningRegion;
use crate::rules::{Rules, Voxel};

/// A box of region coordinates, `[x, y, z]` ranges.
pub(super) type VoxelBox = [Range<i64>; 3];

/// The field cut into the slabs that `parts` (sorted by [`block_parts`]) meet: one slab
/// per layer of blocks, with that layer's parts.
pub(super) fn layers<'a>(
    region: &PlanningRegion,
    mut voxels: &'a mut [Voxel],
    mut stamps: Option<&'a mut [u64]>,
    parts: &'a [(BlockKey, VoxelBox)],
) -> Vec<Layer<'a>> {
    let [nx, ny, _] = region.dims();
    let plane = nx * ny;
    let mut consumed = 0;
    let mut layers = Vec::new();
    // Parts of one layer of blocks share their z range, and layers come in z order.
    for group in parts.chunk_by(|a, b| a.1[2] == b.1[2]) {
        let zs = &group[0].1[2];
        let (start, end) = (zs.start as usize * plane, zs.end as usize * plane);
        let (slab, rest) = cut(std::mem::take(&mut voxels), start - consumed, end - start);
        voxels = rest;
        let stamp_slab = stamps.take().map(|all| {
            let (slab, rest) = cut(all, start - consumed, end - start);
            stamps = Some(rest);
            slab
        });
        consumed = end;
        layers.push(Layer {
            base: start,
            voxels: slab,
            stamps: stamp_slab,
            parts: group,
        });
    }
    layers
}

/// Skips `skip` items of `items`, then splits off the next `len`: `(those, the rest)`.
fn cut<T>(items: &mut [T], skip: usize, len: usize) -> (&mut [T], &mut [T]) {
    items[skip..].split_at_mut(len)
}

/// One layer of blocks: the slab of the field it covers (from dense index `base`) and the
/// changed blocks' parts in it.
pub(super) struct Layer<'a> {
    base: usize,
    voxels: &'a mut [Voxel],
    stamps: Option<&'a mut [u64]>,
    parts: &'a [(BlockKey, VoxelBox)],
}

/// What updating one layer did.
pub(super) struct LayerOutcome {
    pub(super) read: usize,
    pub(super) changed: usize,
    pub(super) flipped: usize,
    /// Per part with flipped voxels, their bounding box.
    pub(super) flips: Vec<VoxelBox>,
    pub(super) tally: RateTally,
}

/// A task's buffers for one block.
pub(super) struct Scratch {
    cells: [Memberships; BLOCK_CELLS],
    stamps: [u64; BLOCK_CELLS],
    /// Voxels whose stamp changed: their slab index, then their new stamps and memberships.
    pending: Vec<usize>,
    pending_stamps: Vec<u64>,
}

impl Scratch {
    pub(super) fn new() -> Box<Self> {
        Box::new(Self {
            cells: [Memberships::default(); BLOCK_CELLS],
            stamps: [0; BLOCK_CELLS],
            pending: Vec::with_capacity(BLOCK_CELLS),
            pending_stamps: Vec::with_capacity(BLOCK_CELLS),
        })
    }
}

impl Layer<'_> {
    /// Reads the class, safety and stamp of every voxel of the layer's blocks (one task's
    /// share of a full build).
    pub(super) fn fill(
        mut self,
        map: &dyn VoxelMap,
        region: &PlanningRegion,
        measures: &MeasureConfig,
        scratch: &mut Scratch,
    ) {
        for (block, part) in self.parts {
            map.block_memberships(*block, &mut scratch.cells);
            let stamps = self.stamps.as_deref_mut();
            let stamped = stamps.is_some() && map.block_stamps(*block, &mut scratch.stamps);
            for (cell, local, width) in part_rows(region, *block, part, self.base) {
                let cells = &scratch.cells[cell..cell + width];
                for (v, m) in self.voxels[local..local + width].iter_mut().zip(cells) {
                    (v.safety, v.class) = measures.safety_and_class(*m);
                }
            }
            if let Some(known) = stamps.filter(|_| stamped) {
                for (cell, local, width) in part_rows(region, *block, part, self.base) {
                    known[local..local + width]
                        .copy_from_slice(&scratch.stamps[cell..cell + width]);
                }
            }
        }
    }

    /// Reads the layer's changed blocks and writes each voxel whose class or safety changed,
    /// with its rate at its current clearance (which stays right unless a voxel within the
    /// clearance cap flips between blocked and not; the caller recomputes those).
    pub(super) fn update(
        mut self,
        map: &dyn VoxelMap,
        region: &PlanningRegion,
        rules: &Rules,
        measures: &MeasureConfig,
        least: LeastRate,
        scratch: &mut Scratch,
    ) -> LayerOutcome {
        let mut outcome = LayerOutcome {
            read: 0,
            changed: 0,
            flipped: 0,
            flips: Vec::new(),
            tally: RateTally::new(least),
        };
        let base = self.base;
        for (block, part) in self.parts {
            let mut flips: Option<VoxelBox> = None;
            let mut write = |local: usize, m: Memberships, outcome: &mut LayerOutcome| {
                let (safety, class) = measures.safety_and_class(m);
                let v = &mut self.voxels[local];
                if v.class == class && v.safety.to_bits() == safety.to_bits() {
                    return;
                }
                outcome.changed += 1;
                if rules.blocked(v.class, v.safety) != rules.blocked(class, safety) {
                    outcome.flipped += 1;
                    let c = region.coordinates_at(base + local);
                    let b = flips.get_or_insert_with(|| c.map(|v| v..v + 1));
                    for a in 0..3 {
                        b[a] = b[a].start.min(c[a])..b[a].end.max(c[a] + 1);
                    }
                }
                let (traversable, rate) = rules.entry(class, safety, v.clearance);
                outcome.tally.record(v.rate, rate);
                (v.safety, v.class, v.traversable, v.rate) = (safety, class, traversable, rate);
            };
            let rows = part_rows(region, *block, part, base);
            match self.stamps.as_deref_mut() {
                Some(known) if map.block_stamps(*block, &mut scratch.stamps) => {
                    // Only the voxels whose stamp changed, decoded together.
                    scratch.pending.clear();
                    scratch.pending_stamps.clear();
                    for (cell, local, width) in rows {
                        let fresh = &scratch.stamps[cell..cell + width];
                        for ((k, old), new) in
                            (local..).zip(&mut known[local..local + width]).zip(fresh)
                        {
                            if old != new {
                                *old = *new;
                                scratch.pending.push(k);
                                scratch.pending_stamps.push(*new);
                            }
                        }
                    }
                    let n = scratch.pending.len();
                    map.memberships_of_stamps(&scratch.pending_stamps, &mut scratch.cells[..n]);
                    outcome.read += n;
                    for (&local, &m) in scratch.pending.iter().zip(&scratch.cells[..n]) {
                        write(local, m, &mut outcome);
                    }
                }
                _ => {
                    map.block_memberships(*block, &mut scratch.cells);
                    for (cell, local, width) in rows {
                        outcome.read += width;
                        for (k, m) in (local..local + width).zip(&scratch.cells[cell..cell + width])
                        {
                            write(k, *m, &mut outcome);
                        }
                    }
                }
            }
            outcome.flips.extend(flips);
        }
        outcome
    }
}

/// The rows of a block's part: for each, its first cell in the block, its first voxel's index
/// less `base`, and its width (along x, the cell and the index both advance by one).
fn part_rows(
    region: &PlanningRegion,
    block: BlockKey,
    part: &VoxelBox,
    base: usize,
) -> impl Iterator<Item = (usize, usize, usize)> {
    let lowest = region.min();
    let origin = block.origin();
    // Region coordinates of the block's first cell.
    let o = [
        i64::from(origin.x) - i64::from(lowest.x),
        i64::from(origin.y) - i64::from(lowest.y),
        i64::from(origin.z) - i64::from(lowest.z),
    ];
    let side = BLOCK_SIDE as i64;
    let [xs, ys, zs] = part.clone();
    let width = (xs.end - xs.start) as usize;
    let region = *region;
    zs.flat_map(move |z| ys.clone().map(move |y| (y, z)))
        .map(move |(y, z)| {
            let cell = ((xs.start - o[0]) + side * ((y - o[1]) + side * (z - o[2]))) as usize;
            (cell, region.index_at([xs.start, y, z]) - base, width)
        })
}

/// Each block's part of the region (blocks that miss it are dropped), in region coordinates,
/// in z, y, x order of the blocks: the field is stored x fastest, so neighbours along x, which
/// share cache lines of the field, follow each other.
pub(super) fn block_parts(
    region: &PlanningRegion,
    blocks: impl Iterator<Item = BlockKey>,
) -> Vec<(BlockKey, VoxelBox)> {
    let lowest = region.min();
    let low = [lowest.x, lowest.y, lowest.z];
    let dims = region.dims().map(|d| d as i64);
    let mut parts: Vec<(BlockKey, VoxelBox)> = blocks
        .filter_map(|block| {
            let origin = block.origin();
            let from = [origin.x, origin.y, origin.z];
            let part: VoxelBox = std::array::from_fn(|a| {
                let start = i64::from(from[a]) - i64::from(low[a]);
                start.max(0)..(start + BLOCK_SIDE as i64).min(dims[a])
            });
            part.iter()
                .all(|r| r.start < r.end)
                .then_some((block, part))
        })
        .collect();
    parts.sort_unstable_by_key(|(b, _)| (b.z, b.y, b.x));
    parts
}
