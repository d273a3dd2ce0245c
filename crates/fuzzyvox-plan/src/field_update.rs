//! Updating a cost field from the blocks a map changed, with the same result as a full build.
//!
//! A voxel's own entries (class, safety, rate) depend on it alone; its clearance depends on
//! the blocked voxels within [`CostField::clearance_cap`]. So an update re-reads the voxels of
//! the changed blocks, and only where a voxel became blocked or stopped being blocked does it
//! recompute clearances: over the box of those voxels grown by the cap, from a distance
//! transform over that box grown by the cap again. Boxes that overlap are merged first, so a
//! frame that changed a few clusters of voxels pays for those clusters, not for the region.

use rayon::prelude::*;
use serde::Serialize;

use fuzzyvox_core::map::VoxelMap;
use fuzzyvox_core::storage::{BLOCK_CELLS, BlockKey};

use crate::cost_field::CostField;
use crate::layers::{LayerOutcome, Scratch, VoxelBox, block_parts, layers};

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
        let outcomes: Vec<LayerOutcome> = layers(
            &region,
            &mut self.voxels,
            self.stamps.as_deref_mut(),
            &parts,
        )
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
    use std::ops::Range;

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
