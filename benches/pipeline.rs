//! One stereo pair through the whole pipeline at 320 × 240: the depth stage (rectification,
//! matching, intervals and confidence) and fuzzy frustum integration, on pairs of the
//! simulator's random flight. Criterion reports time per pair; pairs per second = 1 / time.
//! The rendering of the views is outside the measured loop.
//!
//! Run: `cargo bench --bench pipeline`.

use criterion::{Criterion, criterion_group, criterion_main};
use fuzzyvox::depth::{DepthParams, ForwardMotion, Frame, MatchMethod, depth_from_pair};
use fuzzyvox::sim::scenario;
use fuzzyvox::{FuzzyConfig, FuzzyMap, IntegrationOptions, VoxelMap};

fn frames() -> Vec<(Frame, Frame, MatchMethod)> {
    let scenario = scenario::random(40, 1).expect("scenario");
    let params = DepthParams {
        depth_range: Some((1.0, scenario.max_range)),
        forward_motion: ForwardMotion::PlaneSweep,
        ..DepthParams::default()
    };
    let mut pairs = Vec::new();
    for (index, (reference, other)) in scenario.pairs.iter().enumerate() {
        let views = scenario.render_pair(index, 1).expect("pair");
        let frame = |i: usize, pose| {
            views[i]
                .to_frame(scenario.intrinsics, pose, index as f64)
                .expect("frame")
        };
        let (a, b) = (frame(0, *reference), frame(1, *other));
        if let Ok(result) = depth_from_pair(&a, &b, &params) {
            pairs.push((a, b, result.method));
        }
    }
    pairs
}

fn pipeline(c: &mut Criterion) {
    let scenario = scenario::random(1, 1).expect("scenario");
    let params = DepthParams {
        depth_range: Some((1.0, scenario.max_range)),
        forward_motion: ForwardMotion::PlaneSweep,
        ..DepthParams::default()
    };
    let options = IntegrationOptions {
        max_range: Some(scenario.max_range),
    };
    let pairs = frames();
    let mut group = c.benchmark_group("pair_320x240");
    group.sample_size(10);
    for method in [MatchMethod::Rectified, MatchMethod::PlaneSweep] {
        let chosen: Vec<_> = pairs.iter().filter(|p| p.2 == method).take(8).collect();
        if chosen.is_empty() {
            continue;
        }
        let name = match method {
            MatchMethod::Rectified => "rectified",
            MatchMethod::PlaneSweep => "plane_sweep",
        };
        group.bench_function(format!("{name}_depth_and_fuzzy_integration"), |b| {
            let mut i = 0;
            let mut map = FuzzyMap::new(FuzzyConfig::new(0.2).unwrap()).unwrap();
            b.iter(|| {
                let (reference, other, _) = chosen[i % chosen.len()];
                i += 1;
                let result = depth_from_pair(reference, other, &params).unwrap();
                map.integrate_depth(&result.frame, &options).unwrap()
            })
        });
    }
    group.finish();
}

criterion_group!(benches, pipeline);
criterion_main!(benches);
