use std::path::Path;

use super::{AlphaCutMap, FuzzyMap, LogOddsMap, VoxelMap, VoxelMapMut};
use crate::error::Result;
use crate::io::{MapKind, read_header};

/// Any of the three maps, for code that handles whichever kind a file holds.
#[derive(Clone, Debug)]
pub enum AnyMap {
    /// The dual-set fuzzy map.
    Fuzzy(FuzzyMap),
    /// The standard log-odds map.
    LogOdds(LogOddsMap),
    /// The alpha-cut map.
    Alpha(AlphaCutMap),
}

impl AnyMap {
    /// Loads a native map file of any kind.
    pub fn load(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        Ok(match read_header(path)?.kind {
            MapKind::Fuzzy => Self::Fuzzy(FuzzyMap::load(path)?),
            MapKind::LogOdds => Self::LogOdds(LogOddsMap::load(path)?),
            MapKind::AlphaCut => Self::Alpha(AlphaCutMap::load(path)?),
        })
    }

    /// Saves the map atomically in the native format.
    pub fn save(&self, path: impl AsRef<Path>) -> Result<()> {
        match self {
            Self::Fuzzy(m) => m.save(path),
            Self::LogOdds(m) => m.save(path),
            Self::Alpha(m) => m.save(path),
        }
    }

    /// The map as the bytes of a native map file.
    pub fn to_bytes(&self) -> Vec<u8> {
        match self {
            Self::Fuzzy(m) => m.to_bytes(),
            Self::LogOdds(m) => m.to_bytes(),
            Self::Alpha(m) => m.to_bytes(),
        }
    }

    /// Which kind of map this is.
    pub fn kind(&self) -> MapKind {
        match self {
            Self::Fuzzy(_) => MapKind::Fuzzy,
            Self::LogOdds(_) => MapKind::LogOdds,
            Self::Alpha(_) => MapKind::AlphaCut,
        }
    }

    /// The map through the interface every map implements.
    pub fn as_map(&self) -> &dyn VoxelMap {
        match self {
            Self::Fuzzy(m) => m,
            Self::LogOdds(m) => m,
            Self::Alpha(m) => m,
        }
    }

    /// The map through the interface every map implements, for integration.
    pub fn as_map_mut(&mut self) -> &mut dyn VoxelMapMut {
        match self {
            Self::Fuzzy(m) => m,
            Self::LogOdds(m) => m,
            Self::Alpha(m) => m,
        }
    }
}
