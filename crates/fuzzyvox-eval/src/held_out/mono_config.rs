//! What `run_mono` needs beyond the maps under test: the depth stage's settings and where the
//! poses come from.

use std::path::PathBuf;

use super::config::HeldOutConfig;
use super::flights::RealFlightConfig;
use fuzzyvox_core::error::{Error, Result};
use fuzzyvox_core::integrate::EvidenceModel;
use fuzzyvox_depth::{ConsistencyParams, DepthParams, DepthStream, PairCriteria};

/// The settings of [`super::run_mono`].
#[derive(Clone, Debug, PartialEq)]
pub struct MonoConfig {
    /// The maps under test and their check against held-out frames.
    pub held_out: HeldOutConfig,
    /// Views matched at once for each depth image (2: pairs; at most 17).
    pub views: u32,
    /// Poses from a TUM trajectory (one pose per frame in frame order) instead of
    /// `frame-N.pose.txt`.
    pub trajectory: Option<PathBuf>,
    /// The colour camera's pose in the depth camera's frame (`depth_from_color`, a row-major
    /// 4×4 matrix file as `pose.txt`), when the poses are the depth camera's.
    pub extrinsics: Option<PathBuf>,
    /// Nearest depth searched (m).
    pub near: f64,
    /// Farthest depth searched (m); also the integration's range.
    pub far: f64,
    /// Smallest baseline of a pair (m).
    pub min_baseline: f64,
    /// The check of each depth image against its neighbours in the stream.
    pub consistency: ConsistencyParams,
    /// Flights through the maps, checked against a reference map of the folder's sensor
    /// depth; `None`: none.
    pub flights: Option<RealFlightConfig>,
}

impl MonoConfig {
    /// The command's defaults at `resolution` metres: [`HeldOutConfig::new`] with the evidence
    /// model for confirmed depth ([`EvidenceModel::confirmed`]), three views per depth image,
    /// each image checked against four neighbours on each side
    /// ([`ConsistencyParams::default`]), poses from `pose.txt`, depth searched from 0.3 to
    /// 8 m, baselines from 5 cm.
    pub fn new(resolution: f64) -> Self {
        Self {
            held_out: HeldOutConfig {
                evidence: EvidenceModel::confirmed(),
                ..HeldOutConfig::new(resolution)
            },
            views: 3,
            trajectory: None,
            extrinsics: None,
            near: 0.3,
            far: 8.0,
            min_baseline: 0.05,
            consistency: ConsistencyParams::default(),
            flights: None,
        }
    }

    /// Checks every value: the maps' ([`HeldOutConfig::validate`]), 2 to 17 views,
    /// `0 < near < far` (both finite) and the pair criteria.
    pub fn validate(&self) -> Result<()> {
        self.held_out.validate()?;
        if !(2..=17).contains(&self.views) {
            return Err(Error::InvalidParameter {
                name: "views",
                value: f64::from(self.views),
                expected: "2 to 17 views matched at once",
            });
        }
        let expected = "0 < near < far, both finite (metres)";
        if !(self.near.is_finite() && self.near > 0.0) {
            return Err(Error::InvalidParameter {
                name: "near",
                value: self.near,
                expected,
            });
        }
        if !(self.far.is_finite() && self.far > self.near) {
            return Err(Error::InvalidParameter {
                name: "far",
                value: self.far,
                expected,
            });
        }
        self.consistency.validate()?;
        if let Some(flights) = &self.flights {
            flights.validate()?;
        }
        self.stream().map(|_| ())
    }

    /// A new depth stream of these settings.
    pub(super) fn stream(&self) -> Result<DepthStream> {
        let criteria = PairCriteria {
            min_baseline: self.min_baseline,
            ..PairCriteria::default()
        };
        let params = DepthParams {
            depth_range: Some((self.near, self.far)),
            ..DepthParams::default()
        };
        DepthStream::new(criteria, self.views as usize, params)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_valid_and_bad_ranges_are_refused() {
        MonoConfig::new(0.05).validate().unwrap();
        let mut config = MonoConfig::new(0.05);
        (config.near, config.far) = (5.0, 2.0);
        let error = config.validate().unwrap_err();
        assert!(matches!(error, Error::InvalidParameter { name: "far", .. }));
        assert!(error.to_string().contains("0 < near < far"));
        let mut config = MonoConfig::new(0.05);
        config.views = 1;
        assert!(config.validate().is_err());
        let mut config = MonoConfig::new(0.05);
        config.min_baseline = f64::NAN;
        assert!(config.validate().is_err());
    }
}
