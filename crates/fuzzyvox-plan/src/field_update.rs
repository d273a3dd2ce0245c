//! Updating a cost field from the blocks a map changed, with the same result as a full build.
//!
//! A voxel's own entries (class, safety, rate) depend on it alone; its clearance depends on
//! the blocked voxels within [`CostField::clearance_cap`]. So an update re-reads the voxels of
//! the changed blocks, and only where a voxel became blocked or stopped being blocked does it
//! recompute clearances: over the box of those voxels grown by the cap, from a distance
//! transform over that box grown by the cap again. Boxes that overlap are merged first, so a
//! frame that changed a few clusters of voxels pays for those clusters, not for the region.

use std::ops::Range;

use rayon::prelude::*;
use serde::Serialize;

use super::cost_field::{CostField, PlanningRegion, Rules, Voxel};
use super::least_rate::{LeastRate, RateTally};
use crate::map::VoxelMap;
use crate::measures::{MeasureConfig, Memberships};
use crate::storage::{BLOCK_CELLS, BLOCK_SIDE, BlockKey};

/// What one incremental update of a cost field did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct FieldUpdate {
    /// Changed blocks of the map that meet the planning region.
    pub blocks: usize,
    /// Voxels whose memberships were read again: those whose stamp changed, when the map
    /// keeps stamps ([`VoxelMap::block_stamps`]), or else every voxel of the changed blocks.
    pub voxels_read: usize,
    /// Voxels whose class or safety changed.
    pub voxels_changed: usize,
    /// Voxels that became blocked or stopped being blocked.
    pub voxels_flipped: usize,
    /// Voxels whose clearance was recomputed (around the flipped ones).
    pub clearance_voxels: usize,
    /// Whether the whole field was rebuilt (the map's write version went backwards, or it
    /// stopped or started reporting one: the field could not know what changed).
    pub rebuilt: bool,
}

/// A box of region coordinates, `[x, y, z]` ranges.
pub(super) type VoxelBox = [Range<i64>; 3];

impl CostField {
    /// Brings the field up to date with `map` after the voxels of `blocks` changed (the blocks
    /// a map reports through [`VoxelMap::changed_blocks_since`]; blocks outside the region are
    /// ignored). The result is exactly the field [`CostField::build`] would give on the
    /// updated map, as long as no voxel of the region changed outside `blocks`.
    ///
    /// When the map keeps stamps ([`VoxelMap::block_stamps`]), only the voxels whose stamp
    /// changed are decoded. The blocks are updated in place and in parallel, one layer of
    /// blocks (8 voxels of z, a contiguous slab of the field) per task.
    pub fn update(&mut self, map: &dyn VoxelMap, blocks: &[BlockKey]) -> FieldUpdate {
        let region = *self.region();
        let dims = region.dims().map(|d| d as i64);
        let parts = block_parts(&region, blocks.iter().copied());
        let mut stats = FieldUpdate {
            blocks: parts.len(),
            ..FieldUpdate::default()
        };
        if let Some((block, _)) = parts.first()
            && self.stamps.is_some()
            && !map.block_stamps(*block, &mut [0; BLOCK_CELLS])
        {
            // Not the map the field was built from: it keeps no stamps.
            self.stamps = None;
        }
        let (rules, measures, least) = (self.rules(), *map.measure_config(), self.least);
        let outcomes: Vec<LayerOutcome> = self
            .layers(&parts)
            .into_par_iter()
            .map_init(Scratch::new, |scratch, layer| {
                layer.update(map, &region, &rules, &measures, least, scratch)
            })
            .collect();
        let mut flipped: Vec<VoxelBox> = Vec::new();
        for outcome in &outcomes {
            stats.voxels_read += outcome.read;
            stats.voxels_changed += outcome.changed;
            stats.voxels_flipped += outcome.flipped;
            flipped.extend(outcome.flips.iter().cloned());
        }
        self.least.merge(outcomes.iter().map(|o| o.tally));
        // Clearances around the flipped voxels, one distance transform per merged box.
        let reach = self.reach();
        let grown: Vec<VoxelBox> = flipped
            .iter()
            .map(|b| {
                std::array::from_fn(|a| {
                    (b[a].start - reach).max(0)..(b[a].end + reach).min(dims[a])
                })
            })
            .collect();
        for target in merge_overlapping(grown) {
            self.recompute_clearance(&target);
            for_each_voxel(&target, |x, y, z| {
                stats.clearance_voxels += 1;
                self.derive(region.index_at([x, y, z]), &rules);
            });
        }
        if self.least.is_lost() {
            self.rescan_least_rate();
        }
        stats
    }

