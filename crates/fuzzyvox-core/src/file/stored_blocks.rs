//! Blocks as they are stored in map files: in ascending key order, so that equal maps give
//! equal bytes however they were built. Since format version 4 a block stores its distinct
//! values once and each cell's index among them in the fewest bits ([`PackedStoredBlock`]);
//! versions 1 to 3 store 512 cells per block ([`StoredBlock`]), and still load.

use rustc_hash::FxHashSet;
use serde::{Deserialize, Serialize};

use crate::error::FormatError;
use crate::storage::{BLOCK_CELLS, Block, BlockGrid, BlockKey, CellBits, PackedGrid};

/// One stored block as versions 1 to 3 store it: its 512 cells.
#[derive(Serialize, Deserialize)]
pub(crate) struct StoredBlock<C> {
    pub(crate) key: BlockKey,
    pub(crate) cells: Vec<C>,
}

/// One stored block as version 4 stores it: its distinct values in order of first appearance,
/// and each cell's index among them in `bits_for(values.len())` bits (0, 1, 2, 4 or 8; cell
/// `i`'s index in the low bits first). A block of more than 256 distinct values stores its
/// 512 cells as `values`, with no codes.
#[derive(Serialize, Deserialize)]
pub(crate) struct PackedStoredBlock<C> {
    pub(crate) key: BlockKey,
    pub(crate) values: Vec<C>,
    pub(crate) codes: Vec<u8>,
}

/// Bits per cell index for `n` distinct values (at most 256).
fn bits_for(n: usize) -> usize {
    match n {
        0 | 1 => 0,
        2 => 1,
        3 | 4 => 2,
        5..=16 => 4,
        _ => 8,
    }
}

/// The grid's blocks in key order, each as its distinct values and cell codes.
pub(crate) fn store_packed<C: CellBits>(grid: &PackedGrid<C>) -> Vec<PackedStoredBlock<C>> {
    grid.sorted_block_keys()
        .into_iter()
        .filter_map(|key| grid.block(key).map(|b| pack_stored(key, &b.unpack().cells)))
        .collect()
}

fn pack_stored<C: CellBits>(key: BlockKey, cells: &[C; BLOCK_CELLS]) -> PackedStoredBlock<C> {
    let mut values: Vec<C> = Vec::new();
    let mut seen: rustc_hash::FxHashMap<u64, usize> = rustc_hash::FxHashMap::default();
    let mut index = [0usize; BLOCK_CELLS];
    for (slot, cell) in index.iter_mut().zip(cells) {
        *slot = *seen.entry(cell.bits()).or_insert_with(|| {
            values.push(*cell);
            values.len() - 1
        });
    }
    if values.len() > 256 {
        return PackedStoredBlock {
            key,
            values: cells.to_vec(),
            codes: Vec::new(),
        };
    }
    let bits = bits_for(values.len());
    let mut codes = vec![0u8; BLOCK_CELLS * bits / 8];
    if let Some(per_byte) = 8usize.checked_div(bits) {
        for (i, &k) in index.iter().enumerate() {
            if let Some(byte) = codes.get_mut(i / per_byte) {
                *byte |= (k as u8) << (bits * (i % per_byte));
            }
        }
    }
    PackedStoredBlock { key, values, codes }
}

/// Version 4 blocks as 512 cells each, checking their values and codes.
pub(crate) fn unpack_stored<C: Copy>(
    blocks: Vec<PackedStoredBlock<C>>,
) -> Result<Vec<StoredBlock<C>>, FormatError> {
    let invalid = FormatError::Invalid;
    blocks
        .into_iter()
        .map(|b| {
            let n = b.values.len();
            if n == 0 || (n > 256 && (n != BLOCK_CELLS || !b.codes.is_empty())) {
                return Err(invalid(format!(
                    "block {:?} holds {n} values and {} code bytes",
                    b.key,
                    b.codes.len()
                )));
            }
            if n > 256 {
                return Ok(StoredBlock {
                    key: b.key,
                    cells: b.values,
                });
            }
            let bits = bits_for(n);
            if b.codes.len() != BLOCK_CELLS * bits / 8 {
                return Err(invalid(format!(
                    "block {:?} has {} code bytes for {n} values",
                    b.key,
                    b.codes.len()
                )));
            }
            let mut cells = Vec::with_capacity(BLOCK_CELLS);
            let mask = ((1u16 << bits) - 1) as u8;
            for i in 0..BLOCK_CELLS {
                // The length was checked above, so every cell's byte is there.
                let k = match 8usize.checked_div(bits) {
                    None => 0,
                    Some(per_byte) => b.codes.get(i / per_byte).map_or(usize::MAX, |byte| {
                        usize::from((byte >> (bits * (i % per_byte))) & mask)
                    }),
                };
                match b.values.get(k) {
                    Some(value) => cells.push(*value),
                    None => {
                        return Err(invalid(format!(
                            "block {:?}: cell {i} names value {k} of {n}",
                            b.key
                        )));
                    }
                }
            }
            Ok(StoredBlock { key: b.key, cells })
        })
        .collect()
}

/// The grid's blocks in key order, each as its 512 cells (versions 1 to 3, written by tests).
#[cfg(test)]
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn packed_blocks_round_trip_at_every_width_and_bad_codes_are_errors() {
        let key = BlockKey::new(1, -2, 3);
        for distinct in [1usize, 2, 3, 4, 5, 16, 17, 256, 257, 512] {
            let mut cells = [0u32; BLOCK_CELLS];
            for (i, c) in cells.iter_mut().enumerate() {
                *c = (i * 7 % distinct) as u32 * 3 + 1;
            }
            let packed = pack_stored(key, &cells);
            let expected = if distinct > 256 {
                BLOCK_CELLS
            } else {
                distinct
            };
            assert_eq!(packed.values.len(), expected);
            let back = unpack_stored(vec![packed]).unwrap();
            assert_eq!(back[0].cells, cells.to_vec(), "{distinct} values");
            assert_eq!(back[0].key, key);
        }
        let mut cells = [0u32; BLOCK_CELLS];
        cells[3] = 5;
        cells[9] = 6;
        let mut short = pack_stored(key, &cells);
        short.codes.pop();
        assert!(unpack_stored(vec![short]).is_err());
        let mut beyond = pack_stored(key, &cells);
        beyond.values.pop();
        assert!(unpack_stored(vec![beyond]).is_err());
        let empty = PackedStoredBlock::<u32> {
            key,
            values: Vec::new(),
            codes: Vec::new(),
        };
        assert!(unpack_stored(vec![empty]).is_err());
    }
}
