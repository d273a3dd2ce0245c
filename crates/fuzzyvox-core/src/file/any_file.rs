//! Files of any kind of map: [`AnyMap`]'s load and save.

use std::path::Path;

use super::mapfile::{MapHeader, from_memory, read_checked, split};
use crate::error::{Error, Result};
use crate::map::MapKind;
use crate::map::{AlphaCutMap, AnyMap, FuzzyMap, LogOddsMap};

impl AnyMap {
    /// Loads a native map file of any kind.
    pub fn load(path: impl AsRef<Path>) -> Result<Self> {
        Self::load_with_header(path.as_ref()).map(|(_, map)| map)
    }

    /// A map of whichever kind the bytes of a native map file (`to_bytes`) hold. Errors name
    /// the bytes `<memory>`.
    pub fn from_bytes(bytes: &[u8]) -> Result<Self> {
        let header = from_memory(bytes, |b| split(b).map(|(header, _)| header))?;
        Self::decode(&header, bytes)
    }

    fn decode(header: &MapHeader, bytes: &[u8]) -> Result<Self> {
        match header.kind {
            MapKind::Fuzzy => FuzzyMap::from_bytes(bytes).map(Self::Fuzzy),
            MapKind::LogOdds => LogOddsMap::from_bytes(bytes).map(Self::LogOdds),
            MapKind::AlphaCut => AlphaCutMap::from_bytes(bytes).map(Self::Alpha),
        }
    }

    /// Loads a native map file of any kind, reading it once, with its header.
    pub fn load_with_header(path: &Path) -> Result<(MapHeader, Self)> {
        let (header, bytes) = read_checked(path)?;
        let map = Self::decode(&header, &bytes);
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
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::map::{AlphaConfig, FuzzyConfig, LogOddsConfig};

    #[test]
    fn bytes_of_any_kind_decode_as_their_kind() {
        let maps = [
            AnyMap::Fuzzy(FuzzyMap::new(FuzzyConfig::new(0.2).unwrap()).unwrap()),
            AnyMap::LogOdds(LogOddsMap::new(LogOddsConfig::new(0.2).unwrap()).unwrap()),
            AnyMap::Alpha(AlphaCutMap::new(AlphaConfig::new(0.2).unwrap()).unwrap()),
        ];
        for map in maps {
            let bytes = map.to_bytes();
            let back = AnyMap::from_bytes(&bytes).unwrap();
            assert_eq!(back.kind(), map.kind());
            assert_eq!(back.to_bytes(), bytes);
        }
        assert!(matches!(
            AnyMap::from_bytes(b"not a map"),
            Err(Error::Format { path, reason: crate::error::FormatError::BadMagic }) if path.as_os_str() == "<memory>"
        ));
    }
}
