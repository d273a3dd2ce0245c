use super::{AlphaCutMap, FuzzyMap, LogOddsMap, VoxelMap, VoxelMapMut};

/// Any of the three maps, for code that handles whichever kind a file holds (its file methods
/// are in [`file`](mod@crate::file)).
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
