use serde::{Deserialize, Serialize};

use super::mapfile::{self, MapKind};
use super::stored_blocks::{self, StoredBlock};
use crate::error::{FormatError, Result};
use crate::map::{FuzzyConfig, FuzzyMap};
use crate::measures::Memberships;

#[derive(Serialize, Deserialize)]
struct Body {
    config: FuzzyConfig,
    blocks: Vec<StoredBlock<Memberships>>,
}

mapfile::native_file_methods!(FuzzyMap);

impl FuzzyMap {
    /// The map as the bytes of a native map file. Blocks are written in key order, so equal
    /// maps give equal bytes however they were built.
    pub fn to_bytes(&self) -> Vec<u8> {
        let config = *self.config();
        mapfile::encode(
            MapKind::Fuzzy,
            Some(config.operator.family()),
            config.resolution.size(),
            &Body {
                config,
                blocks: stored_blocks::store(self.grid()),
            },
        )
    }

    fn decode(bytes: &[u8]) -> Result<Self, FormatError> {
        let (header, body) = mapfile::body_of(bytes, MapKind::Fuzzy)?;
        let invalid = FormatError::Invalid;
        let body: Body = postcard::from_bytes(body).map_err(|e| invalid(e.to_string()))?;
        let config = body.config.validate().map_err(|e| invalid(e.to_string()))?;
        if header.resolution != config.resolution.size()
            || header.operator != Some(config.operator.family())
        {
            return Err(invalid("header and body disagree".into()));
        }
        let unit = |v: f32| (0.0..=1.0).contains(&v);
        let grid = stored_blocks::restore(body.blocks, |m: &Memberships| {
            unit(m.occupied) && unit(m.free)
        })?;
        Ok(FuzzyMap::from_parts(config, grid))
    }
}
