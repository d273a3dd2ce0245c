use serde::{Deserialize, Serialize};

use fuzzyvox_core::error::{Error, Result, finite};

/// What to do with space the map knows nothing about.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum UnknownPolicy {
    /// Unknown voxels are obstacles: the safe choice for flying.
    Forbid,
    /// Unknown voxels may be crossed, each step through them costing this much extra per
    /// metre (optimistic exploration).
    Cost(f32),
}

/// Every threshold and weight of planning, in one value.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct PlannerConfig {
    /// Voxels with safety below this (and not unknown under [`UnknownPolicy::Cost`]) are
    /// blocked. Default 0.2: one confident free observation in the fuzzy map (μE = 0.6, safety
    /// 0.36) or in the log-odds map clears it.
    pub safety_threshold: f32,
    /// Vehicle radius in metres: a voxel is traversable only when the nearest blocked voxel is
    /// at least this far away. Default 0.3 m.
    pub vehicle_radius: f64,
    /// `k` in the step cost `length × (1 + k (1 - S))`. Default 2.
    pub safety_weight: f32,
    /// Clearance (metres) below which the clearance penalty applies. Default 1 m.
    pub preferred_clearance: f64,
    /// Weight of the clearance penalty `length × w × (1 - clearance / preferred)`. Default 1.
    pub clearance_weight: f32,
    /// Unknown space: forbidden (default) or allowed at a cost.
    pub unknown: UnknownPolicy,
}

impl Default for PlannerConfig {
    fn default() -> Self {
        Self {
            safety_threshold: 0.2,
            vehicle_radius: 0.3,
            safety_weight: 2.0,
            preferred_clearance: 1.0,
            clearance_weight: 1.0,
            unknown: UnknownPolicy::Forbid,
        }
    }
}

impl PlannerConfig {
    /// Checks every value: thresholds in `[0, 1]`, non-negative finite weights and distances.
    pub fn validate(self) -> Result<Self> {
        let invalid = |name, value: f64, expected| Error::InvalidParameter {
            name,
            value,
            expected,
        };
        if !(0.0..=1.0).contains(&self.safety_threshold) {
            return Err(invalid(
                "safety_threshold",
                f64::from(self.safety_threshold),
                "a safety in [0, 1]",
            ));
        }
        for (name, value) in [
            ("vehicle_radius", self.vehicle_radius),
            ("preferred_clearance", self.preferred_clearance),
            ("safety_weight", f64::from(self.safety_weight)),
            ("clearance_weight", f64::from(self.clearance_weight)),
        ] {
            finite(name, value)?;
            if value < 0.0 {
                return Err(invalid(name, value, "a non-negative value"));
            }
        }
        if let UnknownPolicy::Cost(cost) = self.unknown
            && !(cost.is_finite() && cost >= 0.0)
        {
            return Err(invalid(
                "unknown cost",
                f64::from(cost),
                "a non-negative finite cost per metre",
            ));
        }
        Ok(self)
    }
}
