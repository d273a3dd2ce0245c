//! Files of any kind of map: [`AnyMap`]'s load and save.

use std::path::Path;

use super::mapfile::{MapHeader, MapKind, read_checked};
use crate::error::{Error, Result};
use crate::map::{AlphaCutMap, AnyMap, FuzzyMap, LogOddsMap};

impl AnyMap {
    /// Loads a native map file of any kind.
    pub fn load(path: impl AsRef<Path>) -> Result<Self> {
        Self::load_with_header(path.as_ref()).map(|(_, map)| map)
    }

    /// Loads a native map file of any kind, reading it once, with its header.
    pub fn load_with_header(path: &Path) -> Result<(MapHeader, Self)> {
        let (header, bytes) = read_checked(path)?;
        let map = match header.kind {
            MapKind::Fuzzy => FuzzyMap::from_bytes(&bytes).map(Self::Fuzzy),
            MapKind::LogOdds => LogOddsMap::from_bytes(&bytes).map(Self::LogOdds),
            MapKind::AlphaCut => AlphaCutMap::from_bytes(&bytes).map(Self::Alpha),
        };
        // The decoders name the bytes `<memory>`; name the file instead.
        let map = map.map_err(|error| match error {
            Error::Format { reason, .. } => Error::Format {
                path: path.to_path_buf(),
                reason,
            },
            other => other,
        })?;
        Ok((header, map))
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
}
