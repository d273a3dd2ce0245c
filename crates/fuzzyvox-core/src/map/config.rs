use serde::{Deserialize, Serialize};

use crate::error::Result;
use crate::integrate::EvidenceModel;
use crate::measures::MeasureConfig;
use crate::ops::TConorm;
use crate::storage::Resolution;

/// Everything that defines a fuzzy map's behaviour.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct FuzzyConfig {
    /// Voxel size.
    pub resolution: Resolution,
    /// The t-conorm `S` that aggregates evidence: `μ ← S(μ, evidence)` (probabilistic sum by
    /// default).
    pub operator: TConorm,
    /// How measurements become evidence.
    pub evidence: EvidenceModel,
    /// How measures and classes are computed.
    pub measures: MeasureConfig,
}

impl FuzzyConfig {
    /// The default configuration at `resolution` metres.
    ///
    /// ```
    /// use fuzzyvox_core::{Family, FuzzyConfig, TConorm};
    /// let config = FuzzyConfig::new(0.1)
    ///     .unwrap()
    ///     .with_operator(TConorm::new(Family::Dombi { lambda: 2.0 }).unwrap());
    /// assert_eq!(config.resolution.size(), 0.1);
    /// ```
    pub fn new(resolution: f64) -> Result<Self> {
        Ok(Self {
            resolution: Resolution::new(resolution)?,
            operator: TConorm::default(),
            evidence: EvidenceModel::default(),
            measures: MeasureConfig::default(),
        })
    }

    /// The same configuration with another aggregation operator.
    pub fn with_operator(mut self, operator: TConorm) -> Self {
        self.operator = operator;
        self
    }

    /// The same configuration with another evidence model (for example
    /// [`EvidenceModel::paper`] to compare with the paper's model).
    pub fn with_evidence(mut self, evidence: EvidenceModel) -> Self {
        self.evidence = evidence;
        self
    }

    /// Checks every part (useful after editing fields or decoding a file).
    pub fn validate(self) -> Result<Self> {
        Resolution::new(self.resolution.size())?;
        TConorm::new(self.operator.family())?;
        self.evidence.validate()?;
        self.measures.validate()?;
        Ok(self)
    }
}