    /// Reads the class, safety and stamp of every voxel of `parts` (blocks sorted by
    /// [`block_parts`]) into the field, in place and in parallel by layers of blocks; the rest
    /// of each voxel's entries are left for the caller to derive.
    pub(super) fn fill(&mut self, map: &dyn VoxelMap, parts: &[(BlockKey, VoxelBox)]) {
        let (region, measures) = (*self.region(), *map.measure_config());
        self.layers(parts)
            .into_par_iter()
            .for_each_init(Scratch::new, |scratch, layer| {
                layer.fill(map, &region, &measures, scratch)
            });
    }

    /// The field cut into the slabs that `parts` (sorted by [`block_parts`]) meet: one slab
    /// per layer of blocks, with that layer's parts.
    fn layers<'a>(&'a mut self, parts: &'a [(BlockKey, VoxelBox)]) -> Vec<Layer<'a>> {
        let [nx, ny, _] = self.region().dims();
        let plane = nx * ny;
        let mut voxels: &mut [Voxel] = &mut self.voxels;
        let mut stamps: Option<&mut [u64]> = self.stamps.as_deref_mut();
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
}

/// Skips `skip` items of `items`, then splits off the next `len`: `(those, the rest)`.
fn cut<T>(items: &mut [T], skip: usize, len: usize) -> (&mut [T], &mut [T]) {
    items[skip..].split_at_mut(len)
}

/// One layer of blocks: the slab of the field it covers (from dense index `base`) and the
/// changed blocks' parts in it.
struct Layer<'a> {
    base: usize,
    voxels: &'a mut [Voxel],
    stamps: Option<&'a mut [u64]>,
    parts: &'a [(BlockKey, VoxelBox)],
}

/// What updating one layer did.
struct LayerOutcome {
    read: usize,
    changed: usize,
    flipped: usize,
    /// Per part with flipped voxels, their bounding box.
    flips: Vec<VoxelBox>,
    tally: RateTally,
}

/// A task's buffers for one block.
struct Scratch {
    cells: [Memberships; BLOCK_CELLS],
    stamps: [u64; BLOCK_CELLS],
    /// Voxels whose stamp changed: their slab index, then their new stamps and memberships.
    pending: Vec<usize>,
    pending_stamps: Vec<u64>,
}

impl Scratch {
    fn new() -> Box<Self> {
        Box::new(Self {
            cells: [Memberships::default(); BLOCK_CELLS],
            stamps: [0; BLOCK_CELLS],
            pending: Vec::with_capacity(BLOCK_CELLS),
            pending_stamps: Vec::with_capacity(BLOCK_CELLS),
        })
    }
}

impl Layer<'_> {
    /// [`CostField::fill`] for this layer.
    fn fill(
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
    fn update(
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

/// Calls `visit(x, y, z)` for every voxel of a box, x fastest.
fn for_each_voxel(b: &VoxelBox, mut visit: impl FnMut(i64, i64, i64)) {
    for z in b[2].clone() {
        for y in b[1].clone() {
            for x in b[0].clone() {
                visit(x, y, z);
            }
        }
    }
}

/// Replaces boxes that overlap by their bounding box until no two overlap.
fn merge_overlapping(mut boxes: Vec<VoxelBox>) -> Vec<VoxelBox> {
    let overlap =
        |a: &VoxelBox, b: &VoxelBox| (0..3).all(|k| a[k].start < b[k].end && b[k].start < a[k].end);
    let mut merged: Vec<VoxelBox> = Vec::with_capacity(boxes.len());
    while let Some(mut current) = boxes.pop() {
        // Absorb every box that meets the growing one; absorbing may make it meet boxes it
        // missed before, so scan again until nothing changes.
        loop {
            let before = boxes.len();
            boxes.retain(|other| {
                if overlap(&current, other) {
                    for k in 0..3 {
                        current[k] =
                            current[k].start.min(other[k].start)..current[k].end.max(other[k].end);
                    }
                    false
                } else {
                    true
                }
            });
            if boxes.len() == before {
                break;
            }
        }
        // A finished box may now meet one merged earlier.
        if let Some(k) = merged.iter().position(|m| overlap(m, &current)) {
            let earlier = merged.swap_remove(k);
            boxes.push(std::array::from_fn(|a| {
                earlier[a].start.min(current[a].start)..earlier[a].end.max(current[a].end)
            }));
        } else {
            merged.push(current);
        }
    }
    merged
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn merged_boxes_are_disjoint_and_cover_the_inputs() {
        let b = |x: Range<i64>, y: Range<i64>| [x, y, 0..1];
        let boxes = vec![
            b(0..2, 0..2),
            b(5..7, 0..2),
            b(1..6, 1..2),
            b(10..12, 10..12),
        ];
        let merged = merge_overlapping(boxes.clone());
        assert_eq!(merged.len(), 2);
        for input in &boxes {
            assert!(
                merged
                    .iter()
                    .any(|m| (0..3)
                        .all(|k| m[k].start <= input[k].start && input[k].end <= m[k].end))
            );
        }
        assert!(merged.contains(&b(0..7, 0..2)));
    }
}
