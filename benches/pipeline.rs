//! One stereo pair through the whole pipeline at 320 × 240: the depth stage (rectification,
//! matching, intervals and confidence) and fuzzy frustum integration, on pairs of the
//! simulator's random flight. Criterion reports time per pair; pairs per second = 1 / time.
//! The rendering of the views is outside the measured loop. `multi_view` is one depth image
//! from five views (a pair and its three earlier positions, chosen by the same [`ViewWindow`]
//! as `fuzzyvox eval --views 5`).
//!
//! Run: `cargo bench --bench pipeline`.

#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use criterion::{Criterion, criterion_group, criterion_main};
use fuzzyvox::VoxelMapMut;
use fuzzyvox::depth::{
    DepthParams, ForwardMotion, Frame, MatchMethod, ViewWindow, depth_from_pair,
};
use fuzzyvox::sim::scenario;
use fuzzyvox::{FuzzyConfig, FuzzyMap, IntegrationOptions};

/// Every pair of a 40-pair random flight, its views and how the depth stage matches it.
fn frames(params: &DepthParams) -> Vec<(Frame, Frame, Option<MatchMethod>)> {
    let scenario = scenario::random(40, 1).expect("scenario");
    let mut pairs = Vec::new();
    for (index, (reference, other)) in scenario.pairs.iter().enumerate() {
        let views = scenario.render_pair(index, 1).expect("pair");
        let frame = |i: usize, pose| {
            views[i]
                .to_frame(scenario.intrinsics, pose, index as f64)
                .expect("frame")
        };
        let (a, b) = (frame(0, *reference), frame(1, *other));
        let method = depth_from_pair(&a, &b, params).ok().map(|r| r.method);
        pairs.push((a, b, method));
    }
    pairs
}

/// Windows of five views per depth image, as `eval --views 5` builds them: for pair `k`, a
/// [`ViewWindow`] that remembers the flight's pairs before it (the random flight is one phase),
/// kept where its five-view sweep fits the plane limit.
fn windows(
    pairs: &[(Frame, Frame, Option<MatchMethod>)],
    params: &DepthParams,
) -> Vec<(usize, ViewWindow)> {
    let mut window = ViewWindow::new(5).expect("window");
    let mut chosen = Vec::new();
    for (k, (reference, other, _)) in pairs.iter().enumerate() {
        if chosen.len() == 8 {
            break;
        }
        if window
            .preview(reference, other, params)
            .is_ok_and(|r| r.views == 5)
        {
            chosen.push((k, window.clone()));
        }
        window.remember(reference.clone(), other.clone());
    }
    chosen
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
    let pairs = frames(&params);
    let mut group = c.benchmark_group("pair_320x240");
    group.sample_size(10);
    for method in [MatchMethod::Rectified, MatchMethod::PlaneSweep] {
        // Each pair on its own.
        let chosen: Vec<_> = pairs
            .iter()
            .filter(|p| p.2 == Some(method))
            .take(8)
            .collect();
        if chosen.is_empty() {
            continue;
        }
        let name = match method {
            MatchMethod::Rectified => "rectified",
            MatchMethod::PlaneSweep => "plane_sweep",
            MatchMethod::MultiView => "multi_view",
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
    let windows = windows(&pairs, &params);
    assert!(!windows.is_empty(), "no five-view set fits the plane sweep");
    group.bench_function("multi_view_5_depth_and_fuzzy_integration", |b| {
        let mut i = 0;
        let mut map = FuzzyMap::new(FuzzyConfig::new(0.2).unwrap()).unwrap();
        b.iter(|| {
            let (k, window) = &windows[i % windows.len()];
            i += 1;
            let (reference, other, _) = &pairs[*k];
            let result = window.preview(reference, other, &params).unwrap();
            map.integrate_depth(&result.frame, &options).unwrap()
        })
    });
    group.finish();
}

criterion_group!(benches, pipeline);
criterion_main!(benches);
