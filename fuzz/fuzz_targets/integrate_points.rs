//! Point-cloud integration with arbitrary floats, into one of the three maps (the input
//! chooses): each call succeeds with memberships in [0, 1], or fails with a typed error and
//! leaves the map's bytes unchanged.
#![no_main]

#[path = "../common/mod.rs"]
mod common;

use arbitrary::Arbitrary;
use common::{Metres, Operator, Resolution};
use fuzzyvox::{
    AlphaConfig, AlphaCutMap, FuzzyConfig, FuzzyMap, IntegrationOptions, LogOddsConfig, LogOddsMap,
    PointCloud, VoxelMapMut,
};
use libfuzzer_sys::fuzz_target;
use nalgebra::Point3;

const MAX_POINTS: usize = 64;
/// Most voxels that one input's rays may cross in all (see the skip below).
const WORK_VOXELS: f64 = 20_000.0;

#[derive(Arbitrary, Debug)]
struct Input {
    resolution: Resolution,
    operator: Operator,
    origin: [Metres; 3],
    points: Vec<[Metres; 3]>,
    confidence: Option<Vec<f32>>,
    max_range: Option<Metres>,
    /// Which map: fuzzy, log-odds or alpha-cut.
    model: u8,
}

fuzz_target!(|input: Input| {
    let point = |p: [Metres; 3]| Point3::from(p.map(Metres::value));
    let points: Vec<_> = input
        .points
        .iter()
        .take(MAX_POINTS)
        .copied()
        .map(point)
        .collect();
    let Ok(cloud) = PointCloud::new(point(input.origin), points) else {
        return;
    };
    let cloud = match input.confidence {
        Some(mut confidence) => {
            confidence.resize(cloud.len(), 1.0);
            match cloud.with_confidence(confidence) {
                Ok(cloud) => cloud,
                Err(_) => return,
            }
        }
        None => cloud,
    };
    let options = IntegrationOptions {
        max_range: input.max_range.map(Metres::value),
    };
    let res = input.resolution.value();
    // Keep each input cheap, so the fuzzer explores more of them: skip clouds whose rays sum to
    // more than WORK_VOXELS, unless one ray is long enough to be refused outright (that path
    // must stay reachable, and it fails before any walking).
    let voxels = |p: &Point3<f64>| {
        let range = (p - cloud.origin()).norm();
        options.max_range.map_or(range, |max| range.min(max)) / res
    };
    let finite: Vec<f64> = cloud
        .points()
        .iter()
        .filter(|p| p.iter().all(|v| v.is_finite()))
        .map(voxels)
        .collect();
    let refused = finite
        .iter()
        .any(|v| *v > IntegrationOptions::MAX_RAY_VOXELS);
    if !refused && finite.iter().sum::<f64>() > WORK_VOXELS {
        return;
    }
    // One map kind per input: three times the inputs per second.
    match input.model % 3 {
        0 => {
            if let (Ok(config), Some(operator)) = (FuzzyConfig::new(res), input.operator.tconorm())
            {
                let map = FuzzyMap::new(config.with_operator(operator)).expect("valid config");
                check(map, &cloud, &options, |m| m.to_bytes());
            }
        }
        1 => {
            if let Ok(config) = LogOddsConfig::new(res) {
                let map = LogOddsMap::new(config).expect("valid config");
                check(map, &cloud, &options, |m| m.to_bytes());
            }
        }
        _ => {
            if let Ok(config) = AlphaConfig::new(res) {
                let map = AlphaCutMap::new(config).expect("valid config");
                check(map, &cloud, &options, |m| m.to_bytes());
            }
        }
    }
});

/// Integrates a small fixed scan, then the input: an error must leave the bytes unchanged.
fn check<M: VoxelMapMut>(
    mut map: M,
    cloud: &PointCloud,
    options: &IntegrationOptions,
    bytes: impl Fn(&M) -> Vec<u8>,
) {
    let step = map.resolution().size();
    let seed = PointCloud::new(
        Point3::origin(),
        vec![
            Point3::new(4.0 * step, step, 0.0),
            Point3::new(0.0, -3.0 * step, step),
        ],
    )
    .expect("finite origin");
    map.integrate_cloud(&seed, &IntegrationOptions::default())
        .expect("a short scan integrates");
    let before = bytes(&map);
    match map.integrate_cloud(cloud, options) {
        Ok(stats) => {
            assert!(stats.integrated + stats.skipped <= cloud.len());
            for (_, m) in map.cells() {
                assert!((0.0..=1.0).contains(&m.occupied), "{m:?}");
                assert!((0.0..=1.0).contains(&m.free), "{m:?}");
            }
        }
        Err(_) => assert!(
            bytes(&map) == before,
            "a failed integration changed the map"
        ),
    }
}
