use serde::{Deserialize, Serialize};

use super::mapfile;
use super::stored_blocks::{self, PackedStoredBlock, StoredBlock};
use crate::error::{FormatError, Result};
use crate::map::MapKind;
use crate::map::{AlphaConfig, AlphaCutMap, LogOdds, LogOddsConfig, LogOddsMap};

/// A body of format versions 1 to 3: 512 cells per block.
#[derive(Serialize, Deserialize)]
struct Body<Config> {
    config: Config,
    blocks: Vec<StoredBlock<LogOdds>>,
}

/// A body of format version 4: each block's distinct values and cell codes.
#[derive(Serialize, Deserialize)]
struct BodyV4<Config> {
    config: Config,
    blocks: Vec<PackedStoredBlock<LogOdds>>,
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
    let body: Body<Config> = if header.version >= 4 {
        let body: BodyV4<Config> =
            postcard::from_bytes(body).map_err(|e| invalid(e.to_string()))?;
        Body {
            config: body.config,
            blocks: stored_blocks::unpack_stored(body.blocks)?,
        }
    } else {
        postcard::from_bytes(body).map_err(|e| invalid(e.to_string()))?
    };
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
            &BodyV4 {
                config,
                blocks: stored_blocks::store_packed(self.grid()),
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
            &BodyV4 {
                config,
                blocks: stored_blocks::store_packed(self.log_odds().grid()),
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::PointCloud;
    use crate::map::VoxelMapMut;
    use nalgebra::Point3;

    fn cloud() -> PointCloud {
        let points = (0..300)
            .map(|i| {
                let a = f64::from(i) * 0.07;
                Point3::new(3.0 * a.cos(), 2.0 * a.sin(), 0.5 * (2.0 * a).sin())
            })
            .collect();
        PointCloud::new(Point3::new(0.05, 0.1, 0.0), points)
            .unwrap()
            .with_confidence((0..300).map(|i| (i % 10) as f32 / 9.0).collect())
            .unwrap()
    }

    /// Version 3 files (512 cells per block) of both baseline maps load as the maps they were
    /// written from, and version 4 files of the same maps are smaller.
    #[test]
    fn version_3_files_load_as_written() {
        let mut logodds = LogOddsMap::new(LogOddsConfig::new(0.1).unwrap()).unwrap();
        logodds
            .integrate_cloud(&cloud(), &Default::default())
            .unwrap();
        let config = *logodds.config();
        let v3 = mapfile::encode(
            MapKind::LogOdds,
            None,
            0.1,
            &Body {
                config,
                blocks: stored_blocks::store(logodds.grid()),
            },
        );
        let v3 = mapfile::with_version(v3, 3);
        assert_eq!(
            LogOddsMap::decode(&v3).unwrap().to_bytes(),
            logodds.to_bytes()
        );
        assert!(logodds.to_bytes().len() < v3.len() / 2);

        let mut alpha = AlphaCutMap::new(AlphaConfig::new(0.1).unwrap()).unwrap();
        alpha
            .integrate_cloud(&cloud(), &Default::default())
            .unwrap();
        let config = *alpha.config();
        let v3 = mapfile::encode(
            MapKind::AlphaCut,
            None,
            0.1,
            &Body {
                config,
                blocks: stored_blocks::store(alpha.log_odds().grid()),
            },
        );
        let v3 = mapfile::with_version(v3, 3);
        assert_eq!(
            AlphaCutMap::decode(&v3).unwrap().to_bytes(),
            alpha.to_bytes()
        );
    }
}
