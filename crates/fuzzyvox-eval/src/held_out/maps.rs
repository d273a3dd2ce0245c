//! The maps under test: each built from the same depth images, timed, checked against the
//! held-out frames, and reported.

use std::time::{Duration, Instant};

use serde::Serialize;

use super::flights::RealFlights;
use crate::rgbd::{DepthAgreement, DepthCheckConfig, DepthErrors};
use fuzzyvox_core::error::Result;
use fuzzyvox_core::integrate::{DepthFrame, IntegrationOptions};
use fuzzyvox_core::map::{AnyMap, MapKind, VoxelCounts};
use fuzzyvox_core::ops::Family;

/// One map's report: its model, timings, voxel counts, memory and its agreement with the
/// held-out frames' sensor depth.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MapCheckReport {
    /// The map's model.
    pub model: MapKind,
    /// The fuzzy map's t-conorm (`product`, `dombi:2`, ...); `None` for the other models.
    pub operator: Option<String>,
    /// Time spent integrating into this map (s).
    pub build_seconds: f64,
    /// Time spent ray casting this map into the held-out frames (s).
    pub predict_seconds: f64,
    /// The map's voxels per class.
    #[serde(flatten)]
    pub counts: VoxelCounts,
    /// The map's memory (bytes).
    pub memory_bytes: usize,
    /// How well the map predicts the held-out depth.
    #[serde(flatten)]
    pub agreement: DepthAgreement,
    /// Flights planned through the map and checked against the reference map (`mono --plan`);
    /// `None` (no keys) otherwise.
    #[serde(flatten)]
    pub flights: Option<RealFlights>,
}

/// One map under test, with its timings and its errors on held-out frames.
pub(super) struct MapUnderTest {
    pub(super) map: AnyMap,
    build: Duration,
    predict: Duration,
    errors: DepthErrors,
}

impl MapUnderTest {
    /// A map not yet built.
    pub(super) fn new(map: AnyMap) -> Self {
        Self {
            map,
            build: Duration::ZERO,
            predict: Duration::ZERO,
            errors: DepthErrors::default(),
        }
    }

    /// The report at the map's resolution; `operator` is the fuzzy map's.
    pub(super) fn report(&self, operator: Family, resolution: f64) -> MapCheckReport {
        let view = self.map.as_map();
        let model = self.map.kind();
        MapCheckReport {
            model,
            operator: (model == MapKind::Fuzzy).then(|| operator.to_string()),
            build_seconds: self.build.as_secs_f64(),
            predict_seconds: self.predict.as_secs_f64(),
            counts: view.counts(),
            memory_bytes: view.memory_bytes(),
            agreement: self.errors.summary(resolution),
            flights: None,
        }
    }
}

/// Integrates one depth image into every map, timing each.
pub(super) fn integrate_all(
    maps: &mut [MapUnderTest],
    frame: &DepthFrame,
    options: &IntegrationOptions,
) -> Result<()> {
    for entry in maps {
        let started = Instant::now();
        entry.map.as_map_mut().integrate_depth(frame, options)?;
        entry.build += started.elapsed();
    }
    Ok(())
}

/// Casts every map into one held-out frame of sensor depth and records the errors.
pub(super) fn check_all(
    maps: &mut [MapUnderTest],
    frame: &DepthFrame,
    check: &DepthCheckConfig,
) -> Result<()> {
    for entry in maps {
        let started = Instant::now();
        entry.errors.add_frame(entry.map.as_map(), frame, check)?;
        entry.predict += started.elapsed();
    }
    Ok(())
}
