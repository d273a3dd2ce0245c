use std::path::Path;

use rustc_hash::FxHashSet;
use serde::{Deserialize, Serialize};

use super::atomic::write_atomic;
use super::mapfile::{self, MapKind};
use crate::error::{Error, FormatError, Result};
use crate::map::{FuzzyConfig, FuzzyMap};
use crate::measures::Memberships;
use crate::storage::{BLOCK_CELLS, Block, BlockGrid, BlockKey};

#[derive(Serialize, Deserialize)]
struct Body {
    config: FuzzyConfig,
    blocks: Vec<StoredBlock>,
}

#[derive(Serialize, Deserialize)]
struct StoredBlock {
    key: BlockKey,
    cells: Vec<Memberships>,
}

impl FuzzyMap {
    /// The map as the bytes of a native map file. Blocks are written in key order, so equal
    /// maps give equal bytes however they were built.
    pub fn to_bytes(&self) -> Vec<u8> {
        let grid = self.grid();
        let blocks = grid
            .sorted_block_keys()
            .into_iter()
            .filter_map(|key| {
                grid.block(key).map(|b| StoredBlock {
                    key,
                    cells: b.cells.to_vec(),
                })
            })
            .collect();
        let config = *self.config();
        mapfile::encode(
            MapKind::Fuzzy,
            Some(config.operator.family()),
            config.resolution.size(),
            &Body { config, blocks },
        )
    }

    /// Reads a map from the bytes of a native map file, checking the header, the length, the
    /// checksum and every value.
    pub fn from_bytes(bytes: &[u8]) -> Result<Self> {
        Self::decode(bytes).map_err(|reason| Error::Format {
            path: "<memory>".into(),
            reason,
        })
    }

    /// Saves the map to `path` atomically (temporary file, sync, rename): a crash never leaves
    /// a half-written map, and a failed save leaves the old file intact.
    pub fn save(&self, path: impl AsRef<Path>) -> Result<()> {
        write_atomic(path.as_ref(), &self.to_bytes())
    }

    /// Loads a map saved by [`FuzzyMap::save`]. A damaged, truncated or foreign file is a
    /// typed [`Error::Format`].
    pub fn load(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        let bytes = std::fs::read(path).map_err(|source| Error::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Self::decode(&bytes).map_err(|reason| Error::Format {
            path: path.to_path_buf(),
            reason,
        })
    }

    fn decode(bytes: &[u8]) -> Result<Self, FormatError> {
        let (header, body) = mapfile::split(bytes)?;
        if header.kind != MapKind::Fuzzy {
            return Err(FormatError::WrongKind {
                expected: MapKind::Fuzzy.name(),
                found: header.kind.name().into(),
            });
        }
        let invalid = |what: String| FormatError::Invalid(what);
        let body: Body = postcard::from_bytes(body).map_err(|e| invalid(e.to_string()))?;
        let config = body.config.validate().map_err(|e| invalid(e.to_string()))?;
        if header.resolution != config.resolution.size()
            || header.operator != Some(config.operator.family())
        {
            return Err(invalid("header and body disagree".into()));
        }
        let mut grid = BlockGrid::new();
        let mut seen = FxHashSet::default();
        for stored in body.blocks {
            if !stored.key.origin().is_valid() || !stored.key.voxel(BLOCK_CELLS - 1).is_valid() {
                return Err(invalid(format!("block key {:?} out of range", stored.key)));
            }
            if !seen.insert(stored.key) {
                return Err(invalid(format!("block {:?} appears twice", stored.key)));
            }
            let cells: [Memberships; BLOCK_CELLS] =
                stored.cells.try_into().map_err(|v: Vec<_>| {
                    invalid(format!(
                        "a block holds {} cells, not {BLOCK_CELLS}",
                        v.len()
                    ))
                })?;
            if let Some(bad) = cells
                .iter()
                .find(|m| !((0.0..=1.0).contains(&m.occupied) && (0.0..=1.0).contains(&m.free)))
            {
                return Err(invalid(format!("membership {bad:?} outside [0, 1]")));
            }
            grid.insert_block(
                stored.key,
                Box::new(Block {
                    cells,
                    summary: Default::default(),
                }),
            );
        }
        Ok(FuzzyMap::from_parts(config, grid))
    }
}
