use serde::{Deserialize, Serialize};

use super::mapfile;
use super::stored_blocks::{self, PackedStoredBlock, StoredBlock};
use crate::error::{FormatError, Result};
use crate::integrate::{EvidenceKind, EvidenceModel};
use crate::map::MapKind;
use crate::map::{Accumulator, FuzzyConfig, FuzzyMap, Levels};
use crate::measures::{MeasureConfig, Memberships};
use crate::ops::TConorm;
use crate::storage::Resolution;

/// A format version 5 body: the settings with the evidence model's end-point share, each
/// block's distinct levels and cell codes.
#[derive(Serialize, Deserialize)]
struct BodyV5 {
    config: FuzzyConfig,
    blocks: Vec<PackedStoredBlock<Levels>>,
}

/// A format version 4 body: levels as version 3, each block's distinct values and cell codes.
#[derive(Serialize, Deserialize)]
struct BodyV4 {
    config: ConfigV4,
    blocks: Vec<PackedStoredBlock<Levels>>,
}

/// A format version 3 body: memberships as levels of the operator's generator, 512 per block.
#[derive(Serialize, Deserialize)]
struct BodyV3 {
    config: ConfigV4,
    blocks: Vec<StoredBlock<Levels>>,
}

/// A format version 2 body: memberships as `f32`.
#[derive(Serialize, Deserialize)]
struct BodyV2 {
    config: ConfigV4,
    blocks: Vec<StoredBlock<Memberships>>,
}

/// The settings as versions 2 to 4 stored them: the evidence model had no end-point share (end
/// points counted in full).
#[derive(Clone, Copy, Serialize, Deserialize)]
struct ConfigV4 {
    resolution: Resolution,
    operator: TConorm,
    evidence: EvidenceV4,
    measures: MeasureConfig,
}

#[derive(Clone, Copy, Serialize, Deserialize)]
struct EvidenceV4 {
    kind: EvidenceKind,
    occupied_gain: f32,
    free_gain: f32,
    angular_resolution: f64,
    interval_falloff: f32,
    free_reach: f32,
    fill_footprints: bool,
}

impl From<ConfigV4> for FuzzyConfig {
    fn from(old: ConfigV4) -> Self {
        let e = old.evidence;
        FuzzyConfig {
            resolution: old.resolution,
            operator: old.operator,
            evidence: EvidenceModel {
                kind: e.kind,
                occupied_gain: e.occupied_gain,
                free_gain: e.free_gain,
                angular_resolution: e.angular_resolution,
                interval_falloff: e.interval_falloff,
                free_reach: e.free_reach,
                fill_footprints: e.fill_footprints,
                end_point_share: 0.0,
            },
            measures: old.measures,
        }
    }
}

/// A format version 1 body: its evidence model had no kind (it was the paper's model) and no
/// free reach.
#[derive(Serialize, Deserialize)]
struct BodyV1 {
    config: ConfigV1,
    blocks: Vec<StoredBlock<Memberships>>,
}

#[derive(Serialize, Deserialize)]
struct ConfigV1 {
    resolution: Resolution,
    operator: TConorm,
    evidence: EvidenceV1,
    measures: MeasureConfig,
}

#[derive(Serialize, Deserialize)]
struct EvidenceV1 {
    occupied_gain: f32,
    free_gain: f32,
    angular_resolution: f64,
    interval_falloff: f32,
}

