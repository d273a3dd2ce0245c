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

use super::cost_field::{CostField, PlanningRegion, is_blocked};
use crate::map::VoxelMap;
use crate::measures::{Memberships, VoxelClass};
use crate::storage::{BLOCK_CELLS, BLOCK_SIDE, BlockKey};

/// What one incremental update of a cost field did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct FieldUpdate {
    /// Changed blocks of the map that meet the planning region.
    pub blocks: usize,
    /// Voxels whose measures were read again.
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

/// A voxel whose class or safety changed, with its new entries.
pub(super) struct Change {
    pub(super) index: usize,
    pub(super) safety: f32,
    pub(super) class: VoxelClass,
    /// Whether it became blocked or stopped being blocked.
    pub(super) flipped: bool,
    /// Traversability and rate with its current clearance (recomputed when a voxel flips
    /// within the cap).
    pub(super) traversable: bool,
    pub(super) rate: f32,
}

/// A box of region coordinates, `[x, y, z]` ranges.
pub(super) type VoxelBox = [Range<i64>; 3];

impl CostField {
    /// Brings the field up to date with `map` after the voxels of `blocks` changed (the blocks
    /// a map reports through [`VoxelMap::changed_blocks_since`]; blocks outside the region are
    /// ignored). The result is exactly the field [`CostField::build`] would give on the
    /// updated map, as long as no voxel of the region changed outside `blocks`.
    pub fn update(&mut self, map: &dyn VoxelMap, blocks: &[BlockKey]) -> FieldUpdate {
        let region = *self.region();
        let dims = region.dims().map(|d| d as i64);
        let parts = block_parts(&region, blocks.iter().copied());
        let mut stats = FieldUpdate {
            blocks: parts.len(),
            ..FieldUpdate::default()
        };
        // In parallel: each changed voxel's new entries; its rate and traversability with the
        // clearance it has now, which stays right unless a blocked voxel flips within the cap.
        let read = read_parts(map, &region, &parts, |i, safety, class| {
            (!self.has_measures(i, safety, class)).then(|| {
                let flipped = self.is_blocked(i) != is_blocked(class, safety, self.config());
                let (traversable, rate) = self.entry(class, safety, self.clearance(i));
                Change {
                    index: i,
                    safety,
                    class,
                    flipped,
                    traversable,
                    rate,
                }
            })
        });
        stats.voxels_read = parts
            .iter()
            .map(|(_, part)| {
                part.iter()
                    .map(|r| (r.end - r.start) as usize)
                    .product::<usize>()
            })
            .sum();
        let mut flipped: Vec<VoxelBox> = Vec::new();
        for changes in &read {
            let mut flips: Option<VoxelBox> = None;
            for change in changes {
                stats.voxels_changed += 1;
                self.set_entries(change);
                if change.flipped {
                    stats.voxels_flipped += 1;
                    let c = region.coordinates_at(change.index);
                    let b = flips.get_or_insert_with(|| c.map(|v| v..v + 1));
                    for a in 0..3 {
                        b[a] = b[a].start.min(c[a])..b[a].end.max(c[a] + 1);
                    }
                }
            }
            flipped.extend(flips);
        }
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
                self.derive(region.index_at([x, y, z]));
            });
        }
        self.refresh_min_rate();
        stats
    }
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

/// `visit(dense index, safety, class)` for every voxel of `parts`, keeping what it returns,
/// one list per part: each block is read from the map once, in parallel.
pub(super) fn read_parts<T: Send>(
    map: &dyn VoxelMap,
    region: &PlanningRegion,
    parts: &[(BlockKey, VoxelBox)],
    visit: impl Fn(usize, f32, VoxelClass) -> Option<T> + Sync,
) -> Vec<Vec<T>> {
    let lowest = region.min();
    let measures = *map.measure_config();
    parts
        .par_iter()
        .map_init(
            || Box::new([Memberships::default(); BLOCK_CELLS]),
            |cells, (block, part)| {
                map.block_memberships(*block, cells);
                let origin = block.origin();
                // Region coordinates of the block's first cell.
                let o = [
                    i64::from(origin.x) - i64::from(lowest.x),
                    i64::from(origin.y) - i64::from(lowest.y),
                    i64::from(origin.z) - i64::from(lowest.z),
                ];
                let side = BLOCK_SIDE as i64;
                let mut voxels = Vec::new();
                // Row by row: along x, the cell and the dense index both advance by one.
                let [xs, ys, zs] = part;
                for z in zs.clone() {
                    for y in ys.clone() {
                        let cell =
                            ((xs.start - o[0]) + side * ((y - o[1]) + side * (z - o[2]))) as usize;
                        let index = region.index_at([xs.start, y, z]);
                        let row = &cells[cell..cell + (xs.end - xs.start) as usize];
                        for (i, m) in (index..).zip(row) {
                            let (safety, class) = measures.safety_and_class(*m);
                            voxels.extend(visit(i, safety, class));
                        }
                    }
                }
                voxels
            },
        )
        .collect()
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
