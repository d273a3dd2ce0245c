//! The map models a command can build (`--model`, parsed through [`MapKind`]), the fuzzy
//! map's evidence model and the prior map options.

use anyhow::Context;
use clap::ValueEnum;
use clap::builder::{PossibleValuesParser, TypedValueParser};
use fuzzyvox::map::MapKind;
use fuzzyvox::{AnyMap, EvidenceKind, EvidenceModel};

/// `--model` of the commands that build one map: a [`MapKind`] by its name.
pub fn kind_parser() -> impl TypedValueParser<Value = MapKind> {
    PossibleValuesParser::new(MapKind::ALL.map(MapKind::name)).try_map(|name| name.parse())
}

/// One `--model` value of the commands that build several maps: a kind, or all of them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ModelArg {
    /// One kind.
    Kind(MapKind),
    /// Every kind (`all`).
    All,
}

impl ModelArg {
    /// Whether this value asks for `kind`.
    pub fn includes(self, kind: MapKind) -> bool {
        match self {
            Self::Kind(k) => k == kind,
            Self::All => true,
        }
    }

    /// The parser of `--model` values: the kinds' names and `all`.
    pub fn parser() -> impl TypedValueParser<Value = ModelArg> {
        let names = MapKind::ALL.map(MapKind::name);
        PossibleValuesParser::new(names.into_iter().chain(["all"])).try_map(|name| {
            if name == "all" {
                Ok(Self::All)
            } else {
                name.parse().map(Self::Kind)
            }
        })
    }
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

/// What colours a map's voxels in a PNG view or a viewer page (`--color`).
#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ColorArg {
    /// The class colour (occupied, free, ambiguous, unknown).
    Class,
    /// Height, by viridis.
    Height,
    /// The occupied membership, by viridis.
    Occupied,
    /// The free membership, by viridis.
    Free,
    /// Ambiguity, by viridis.
    Ambiguity,
    /// Safety, by viridis.
    Safety,
}

impl From<ColorArg> for fuzzyvox::figure::ViewColor {
    fn from(color: ColorArg) -> Self {
        match color {
            ColorArg::Class => Self::Class,
            ColorArg::Height => Self::Height,
            ColorArg::Occupied => Self::Occupied,
            ColorArg::Free => Self::Free,
            ColorArg::Ambiguity => Self::Ambiguity,
            ColorArg::Safety => Self::Safety,
        }
    }
}

/// The prior map options of the commands that build maps (`--prior`, `--prior-confidence`).
#[derive(clap::Args, Clone, Debug)]
pub struct PriorArgs {
    /// Start the fuzzy map from this map: a fuzzyvox map, an OctoMap `.bt` or an OctoMap `.ot`
    /// (told apart by content) of the same resolution. Its occupied and free voxels become
    /// evidence of confidence `--prior-confidence`.
    #[arg(long, value_name = "MAP")]
    pub prior: Option<std::path::PathBuf>,
    /// How much the prior map is trusted, in (0, 1].
    #[arg(
        long,
        value_name = "C",
        default_value_t = 0.5,
        requires = "prior",
        allow_negative_numbers = true
    )]
    pub prior_confidence: f32,
}

impl PriorArgs {
    /// Refuses a prior for commands building other models than the fuzzy one.
    pub fn check_models(&self, models: &[MapKind]) -> anyhow::Result<()> {
        if self.prior.is_some() && models.iter().any(|m| *m != MapKind::Fuzzy) {
            anyhow::bail!(
                "--prior applies to the fuzzy model only (a log-odds or alpha-cut map has no \
                 confidence to give a prior): add --model fuzzy"
            );
        }
        Ok(())
    }

    /// Adds the prior, when one is given, to a fuzzy map; returns the number of voxels it
    /// reached (0 without a prior).
    pub fn apply(&self, map: &mut AnyMap) -> anyhow::Result<usize> {
        let Some(path) = &self.prior else {
            return Ok(0);
        };
        let AnyMap::Fuzzy(fuzzy) = map else {
            anyhow::bail!("--prior applies to the fuzzy model only: add --model fuzzy");
        };
        let prior = fuzzyvox::io::load_map(path)
            .with_context(|| format!("reading the prior map {}", path.display()))?;
        let voxels = fuzzy
            .add_prior(prior.as_map(), self.prior_confidence)
            .with_context(|| format!("adding the prior map {}", path.display()))?;
        tracing::info!(
            "prior {} ({}): {voxels} voxels at confidence {}",
            path.display(),
            prior.model_name(),
            self.prior_confidence
        );
        Ok(voxels)
    }
}
