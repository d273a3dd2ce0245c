//! Building a new map of the kind a command asks for.

use anyhow::Context;
use clap::ValueEnum;
use fuzzyvox::{
    AlphaConfig, AlphaCutMap, AnyMap, EvidenceKind, EvidenceModel, Family, FuzzyConfig, FuzzyMap,
    LogOddsConfig, LogOddsMap, TConorm,
};

/// The map models a command can build.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Model {
    /// The dual-set fuzzy map.
    Fuzzy,
    /// The standard log-odds map (OctoMap semantics).
    Logodds,
    /// The alpha-cut log-odds map (needs per-point confidence).
    Alpha,
}

impl Model {
    /// Every model, in the order reports list them.
    pub const ALL: [Model; 3] = [Model::Logodds, Model::Alpha, Model::Fuzzy];
}

/// How the fuzzy map turns measurements into evidence (`--evidence`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum Evidence {
    /// The paper's model: free evidence weighted by the same confidence as occupied evidence,
    /// and only in front of each depth interval.
    Paper,
    /// Free evidence weighted by how likely the match is right, reaching into the interval.
    #[default]
    Dual,
}

impl Evidence {
    /// The library's evidence model with its default parameters.
    pub fn model(self) -> EvidenceModel {
        EvidenceModel::of_kind(match self {
            Self::Paper => EvidenceKind::Paper,
            Self::Dual => EvidenceKind::Dual,
        })
    }
}

/// A new, empty map of `model` at `resolution` metres; `operator` and `evidence` apply to the
/// fuzzy model and `cuts` to the alpha model.
pub fn new_map(
    model: Model,
    resolution: f64,
    operator: Family,
    evidence: Evidence,
    cuts: u32,
) -> anyhow::Result<AnyMap> {
    Ok(match model {
        Model::Fuzzy => AnyMap::Fuzzy(FuzzyMap::new(
            FuzzyConfig::new(resolution)
                .context("--res")?
                .with_operator(TConorm::new(operator)?)
                .with_evidence(evidence.model()),
        )?),
        Model::Logodds => AnyMap::LogOdds(LogOddsMap::new(
            LogOddsConfig::new(resolution).context("--res")?,
        )?),
        Model::Alpha => {
            let mut config = AlphaConfig::new(resolution).context("--res")?;
            config.cuts = cuts;
            AnyMap::Alpha(AlphaCutMap::new(config).context("--cuts")?)
        }
    })
}
