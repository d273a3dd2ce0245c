//! The maps under test and their check against held-out frames: what `run_rgbd` and
//! `run_mono` share.

use std::path::PathBuf;

use crate::rgbd::DepthCheckConfig;
use fuzzyvox_core::error::{Error, Result, finite};
use fuzzyvox_core::integrate::EvidenceModel;
use fuzzyvox_core::map::{AnyMap, MapKind, MapOptions};
use fuzzyvox_core::ops::Family;

/// A prior map the fuzzy map starts from.
#[derive(Clone, Debug, PartialEq)]
pub struct PriorMap {
    /// A fuzzyvox map, an OctoMap `.bt` or an OctoMap `.ot` (told apart by content) of the
    /// maps' resolution.
    pub path: PathBuf,
    /// How much the prior is trusted, in (0, 1]: its occupied and free voxels become evidence
    /// of this confidence.
    pub confidence: f32,
}

/// The maps under test and their check against held-out frames.
#[derive(Clone, Debug, PartialEq)]
pub struct HeldOutConfig {
    /// Voxel size in metres.
    pub resolution: f64,
    /// The models to build and check; reports list them in [`MapKind::ALL`] order, each once.
    pub models: Vec<MapKind>,
    /// Hold out every K-th frame (the K-th, 2K-th, ...); the others build the maps. At least 2.
    pub holdout: usize,
    /// Check every N-th pixel in both directions of the held-out frames (1: every pixel).
    pub pixel_step: u32,
    /// Cast rays this far (metres); pixels measured farther are not checked.
    pub cast_range: f64,
    /// Let ambiguous voxels stop rays too (by default only occupied voxels do).
    pub stop_at_ambiguous: bool,
    /// The fuzzy map's aggregation t-conorm (the others have none).
    pub operator: Family,
    /// The alpha-cut map's number of confidence cuts.
    pub cuts: u32,
    /// The fuzzy map's evidence model: the dual model for sensor depth,
    /// [`EvidenceModel::confirmed`] for the depth stage's checked images ([`MonoConfig::new`](super::MonoConfig::new)).
    pub evidence: EvidenceModel,
    /// A prior map for the fuzzy map (only when the fuzzy model is the only one).
    pub prior: Option<PriorMap>,
}

impl HeldOutConfig {
    /// All three models at `resolution` metres, every 5th frame held out, every pixel checked
    /// up to 8 m, the probabilistic sum, 10 cuts, no prior: the command's defaults.
    pub fn new(resolution: f64) -> Self {
        Self {
            resolution,
            models: MapKind::ALL.to_vec(),
            holdout: 5,
            pixel_step: 1,
            cast_range: 8.0,
            stop_at_ambiguous: false,
            operator: Family::Product,
            cuts: 10,
            evidence: EvidenceModel::dual(),
            prior: None,
        }
    }

    /// The models asked for, in report order ([`MapKind::ALL`]), each once.
    pub fn kinds(&self) -> Vec<MapKind> {
        MapKind::ALL
            .into_iter()
            .filter(|kind| self.models.contains(kind))
            .collect()
    }

    /// The ray-casting check's settings.
    pub fn check(&self) -> DepthCheckConfig {
        DepthCheckConfig {
            pixel_step: self.pixel_step,
            max_range: self.cast_range,
            stop_at_ambiguous: self.stop_at_ambiguous,
        }
    }

    /// How the maps are set up beyond their resolution.
    pub fn map_options(&self) -> MapOptions {
        MapOptions {
            operator: self.operator,
            cuts: self.cuts,
            evidence: self.evidence,
        }
    }