impl From<ConfigV1> for FuzzyConfig {
    fn from(old: ConfigV1) -> Self {
        let e = old.evidence;
        FuzzyConfig {
            resolution: old.resolution,
            operator: old.operator,
            evidence: EvidenceModel {
                occupied_gain: e.occupied_gain,
                free_gain: e.free_gain,
                angular_resolution: e.angular_resolution,
                interval_falloff: e.interval_falloff,
                ..EvidenceModel::paper()
            },
            measures: old.measures,
        }
    }
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
            &BodyV5 {
                config,
                blocks: stored_blocks::store_packed(self.grid()),
            },
        )
    }

    fn decode(bytes: &[u8]) -> Result<Self, FormatError> {
        let (header, body) = mapfile::body_of(bytes, MapKind::Fuzzy)?;
        let invalid = FormatError::Invalid;
        // Versions 1 and 2 store memberships: their settings and blocks.
        let old: Option<(FuzzyConfig, Vec<StoredBlock<Memberships>>)> = match header.version {
            1 => {
                let old: BodyV1 = postcard::from_bytes(body).map_err(|e| invalid(e.to_string()))?;
                Some((old.config.into(), old.blocks))
            }
            2 => {
                let old: BodyV2 = postcard::from_bytes(body).map_err(|e| invalid(e.to_string()))?;
                Some((old.config.into(), old.blocks))
            }
            _ => None,
        };
        let (config, blocks): (FuzzyConfig, Vec<StoredBlock<Levels>>) = match old {
            Some((config, old_blocks)) => {
                // Memberships before version 3: every one becomes the nearest level.
                let unit = |v: f32| (0.0..=1.0).contains(&v);
                if let Some(bad) = old_blocks.iter().find(|b| {
                    !b.cells
                        .iter()
                        .all(|m: &Memberships| unit(m.occupied) && unit(m.free))
                }) {
                    return Err(invalid(format!(
                        "a membership outside [0, 1] in block {:?}",
                        bad.key
                    )));
                }
                let acc = Accumulator::new(config.operator);
                let blocks = old_blocks
                    .into_iter()
                    .map(|b| StoredBlock {
                        key: b.key,
                        cells: b.cells.iter().map(|m| acc.levels(*m)).collect(),
                    })
                    .collect();
                (config, blocks)
            }
            None if header.version >= 5 => {
                let body: BodyV5 =
                    postcard::from_bytes(body).map_err(|e| invalid(e.to_string()))?;
                (body.config, stored_blocks::unpack_stored(body.blocks)?)
            }
            None if header.version == 4 => {
                let body: BodyV4 =
                    postcard::from_bytes(body).map_err(|e| invalid(e.to_string()))?;
                (
                    body.config.into(),
                    stored_blocks::unpack_stored(body.blocks)?,
                )
            }
            None => {
                let body: BodyV3 =
                    postcard::from_bytes(body).map_err(|e| invalid(e.to_string()))?;
                (body.config.into(), body.blocks)
            }
        };
        let config = config.validate().map_err(|e| invalid(e.to_string()))?;
        if header.resolution != config.resolution.size()
            || header.operator != Some(config.operator.family())
        {
            return Err(invalid("header and body disagree".into()));
        }
        // Every level must be one the operator's accumulator can produce.
        let acc = Accumulator::new(config.operator);
        let grid = stored_blocks::restore(blocks, |l: &Levels| {
            acc.is_valid(l.occupied) && acc.is_valid(l.free)
        })?;
        Ok(FuzzyMap::from_parts(config, grid))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `config` as versions 2 to 4 stored it (the end-point share left out).
    fn config_v4(config: FuzzyConfig) -> ConfigV4 {
        let e = config.evidence;
        ConfigV4 {
            resolution: config.resolution,
            operator: config.operator,
            evidence: EvidenceV4 {
                kind: e.kind,
                occupied_gain: e.occupied_gain,
                free_gain: e.free_gain,
                angular_resolution: e.angular_resolution,
                interval_falloff: e.interval_falloff,
                free_reach: e.free_reach,
                fill_footprints: e.fill_footprints,
            },
            measures: config.measures,
        }
    }

    /// The map's memberships as a version 1 or 2 file stored them.
    fn memberships_grid(map: &FuzzyMap) -> crate::storage::BlockGrid<Memberships> {
        let mut grid = crate::storage::BlockGrid::new();
        for (key, levels) in map.grid().cells() {
            *grid.cell_or_insert(key) = map.accumulator().memberships(levels);
        }
        grid
    }

    /// A version 1 file (written before the evidence model had a kind) loads with the paper's
    /// model, its memberships intact.
    #[test]
    fn version_1_files_load_with_the_papers_model() {
        let config = FuzzyConfig::new(0.25).unwrap();
        let mut map = FuzzyMap::new(config).unwrap();
        let cloud = crate::integrate::PointCloud::new(
            nalgebra::Point3::origin(),
            vec![nalgebra::Point3::new(1.0, 0.5, 0.0)],
        )
        .unwrap();
        crate::map::VoxelMapMut::integrate_cloud(&mut map, &cloud, &Default::default()).unwrap();
        let old = BodyV1 {
            config: ConfigV1 {
                resolution: config.resolution,
                operator: config.operator,
                evidence: EvidenceV1 {
                    occupied_gain: 0.7,
                    free_gain: 0.6,
                    angular_resolution: 0.002,
                    interval_falloff: 1.0,
                },
                measures: config.measures,
            },
            blocks: stored_blocks::store_dense(&memberships_grid(&map)),
        };
        let mut bytes = mapfile::encode(MapKind::Fuzzy, Some(config.operator.family()), 0.25, &old);
        // Rewrite the header as version 1 and fix the checksum.
        bytes[8..10].copy_from_slice(&1u16.to_le_bytes());
        let mut crc = crc32fast::Hasher::new();
        crc.update(&bytes[..36]);
        crc.update(&bytes[40..]);
        let sum = crc.finalize().to_le_bytes();
        bytes[36..40].copy_from_slice(&sum);
        let loaded = FuzzyMap::decode(&bytes).unwrap();
        assert_eq!(loaded.config().evidence.kind, EvidenceKind::Paper);
        assert_eq!(loaded.config().evidence.interval_falloff, 1.0);
        assert_eq!(loaded.grid().cells().count(), map.grid().cells().count());
        let key = crate::storage::Resolution::new(0.25)
            .unwrap()
            .key_of(&nalgebra::Point3::new(1.0, 0.5, 0.0))
            .unwrap();
        assert_eq!(
            crate::map::VoxelMap::memberships_at(&loaded, key),
            crate::map::VoxelMap::memberships_at(&map, key)
        );
        // A version from the future is refused with its number.
        bytes[8..10].copy_from_slice(&6u16.to_le_bytes());
        assert!(matches!(
            FuzzyMap::decode(&bytes),
            Err(FormatError::UnsupportedVersion(6))
        ));
    }

    /// A version 3 file (512 levels per block) loads as the map it was written from.
    #[test]
    fn version_3_files_load_as_written() {
        let mut map = FuzzyMap::new(FuzzyConfig::new(0.2).unwrap()).unwrap();
        let points = (0..200)
            .map(|i| {
                let a = f64::from(i) * 0.1;
                nalgebra::Point3::new(2.0 * a.cos(), 2.0 * a.sin(), 0.3 * a.sin())
            })
            .collect();
        let cloud = crate::integrate::PointCloud::new(nalgebra::Point3::new(0.1, 0.0, 0.0), points)
            .unwrap();
        crate::map::VoxelMapMut::integrate_cloud(&mut map, &cloud, &Default::default()).unwrap();
        let config = *map.config();
        let v3 = mapfile::encode(
            MapKind::Fuzzy,
            Some(config.operator.family()),
            0.2,
            &BodyV3 {
                config: config_v4(config),
                blocks: stored_blocks::store(map.grid()),
            },
        );
        let v3 = mapfile::with_version(v3, 3);
        let loaded = FuzzyMap::decode(&v3).unwrap();
        assert_eq!(loaded.to_bytes(), map.to_bytes());
        // Version 4 stores the same map in fewer bytes.
        assert!(
            map.to_bytes().len() < v3.len() / 2,
            "{} against {}",
            map.to_bytes().len(),
            v3.len()
        );
    }

    /// A version 4 file (no end-point share in its evidence model) loads as the map it was
    /// written from, its end points unweighed; the share survives a save and a load.
    #[test]
    fn version_4_files_load_with_end_points_unweighed() {
        let config = FuzzyConfig::new(0.2)
            .unwrap()
            .with_evidence(EvidenceModel::confirmed());
        let mut map = FuzzyMap::new(config).unwrap();
        let cloud = crate::integrate::PointCloud::new(
            nalgebra::Point3::origin(),
            vec![nalgebra::Point3::new(1.5, 0.3, 0.1)],
        )
        .unwrap();
        crate::map::VoxelMapMut::integrate_cloud(&mut map, &cloud, &Default::default()).unwrap();
        let v4 = mapfile::encode(
            MapKind::Fuzzy,
            Some(config.operator.family()),
            0.2,
            &BodyV4 {
                config: config_v4(config),
                blocks: stored_blocks::store_packed(map.grid()),
            },
        );
        let v4 = mapfile::with_version(v4, 4);
        let loaded = FuzzyMap::decode(&v4).unwrap();
        assert_eq!(loaded.config().evidence.end_point_share, 0.0);
        assert_eq!(
            loaded.config().evidence.free_gain,
            config.evidence.free_gain
        );
        assert_eq!(loaded.grid().cells().count(), map.grid().cells().count());
        let again = FuzzyMap::decode(&map.to_bytes()).unwrap();
        assert_eq!(again.config().evidence.end_point_share, 1.0 / 3.0);
        assert_eq!(again.to_bytes(), map.to_bytes());
    }
}
