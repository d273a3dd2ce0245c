//! The three map models, declared once: their names, parsing and a new empty map of each.

use std::fmt;
use std::str::FromStr;

use serde::{Serialize, Serializer};

use super::{AlphaConfig, AlphaCutMap, AnyMap, FuzzyConfig, FuzzyMap, LogOddsConfig, LogOddsMap};
use crate::error::{Error, Result};
use crate::integrate::EvidenceModel;
use crate::ops::{Family, TConorm};

/// Which map model: every command, experiment, file and binding names maps by this one type.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum MapKind {
    /// The standard log-odds map (OctoMap semantics).
    LogOdds,
    /// The alpha-cut log-odds map (needs per-point confidence).
    AlphaCut,
    /// The dual-set fuzzy map.
    Fuzzy,
}

/// How a new map of any kind is set up beyond its resolution: the fuzzy map's operator and
/// evidence model, the alpha-cut map's number of cuts. The default is each model's default.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MapOptions {
    /// The fuzzy map's aggregation t-conorm family (default: the probabilistic sum).
    pub operator: Family,
    /// The fuzzy map's evidence model (default: the dual model).
    pub evidence: EvidenceModel,
    /// The alpha-cut map's number of confidence cuts (default 10).
    pub cuts: u32,
}

impl Default for MapOptions {
    fn default() -> Self {
        Self {
            operator: Family::Product,
            evidence: EvidenceModel::default(),
            cuts: AlphaConfig::DEFAULT_CUTS,
        }
    }
}

impl MapKind {
    /// Every kind, in the order reports list them (the baselines first).
    pub const ALL: [MapKind; 3] = [MapKind::LogOdds, MapKind::AlphaCut, MapKind::Fuzzy];

    /// Lower-case name: `logodds`, `alpha` or `fuzzy`.
    pub fn name(self) -> &'static str {
        match self {
            Self::LogOdds => "logodds",
            Self::AlphaCut => "alpha",
            Self::Fuzzy => "fuzzy",
        }
    }

    /// An empty map of this kind at `resolution` metres with each model's defaults.
    pub fn new_map(self, resolution: f64) -> Result<AnyMap> {
        self.new_map_with(resolution, &MapOptions::default())
    }

    /// An empty map of this kind at `resolution` metres; `options` apply where they concern
    /// this kind (the operator and evidence model to the fuzzy map, cuts to the alpha-cut map).
    pub fn new_map_with(self, resolution: f64, options: &MapOptions) -> Result<AnyMap> {
        Ok(match self {
            Self::Fuzzy => AnyMap::Fuzzy(FuzzyMap::new(
                FuzzyConfig::new(resolution)?
                    .with_operator(TConorm::new(options.operator)?)
                    .with_evidence(options.evidence),
            )?),
            Self::LogOdds => AnyMap::LogOdds(LogOddsMap::new(LogOddsConfig::new(resolution)?)?),
            Self::AlphaCut => {
                let mut config = AlphaConfig::new(resolution)?;
                config.cuts = options.cuts;
                AnyMap::Alpha(AlphaCutMap::new(config)?)
            }
        })
    }
}

impl fmt::Display for MapKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for MapKind {
    type Err = Error;

    /// Parses a name as [`MapKind::name`] gives it (also `log-odds` and `alpha-cut`), ignoring
    /// case.
    fn from_str(text: &str) -> Result<Self> {
        match text.trim().to_ascii_lowercase().as_str() {
            "logodds" | "log-odds" => Ok(Self::LogOdds),
            "alpha" | "alphacut" | "alpha-cut" => Ok(Self::AlphaCut),
            "fuzzy" => Ok(Self::Fuzzy),
            _ => Err(Error::UnknownName {
                what: "map model",
                name: text.to_string(),
                expected: "fuzzy, logodds or alpha",
            }),
        }
    }
}

/// Serialized as its name, as every JSON report writes it.
impl Serialize for MapKind {
    fn serialize<S: Serializer>(&self, serializer: S) -> std::result::Result<S::Ok, S::Error> {
        serializer.serialize_str(self.name())
    }
}

impl AnyMap {
    /// Which kind of map this is.
    pub fn kind(&self) -> MapKind {
        match self {
            Self::Fuzzy(_) => MapKind::Fuzzy,
            Self::LogOdds(_) => MapKind::LogOdds,
            Self::Alpha(_) => MapKind::AlphaCut,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_parse_back_and_maps_are_of_their_kind() {
        for kind in MapKind::ALL {
            assert_eq!(kind.name().parse::<MapKind>().unwrap(), kind);
            assert_eq!(kind.to_string(), kind.name());
            assert_eq!(kind.new_map(0.1).unwrap().kind(), kind);
        }
        assert_eq!("Log-Odds".parse::<MapKind>().unwrap(), MapKind::LogOdds);
        assert!("octree".parse::<MapKind>().is_err());
        assert!(MapKind::Fuzzy.new_map(f64::NAN).is_err());
        let options = MapOptions {
            cuts: 4,
            ..MapOptions::default()
        };
        let AnyMap::Alpha(alpha) = MapKind::AlphaCut.new_map_with(0.1, &options).unwrap() else {
            panic!("an alpha-cut map");
        };
        assert_eq!(alpha.config().cuts, 4);
    }
}