    /// Checks every value: a finite positive resolution, at least one model, a holdout of at
    /// least 2, the check's step and range, the operator's parameter, a cut count the alpha-cut
    /// map accepts, and a prior only for the fuzzy model alone with a confidence in (0, 1].
    pub fn validate(&self) -> Result<()> {
        finite("resolution", self.resolution)?;
        if self.resolution <= 0.0 {
            return Err(Error::InvalidParameter {
                name: "resolution",
                value: self.resolution,
                expected: "a positive voxel size in metres",
            });
        }
        if self.models.is_empty() {
            return Err(Error::Empty("the list of map models"));
        }
        if self.holdout < 2 {
            return Err(Error::InvalidParameter {
                name: "holdout",
                value: self.holdout as f64,
                expected: "hold out every K-th frame with K >= 2",
            });
        }
        self.check().validate()?;
        // Builds one map of each kind: the resolution, operator and cuts as the maps take them.
        for kind in self.kinds() {
            kind.new_map_with(self.resolution, &self.map_options())?;
        }
        if self.operator != Family::Product && !self.kinds().contains(&MapKind::Fuzzy) {
            return Err(Error::Incompatible(
                "the operator applies to the fuzzy model only".to_string(),
            ));
        }
        if let Some(prior) = &self.prior {
            if self.kinds() != [MapKind::Fuzzy] {
                return Err(Error::Incompatible(
                    "a prior map applies to the fuzzy model only (a log-odds or alpha-cut map \
                     has no confidence to give a prior)"
                        .to_string(),
                ));
            }
            if !(prior.confidence > 0.0 && prior.confidence <= 1.0) {
                return Err(Error::InvalidParameter {
                    name: "prior_confidence",
                    value: f64::from(prior.confidence),
                    expected: "a confidence in (0, 1]",
                });
            }
        }
        Ok(())
    }

    /// A new, empty map per model asked for, in report order (the fuzzy one with its prior,
    /// when given).
    pub(super) fn new_maps(&self) -> Result<Vec<AnyMap>> {
        let prior = match &self.prior {
            Some(prior) => Some((fuzzyvox_io::load_map(&prior.path)?, prior.confidence)),
            None => None,
        };
        self.kinds()
            .into_iter()
            .map(|kind| {
                let mut map = kind.new_map_with(self.resolution, &self.map_options())?;
                if let (AnyMap::Fuzzy(fuzzy), Some((prior, confidence))) = (&mut map, &prior) {
                    fuzzy.add_prior(prior.as_map(), *confidence)?;
                }
                Ok(map)
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_valid_and_bad_values_are_refused() {
        let config = HeldOutConfig::new(0.05);
        config.validate().unwrap();
        assert_eq!(config.kinds(), MapKind::ALL);
        let bad = |change: &dyn Fn(&mut HeldOutConfig)| {
            let mut config = HeldOutConfig::new(0.05);
            change(&mut config);
            config.validate().unwrap_err()
        };
        assert!(matches!(
            bad(&|c| c.resolution = -1.0),
            Error::InvalidParameter {
                name: "resolution",
                ..
            }
        ));
        assert!(matches!(
            bad(&|c| c.holdout = 1),
            Error::InvalidParameter {
                name: "holdout",
                ..
            }
        ));
        assert!(matches!(
            bad(&|c| c.pixel_step = 0),
            Error::InvalidParameter {
                name: "pixel_step",
                ..
            }
        ));
        assert!(matches!(bad(&|c| c.models.clear()), Error::Empty(_)));
        assert!(bad(&|c| c.cuts = 0).to_string().contains("cuts"));
        let prior = PriorMap {
            path: "prior.fvx".into(),
            confidence: 0.5,
        };
        let with_prior = prior.clone();
        assert!(matches!(
            bad(&move |c| c.prior = Some(with_prior.clone())),
            Error::Incompatible(_)
        ));
        let mut fuzzy = HeldOutConfig::new(0.05);
        fuzzy.models = vec![MapKind::Fuzzy, MapKind::Fuzzy];
        fuzzy.prior = Some(PriorMap {
            confidence: 1.5,
            ..prior
        });
        assert!(matches!(
            fuzzy.validate(),
            Err(Error::InvalidParameter {
                name: "prior_confidence",
                ..
            })
        ));
        assert_eq!(fuzzy.kinds(), [MapKind::Fuzzy]);
    }
}
