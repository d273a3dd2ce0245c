//! Building a new map of the kind a command asks for.

use anyhow::Context;
use clap::ValueEnum;
use fuzzyvox::{
    AlphaConfig, AlphaCutMap, AnyMap, Family, FuzzyConfig, FuzzyMap, LogOddsConfig, LogOddsMap,
    TConorm,
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

/// A new, empty map of `model` at `resolution` metres; `operator` applies to the fuzzy model and
/// `cuts` to the alpha model.
pub fn new_map(
    model: Model,
    resolution: f64,
    operator: Family,
    cuts: u32,
) -> anyhow::Result<AnyMap> {
    Ok(match model {
        Model::Fuzzy => AnyMap::Fuzzy(FuzzyMap::new(
            FuzzyConfig::new(resolution)
                .context("--res")?
                .with_operator(TConorm::new(operator)?),
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
