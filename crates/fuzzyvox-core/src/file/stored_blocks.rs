//! Blocks as they are stored in map files: in ascending key order, 512 cells each, so that
//! equal maps give equal bytes however they were built.

use rustc_hash::FxHashSet;
use serde::{Deserialize, Serialize};

use crate::error::FormatError;
use crate::storage::{BLOCK_CELLS, Block, BlockGrid, BlockKey, CellBits, PackedGrid};

/// One stored block.
#[derive(Serialize, Deserialize)]
pub(crate) struct StoredBlock<C> {
    pub(crate) key: BlockKey,
    pub(crate) cells: Vec<C>,
}

/// The grid's blocks in key order, each as its 512 cells, however the grid packs them.
pub(crate) fn store<C: CellBits>(grid: &PackedGrid<C>) -> Vec<StoredBlock<C>> {
    grid.sorted_block_keys()
        .into_iter()
        .filter_map(|key| {
            grid.block(key).map(|b| StoredBlock {
                key,
                cells: b.iter().collect(),
            })
        })
        .collect()
}

/// A dense grid's blocks in key order (files of older versions, written by tests).
#[cfg(test)]
pub(crate) fn store_dense<C: Copy + Default>(grid: &BlockGrid<C>) -> Vec<StoredBlock<C>> {
    grid.sorted_block_keys()
        .into_iter()
        .filter_map(|key| {
            grid.block(key).map(|b| StoredBlock {
                key,
                cells: b.cells.to_vec(),
            })
        })
        .collect()
}

/// Rebuilds a grid, checking keys (in range, no duplicates), cell counts and every cell with
/// `valid`. Summaries are left for the map to compute.
pub(crate) fn restore<C: Copy + Default + std::fmt::Debug>(
    blocks: Vec<StoredBlock<C>>,
    valid: impl Fn(&C) -> bool,
) -> Result<BlockGrid<C>, FormatError> {
    let invalid = FormatError::Invalid;
    let mut grid = BlockGrid::new();
    let mut seen = FxHashSet::default();
    for stored in blocks {
        if !stored.key.origin().is_valid() || !stored.key.voxel(BLOCK_CELLS - 1).is_valid() {
            return Err(invalid(format!("block key {:?} out of range", stored.key)));
        }
        if !seen.insert(stored.key) {
            return Err(invalid(format!("block {:?} appears twice", stored.key)));
        }
        let cells: [C; BLOCK_CELLS] = stored.cells.try_into().map_err(|v: Vec<C>| {
            invalid(format!(
                "a block holds {} cells, not {BLOCK_CELLS}",
                v.len()
            ))
        })?;
        if let Some(bad) = cells.iter().find(|c| !valid(c)) {
            return Err(invalid(format!("invalid cell value {bad:?}")));
        }
        grid.insert_block(
            stored.key,
            Box::new(Block {
                cells,
                summary: Default::default(),
            }),
        );
    }
    Ok(grid)
}
