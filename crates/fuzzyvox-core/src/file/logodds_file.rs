use serde::{Deserialize, Serialize};

use super::mapfile;
use super::stored_blocks::{self, StoredBlock};
use crate::error::{FormatError, Result};
use crate::map::MapKind;
use crate::map::{AlphaConfig, AlphaCutMap, LogOdds, LogOddsConfig, LogOddsMap};

#[derive(Serialize, Deserialize)]
struct Body<Config> {
    config: Config,
    blocks: Vec<StoredBlock<LogOdds>>,
}

/// A log-odds cell is either unobserved (NaN) or a finite value.
fn valid(c: &LogOdds) -> bool {
    c.0.is_nan() || c.0.is_finite()
}

fn decode_body<Config: serde::de::DeserializeOwned>(
    bytes: &[u8],
    kind: MapKind,
    resolution_of: impl Fn(&Config) -> f64,
) -> Result<(Config, crate::storage::BlockGrid<LogOdds>), FormatError> {
    let (header, body) = mapfile::body_of(bytes, kind)?;
    let invalid = FormatError::Invalid;
    let body: Body<Config> = postcard::from_bytes(body).map_err(|e| invalid(e.to_string()))?;
    if header.resolution != resolution_of(&body.config) || header.operator.is_some() {
        return Err(invalid("header and body disagree".into()));
    }
    let grid = stored_blocks::restore(body.blocks, valid)?;
    Ok((body.config, grid))
}

mapfile::native_file_methods!(LogOddsMap);

impl LogOddsMap {
    /// The map as the bytes of a native map file (blocks in key order).
    pub fn to_bytes(&self) -> Vec<u8> {
        let config = *self.config();
        mapfile::encode(
            MapKind::LogOdds,
            None,
            config.resolution.size(),
            &Body {
                config,
                blocks: stored_blocks::store(self.grid()),
            },
        )
    }

    fn decode(bytes: &[u8]) -> Result<Self, FormatError> {
        let (config, grid) = decode_body(bytes, MapKind::LogOdds, |c: &LogOddsConfig| {
            c.resolution.size()
        })?;
        let config = config
            .validate()
            .map_err(|e| FormatError::Invalid(e.to_string()))?;
        Ok(LogOddsMap::from_parts(config, grid))
    }
}

mapfile::native_file_methods!(AlphaCutMap);

impl AlphaCutMap {
    /// The map as the bytes of a native map file (blocks in key order).
    pub fn to_bytes(&self) -> Vec<u8> {
        let config = *self.config();
        mapfile::encode(
            MapKind::AlphaCut,
            None,
            config.logodds.resolution.size(),
            &Body {
                config,
                blocks: stored_blocks::store(self.log_odds().grid()),
            },
        )
    }

    fn decode(bytes: &[u8]) -> Result<Self, FormatError> {
        let (config, grid) = decode_body(bytes, MapKind::AlphaCut, |c: &AlphaConfig| {
            c.logodds.resolution.size()
        })?;
        let config = config
            .validate()
            .map_err(|e| FormatError::Invalid(e.to_string()))?;
        Ok(AlphaCutMap::from_parts(
            config,
            LogOddsMap::from_parts(config.logodds, grid),
        ))
    }
}
